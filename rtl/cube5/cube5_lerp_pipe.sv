// cube5_lerp_pipe: N rounded linear interpolations sharing one weight, cube5_lerp's arithmetic
// (docs/numerics.md, `lerp`: y = rnd(a * 2^WeightW + e * (b - a), WeightW)) in three register
// stages, so that every multiplier sits between registers: the difference b - a, the product
// e (b - a), the rounded sum. The bits are cube5_lerp's. The caller's valid chain gives the three
// stages' enables; a side payload travels beside the items (latency 3, like the items).
module cube5_lerp_pipe #(
  /// Interpolations side by side.
  parameter int unsigned N       = 1,
  /// Width of a, b and y.
  parameter int unsigned ValW    = 16,
  /// Fraction bits of the weight; the effective weight e runs 0 ..= 2^WeightW.
  parameter int unsigned WeightW = 8,
  /// Width of the side payload.
  parameter int unsigned SideW   = 1
) (
  input  logic clk_i,

  /// Stage k takes its input this cycle (k = 0: the difference, 1: the product, 2: the sum).
  input  logic [2:0]        en_i,
  /// Endpoints at e = 0 and e = 2^WeightW, interpolation i at [i*ValW +: ValW].
  input  logic [N*ValW-1:0] a_i,
  input  logic [N*ValW-1:0] b_i,
  /// Effective weight, 2^WeightW is 1.0.
  input  logic [WeightW:0]  e_i,
  input  logic [SideW-1:0]  side_i,
  /// Interpolated values, rounded half up (registered: stage 2's output).
  output logic [N*ValW-1:0] y_o,
  output logic [SideW-1:0]  side_o
);

  // Signed intermediate, as cube5_lerp: |e * (b - a)| < 2^(ValW + WeightW), plus sign and headroom.
  localparam int unsigned SumW  = ValW + WeightW + 2;
  localparam int unsigned DiffW = ValW + 1;

  // Stage 0: the differences, the low endpoints, the weight.
  logic [N*DiffW-1:0] diff_d, diff_q;
  logic [N*ValW-1:0]  a0_q, a1_q;
  logic [WeightW:0]   e0_q;
  logic [SideW-1:0]   side0_q, side1_q, side2_q;
  // Stage 1: the products. Stage 2: the rounded sums.
  logic [N*SumW-1:0]  prod_d, prod_q;
  logic [N*ValW-1:0]  y_d, y_q;
  logic [N*SumW-1:0]  total;

  always_comb begin
    for (int unsigned i = 0; i < N; i++) begin
      logic signed [DiffW-1:0] diff;
      logic signed [SumW-1:0]  delta;
      logic        [SumW-1:0]  base_u;
      diff = $signed({1'b0, b_i[i*ValW +: ValW]}) - $signed({1'b0, a_i[i*ValW +: ValW]});
      diff_d[i*DiffW +: DiffW] = diff;
      delta = SumW'($signed({1'b0, e0_q}) * $signed(diff_q[i*DiffW +: DiffW]));
      prod_d[i*SumW +: SumW] = delta;
      base_u = {2'b00, a1_q[i*ValW +: ValW], {WeightW{1'b0}}};
      total[i*SumW +: SumW] = base_u + prod_q[i*SumW +: SumW] + SumW'(1 << (WeightW - 1));
      y_d[i*ValW +: ValW] = total[i*SumW + WeightW +: ValW];
    end
  end

  // Datapath registers (not reset; the caller's valid chain holds the valids).
  always_ff @(posedge clk_i) begin
    if (en_i[0]) begin
      diff_q  <= diff_d;
      a0_q    <= a_i;
      e0_q    <= e_i;
      side0_q <= side_i;
    end
    if (en_i[1]) begin
      prod_q  <= prod_d;
      a1_q    <= a0_q;
      side1_q <= side0_q;
    end
    if (en_i[2]) begin
      y_q     <= y_d;
      side2_q <= side1_q;
    end
  end

  assign y_o    = y_q;
  assign side_o = side2_q;

  // The sum is in [0, max(a, b) * 2^WeightW + 2^(WeightW-1)]: the top two bits are always zero and
  // the low WeightW bits are the discarded fraction.
  logic unused_total;
  always_comb begin
    unused_total = 1'b0;
    for (int unsigned i = 0; i < N; i++) begin
      unused_total = unused_total ^ (^{total[i*SumW + SumW - 2 +: 2], total[i*SumW +: WeightW]});
    end
  end

endmodule
