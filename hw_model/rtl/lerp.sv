// The filter lerp of texsim's trilinear unit (hw_model/src/trilinear.rs, `lerp`), the
// operation the bilinear filter applies three times per channel and the level blend once:
//   y = a + (b - a) * w / 2^WB, rounded once by ROUND, w in [0, 2^WB].
// ROUND: 0 truncate (toward minus infinity), 1 half-up (ties toward plus infinity),
// 2 half-even (ties to even), as hw_model::fixed::round_shift_right. The result lies between
// a and b, so it never saturates. Combinational; written for texsim (MIT OR Apache-2.0).
module texsim_lerp #(
    parameter int TB = 16,   // operand and result bits (texel_bits)
    parameter int WB = 16,   // weight fraction bits (weight_bits, at most 16)
    parameter int ROUND = 2
) (
    input  logic [TB-1:0] a,
    input  logic [TB-1:0] b,
    input  logic [WB:0]   w,
    output logic [TB-1:0] y
);
    // a 2^WB + (b - a) w lies in [0, 2^(TB+WB)); one sign bit and one spare bit.
    localparam int NW = TB + WB + 2;
    logic signed [NW-1:0] sa, sb, sw, num;
    assign sa  = $signed({{(NW - TB){1'b0}}, a});
    assign sb  = $signed({{(NW - TB){1'b0}}, b});
    assign sw  = $signed({{(NW - WB - 1){1'b0}}, w});
    assign num = (sa <<< WB) + (sb - sa) * sw;

    generate
        if (WB == 0) begin : g_exact
            assign y = num[TB-1:0];
        end else begin : g_round
            logic signed [NW-1:0] fl;
            logic [WB-1:0] rem;
            logic up;
            localparam logic [WB-1:0] HALF = {1'b1, {(WB - 1){1'b0}}};
            assign fl  = num >>> WB;
            assign rem = num[WB-1:0];
            assign up  = (ROUND == 0) ? 1'b0
                       : (ROUND == 1) ? (rem >= HALF)
                       : ((rem > HALF) || ((rem == HALF) && fl[0]));
            assign y = fl[TB-1:0] + {{(TB - 1){1'b0}}, up};
        end
    endgenerate
endmodule
