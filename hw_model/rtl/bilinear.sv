// One channel of the bilinear footprint of texsim's trilinear unit
// (hw_model/src/trilinear.rs, `bilinear`): lerp along x on row y0 and on row y1, then along y,
// each lerp rounded once (texsim_lerp in lerp.sv). Weights wx, wy in [0, 2^WB - 1] as the
// wrap unit produces them. Combinational; written for texsim (MIT OR Apache-2.0).
module texsim_bilinear #(
    parameter int TB = 16,
    parameter int WB = 16,
    parameter int ROUND = 2,
    parameter int WP = (WB > 0) ? WB : 1  // width of a weight port
) (
    input  logic [TB-1:0] t00,
    input  logic [TB-1:0] t10,
    input  logic [TB-1:0] t01,
    input  logic [TB-1:0] t11,
    input  logic [WP-1:0] wx,
    input  logic [WP-1:0] wy,
    output logic [TB-1:0] y
);
    logic [TB-1:0] top, bot;
    logic [WB:0] wx1, wy1;
    assign wx1 = (WB > 0) ? {1'b0, wx} : '0;
    assign wy1 = (WB > 0) ? {1'b0, wy} : '0;
    texsim_lerp #(.TB(TB), .WB(WB), .ROUND(ROUND)) row0 (.a(t00), .b(t10), .w(wx1), .y(top));
    texsim_lerp #(.TB(TB), .WB(WB), .ROUND(ROUND)) row1 (.a(t01), .b(t11), .w(wx1), .y(bot));
    texsim_lerp #(.TB(TB), .WB(WB), .ROUND(ROUND)) col (.a(top), .b(bot), .w(wy1), .y(y));
endmodule
