// Testbench of texsim_lerp (lerp.sv): reads the vectors `texsim vectors lerp` wrote (a.hex,
// b.hex, w.hex, y.hex in the working directory), applies every vector and checks y. Prints
// "lerp_tb: N vectors, P passed, F failed", then PASS, or ends with $fatal (exit status 1).
// Parameters from manifest.json: TB = bits of port a, WB = frac_bits of port w, ROUND from
// the rounding of port y (truncate 0, half-up 1, half-even 2), N = vectors.
module lerp_tb;
    parameter int TB = 16;
    parameter int WB = 16;
    parameter int ROUND = 2;
    parameter int N = 1;

    logic [TB-1:0] a_mem[0:N-1];
    logic [TB-1:0] b_mem[0:N-1];
    logic [WB:0]   w_mem[0:N-1];
    logic [TB-1:0] y_mem[0:N-1];
    logic [TB-1:0] a, b, y;
    logic [WB:0]   w;
    int pass = 0;
    int fail = 0;

    texsim_lerp #(.TB(TB), .WB(WB), .ROUND(ROUND)) dut (.a(a), .b(b), .w(w), .y(y));

    initial begin
        $readmemh("a.hex", a_mem);
        $readmemh("b.hex", b_mem);
        $readmemh("w.hex", w_mem);
        $readmemh("y.hex", y_mem);
        for (int k = 0; k < N; k++) begin
            a = a_mem[k];
            b = b_mem[k];
            w = w_mem[k];
            #1;
            // A missing line reads as x: never a pass.
            if ((^{a_mem[k], b_mem[k], w_mem[k], y_mem[k]}) !== 1'bx && y === y_mem[k]) begin
                pass++;
            end else begin
                fail++;
                if (fail <= 10)
                    $display("lerp_tb: vector %0d: a=%h b=%h w=%h: rtl y=%h, expected %h",
                             k, a, b, w, y, y_mem[k]);
            end
        end
        $display("lerp_tb: %0d vectors, %0d passed, %0d failed", N, pass, fail);
        if (fail != 0) $fatal(1, "lerp_tb: FAIL");
        $display("lerp_tb: PASS");
        $finish;
    end
endmodule
