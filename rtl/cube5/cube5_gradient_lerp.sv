// cube5_gradient_lerp: one exact linear interpolation in difference form, combinational
// (docs/numerics/gradient.md, N10):
//   y = a * 2^WeightW + e * d + Bias,   d = b - a given by the caller
// Unlike cube5_lerp it does not round and takes the difference ready-made, so the stage is one
// multiply and one sum (the caller computes d a stage earlier, off the critical path). Bias lets the
// last lerp of N10 add its rounding half in the same sum.
module cube5_gradient_lerp #(
  /// Width of a, two's complement.
  parameter int unsigned ValW    = 16,
  /// Width of d = b - a, two's complement.
  parameter int unsigned DiffW   = 17,
  /// Fraction bits of the weight; the effective weight e runs 0 ..= 2^WeightW.
  parameter int unsigned WeightW = 8,
  /// Output width; the caller guarantees |y| < 2^(OutW-1).
  parameter int unsigned OutW    = 24,
  /// Constant added to the sum.
  parameter int unsigned Bias    = 0
) (
  /// Endpoint at e = 0.
  input  logic signed [ValW-1:0]  a_i,
  /// b - a, where b is the endpoint at e = 2^WeightW.
  input  logic signed [DiffW-1:0] d_i,
  /// Effective weight, 2^WeightW is 1.0.
  input  logic        [WeightW:0] e_i,
  /// a * 2^WeightW + e * d + Bias, exact.
  output logic signed [OutW-1:0]  y_o
);

  // The sum is computed modulo 2^OutW: partial sums may leave the range, the result does not.
  logic signed [OutW-1:0] prod, total;

  always_comb begin
    prod  = OutW'($signed({1'b0, e_i}) * d_i);
    total = (OutW'(a_i) <<< WeightW) + prod + $signed(OutW'(Bias));
  end

  assign y_o = total;

endmodule
