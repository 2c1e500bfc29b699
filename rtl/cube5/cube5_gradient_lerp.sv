// cube5_gradient_lerp: one exact linear interpolation, combinational (docs/numerics/gradient.md,
// N10). Unlike cube5_lerp it does not round: y = a * 2^WeightW + e * (b - a), so y / 2^WeightW lies
// between a and b and the result keeps every bit (the N10 resampling is rounded once, at the end).
module cube5_gradient_lerp #(
  /// Width of a and b (unsigned).
  parameter int unsigned ValW    = 16,
  /// Fraction bits of the weight; the effective weight e runs 0 ..= 2^WeightW.
  parameter int unsigned WeightW = 8
) (
  /// Endpoint at e = 0.
  input  logic [ValW-1:0]         a_i,
  /// Endpoint at e = 2^WeightW.
  input  logic [ValW-1:0]         b_i,
  /// Effective weight, 2^WeightW is 1.0.
  input  logic [WeightW:0]        e_i,
  /// Interpolated value on the scale 2^WeightW, exact.
  output logic [ValW+WeightW-1:0] y_o
);

  // |e * (b - a)| <= 2^WeightW * (2^ValW - 1): a sign bit and one bit of headroom above ValW+WeightW.
  localparam int unsigned SumW = ValW + WeightW + 2;

  logic signed [ValW:0]   diff;
  logic signed [SumW-1:0] delta;
  logic        [SumW-1:0] total;

  always_comb begin
    diff  = $signed({1'b0, b_i}) - $signed({1'b0, a_i});
    delta = SumW'($signed({1'b0, e_i}) * diff);
    total = {2'b00, a_i, {WeightW{1'b0}}} + delta;
  end

  // The sum lies in [0, max(a, b) * 2^WeightW]: the top two bits are always zero.
  assign y_o = total[ValW+WeightW-1:0];

  logic unused_total;
  assign unused_total = ^total[SumW-1 -: 2];

endmodule
