// Testbench of texsim_bilinear (bilinear.sv, lerp.sv): reads the vectors `texsim vectors
// bilinear` wrote (t00.hex .. t11.hex, wx.hex, wy.hex, y.hex in the working directory), applies
// every vector and checks y. Prints "bilinear_tb: N vectors, P passed, F failed", then PASS, or
// ends with $fatal (exit status 1). Parameters from manifest.json: TB = bits of port t00,
// WB = frac_bits of port wx, ROUND from the rounding of port y, N = vectors.
module bilinear_tb;
    parameter int TB = 16;
    parameter int WB = 16;
    parameter int ROUND = 2;
    parameter int N = 1;
    localparam int WP = (WB > 0) ? WB : 1;

    logic [TB-1:0] t00_mem[0:N-1];
    logic [TB-1:0] t10_mem[0:N-1];
    logic [TB-1:0] t01_mem[0:N-1];
    logic [TB-1:0] t11_mem[0:N-1];
    logic [WP-1:0] wx_mem[0:N-1];
    logic [WP-1:0] wy_mem[0:N-1];
    logic [TB-1:0] y_mem[0:N-1];
    logic [TB-1:0] t00, t10, t01, t11, y;
    logic [WP-1:0] wx, wy;
    int pass = 0;
    int fail = 0;

    texsim_bilinear #(.TB(TB), .WB(WB), .ROUND(ROUND)) dut (
        .t00(t00), .t10(t10), .t01(t01), .t11(t11), .wx(wx), .wy(wy), .y(y)
    );

    initial begin
        $readmemh("t00.hex", t00_mem);
        $readmemh("t10.hex", t10_mem);
        $readmemh("t01.hex", t01_mem);
        $readmemh("t11.hex", t11_mem);
        $readmemh("wx.hex", wx_mem);
        $readmemh("wy.hex", wy_mem);
        $readmemh("y.hex", y_mem);
        for (int k = 0; k < N; k++) begin
            t00 = t00_mem[k];
            t10 = t10_mem[k];
            t01 = t01_mem[k];
            t11 = t11_mem[k];
            wx = wx_mem[k];
            wy = wy_mem[k];
            #1;
            // A missing line reads as x: never a pass.
            if ((^{t00, t10, t01, t11, wx, wy, y_mem[k]}) !== 1'bx && y === y_mem[k]) begin
                pass++;
            end else begin
                fail++;
                if (fail <= 10)
                    $display("bilinear_tb: vector %0d: %h %h %h %h wx=%h wy=%h: rtl y=%h, expected %h",
                             k, t00, t10, t01, t11, wx, wy, y, y_mem[k]);
            end
        end
        $display("bilinear_tb: %0d vectors, %0d passed, %0d failed", N, pass, fail);
        if (fail != 0) $fatal(1, "bilinear_tb: FAIL");
        $display("bilinear_tb: PASS");
        $finish;
    end
endmodule
