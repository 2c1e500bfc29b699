// cube5_lerp: one rounded linear interpolation, combinational (docs/numerics.md, `lerp`).
//
// y = rnd(a * 2^WeightW + e * (b - a), WeightW): the one-multiplier form of the contract's
// a * (2^WeightW - e) + b * e. The result lies between a and b, so no saturation is needed.
module cube5_lerp #(
  /// Width of a, b and y (any fixed-point format; the fraction is carried through).
  parameter int unsigned ValW    = 16,
  /// Fraction bits of the weight; the effective weight e runs 0 ..= 2^WeightW.
  parameter int unsigned WeightW = 8
) (
  /// Endpoint at e = 0.
  input  logic [ValW-1:0]    a_i,
  /// Endpoint at e = 2^WeightW.
  input  logic [ValW-1:0]    b_i,
  /// Effective weight, 2^WeightW is 1.0.
  input  logic [WeightW:0]   e_i,
  /// Interpolated value, rounded half up.
  output logic [ValW-1:0]    y_o
);

  // Signed intermediate: |e * (b - a)| < 2^(ValW + WeightW), plus sign and headroom.
  localparam int unsigned SumW = ValW + WeightW + 2;

  logic        [SumW-1:0] base_u;
  logic signed [ValW:0]   diff;
  logic signed [SumW-1:0] delta;
  logic        [SumW-1:0] total;

  always_comb begin
    base_u = {2'b00, a_i, {WeightW{1'b0}}};
    diff   = $signed({1'b0, b_i}) - $signed({1'b0, a_i});
    delta  = SumW'($signed({1'b0, e_i}) * diff);
    total  = base_u + delta + SumW'(1 << (WeightW - 1));
  end

  assign y_o = total[WeightW +: ValW];

  // The sum is in [0, max(a, b) * 2^WeightW + 2^(WeightW-1)]: the top two bits are always zero and
  // the low WeightW bits are the discarded fraction.
  logic unused_total;
  assign unused_total = ^{total[SumW-1 -: 2], total[WeightW-1:0]};

endmodule
