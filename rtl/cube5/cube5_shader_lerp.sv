// cube5_shader_lerp: one exact linear interpolation of cube5_shader's bilinear lookup
// (docs/numerics/shader.md, § Bilinear interpolation), in two register stages:
//
//   prep:    base = a * 2^WgtFracW + rnd,   diff = b - a,  3 diff    (rnd = 2^(RndShift-1), or 0)
//   product: y    = (base + e * diff) >> RndShift
//
// i.e. y = (a * (2^WgtFracW - e) + b * e + rnd) >> RndShift with one signed product. The weight
// is narrow (WgtFracW + 1 bits, 5 at the frame's widths), so the product is built in LUTs rather
// than on a MULT18X18D, which Yosys 0.23 gives every `*` whatever its widths (docs/accel.md,
// *P = 8 on the 85k part*): radix 4, each two weight bits pick 0, diff, 2 diff or 3 diff
// (registered in the prep stage), shifted to their place and summed; e = 2^WgtFracW, the weight's
// top bit, is diff shifted alone (the other bits are then zero). For e in
// 0 ..= 2^WgtFracW the sum lies in [rnd, max(a, b) * 2^WgtFracW + rnd] < 2^(ValW + WgtFracW): no
// saturation, and the dropped bits are only the RndShift fraction bits that the rounding covers.
// The caller gives `e_i` aligned with the product stage (its copy of the weight held beside the
// prep registers). Datapath only: no reset.
module cube5_shader_lerp #(
  /// Width of a and b (unsigned).
  parameter int unsigned ValW     = 9,
  /// Fraction bits of the weight; e runs 0 ..= 2^WgtFracW.
  parameter int unsigned WgtFracW = 4,
  /// Fraction bits rounded off the result (half up); 0 keeps it exact.
  parameter int unsigned RndShift = 0
) (
  input  logic                              clk_i,
  /// Loads the prep registers (the stage's handshake enable).
  input  logic                              en_prep_i,
  /// Loads the product register.
  input  logic                              en_mul_i,
  /// Value at e = 0.
  input  logic [ValW-1:0]                   a_i,
  /// Value at e = 2^WgtFracW.
  input  logic [ValW-1:0]                   b_i,
  /// Weight, 2^WgtFracW is 1.0, for the item in the prep registers.
  input  logic [WgtFracW:0]                 e_i,
  /// Registered result: ValW + WgtFracW - RndShift bits.
  output logic [ValW+WgtFracW-RndShift-1:0] y_o
);

  localparam int unsigned BaseW = ValW + WgtFracW;
  localparam int unsigned AccW  = BaseW + 2;  // sign and headroom for base + e * diff
  localparam int unsigned YW    = BaseW - RndShift;

  if (RndShift > BaseW) begin : gen_bad_rnd_shift
    $fatal(1, "cube5_shader_lerp: RndShift must be at most ValW + WgtFracW");
  end

  localparam int unsigned Digits = (WgtFracW + 1) / 2;  // radix-4 digits of the fraction bits

  logic        [BaseW-1:0] base_d, base_q;
  logic signed [ValW:0]    diff_d, diff_q;
  logic signed [ValW+2:0]  diff3_d, diff3_q;
  logic signed [AccW-1:0]  acc, d1, d3, prod;
  logic        [YW-1:0]    y_d, y_q;

  always_comb begin
    base_d = {a_i, {WgtFracW{1'b0}}};
    if (RndShift > 0) begin
      base_d = base_d + (BaseW'(1) << (RndShift - 1));
    end
    diff_d  = $signed({1'b0, b_i}) - $signed({1'b0, a_i});
    diff3_d = {{2{diff_d[ValW]}}, diff_d} + {diff_d[ValW], diff_d, 1'b0};

    // e * diff: diff and 3 diff sign-extended; digit j (weight bits 2j, 2j + 1 below WgtFracW)
    // adds 0, 1, 2 or 3 diff shifted by 2j.
    d1   = {{(AccW - ValW - 1){diff_q[ValW]}}, diff_q};
    d3   = {{(AccW - ValW - 3){diff3_q[ValW+2]}}, diff3_q};
    prod = '0;
    for (int unsigned j = 0; j < Digits; j++) begin
      logic [1:0]      digit;
      logic [AccW-1:0] term;
      digit = {2 * j + 1 < WgtFracW && e_i[2*j+1], e_i[2*j]};
      unique case (digit)
        2'd0:    term = '0;
        2'd1:    term = d1;
        2'd2:    term = d1 << 1;
        default: term = d3;
      endcase
      prod = prod + (term << (2 * j));
    end
    if (e_i[WgtFracW]) begin
      prod = d1 << WgtFracW;
    end
    acc = $signed(AccW'(base_q)) + prod;
    y_d = YW'(acc >>> RndShift);
  end

  always_ff @(posedge clk_i) begin
    if (en_prep_i) begin
      base_q  <= base_d;
      diff_q  <= diff_d;
      diff3_q <= diff3_d;
    end
    if (en_mul_i) begin
      y_q <= y_d;
    end
  end

  assign y_o = y_q;

  // The sum is never negative and below 2^BaseW: its top bits are zero; the low RndShift bits
  // are the fraction rounded off.
  logic unused_acc;
  assign unused_acc = ^acc;

endmodule
