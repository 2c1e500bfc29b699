// cube5_shader_lerp: one exact linear interpolation of cube5_shader's bilinear lookup
// (docs/numerics/shader.md, § Bilinear interpolation), in two register stages so that the
// multiplier sits alone between registers:
//
//   prep:    base = a * 2^WgtFracW + rnd,   diff = b - a        (rnd = 2^(RndShift-1), or 0)
//   product: y    = (base + e * diff) >> RndShift
//
// i.e. y = (a * (2^WgtFracW - e) + b * e + rnd) >> RndShift with one signed multiplier. For e in
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

  logic        [BaseW-1:0] base_d, base_q;
  logic signed [ValW:0]    diff_d, diff_q;
  logic signed [AccW-1:0]  acc;
  logic        [YW-1:0]    y_d, y_q;

  always_comb begin
    base_d = {a_i, {WgtFracW{1'b0}}};
    if (RndShift > 0) begin
      base_d = base_d + (BaseW'(1) << (RndShift - 1));
    end
    diff_d = $signed({1'b0, b_i}) - $signed({1'b0, a_i});
    acc    = $signed(AccW'(base_q)) + AccW'(diff_q * $signed({1'b0, e_i}));
    y_d    = YW'(acc >>> RndShift);
  end

  always_ff @(posedge clk_i) begin
    if (en_prep_i) begin
      base_q <= base_d;
      diff_q <= diff_d;
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
