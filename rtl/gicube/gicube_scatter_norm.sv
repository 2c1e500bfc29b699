// gicube_scatter_norm: normalize(V) of docs/numerics/gicube_scatter.md (patent [385]-[386]): a
// vector of signed integers to unit length in S(2.F), out_c = rnd(V_c y, kk + 3) with
// (y, kk) = rsq(sum V_c^2). Seven register stages: the sum of squares, rsq (four), the products,
// the rounding shift. The variable right shift by kk + 3 is done as a left shift by KMax - kk and
// a fixed rounding shift by KMax + 3 (the same integer; the model shifts right directly).
module gicube_scatter_norm #(
  /// Bits of each input component (two's complement).
  parameter int unsigned VW = 16,
  /// Direction fraction bits F of the output.
  parameter int unsigned F  = 14
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// V, component c at [c*VW +: VW].
  input  logic [3*VW-1:0] v_i,
  /// SEED table write {we, index, value} (see gicube_scatter_rsqrt).
  input  logic [gicube_scatter_pkg::seed_wr_w(F)-1:0] seed_wr_i,
  /// normalize(V), S(2.F) components, NormLatency stages after v_i.
  output logic [3*(F+2)-1:0] vn_o,
  /// V was the zero vector (then vn_o is zero too).
  output logic zero_o
);

  localparam int unsigned QW   = 2 * VW;           // sum of three squares < 2^(2 VW)
  localparam int unsigned KMax = VW - 1;           // largest kk
  localparam int unsigned KW   = $clog2(VW) + 1;
  localparam int unsigned YF   = gicube_scatter_pkg::newton_frac_w(F);
  localparam int unsigned PW   = VW + YF + 2;      // V_c * y, signed
  localparam int unsigned SW   = PW + KMax;        // after the left shift
  localparam int unsigned OW   = F + 2;

  if (VW < 2 || VW > 32) begin : gen_bad_vw
    $fatal(1, "gicube_scatter_norm: VW must be 2..32");
  end

  // ---------------------------------------------------------------------------
  // Stage 1: q = sum of squares
  // ---------------------------------------------------------------------------
  logic [QW-1:0]   q_d, q_q;
  logic [3*VW-1:0] v_q;
  logic            zero_d, zero_q;

  gicube_scatter_dot3 #(
    .VW (VW),
    .OW (QW)
  ) u_sum_sq (
    .x_i (v_i),
    .y_i (v_i),
    .z_o (q_d)
  );

  assign zero_d = (v_i == '0);

  // ---------------------------------------------------------------------------
  // Stages 2-5: rsq(q); V and the zero flag wait beside it
  // ---------------------------------------------------------------------------
  logic [YF:0]     y;
  logic [KW-1:0]   kk;
  logic [YF+1:0]   m_unused;
  logic [3*VW-1:0] v_s5;
  logic            zero_s5;

  gicube_scatter_rsqrt #(
    .QW (QW),
    .F  (F),
    .KW (KW)
  ) u_rsqrt (
    .clk_i     (clk_i),
    .en_i      (en_i),
    .q_i       (q_q),
    .seed_wr_i (seed_wr_i),
    .y_o       (y),
    .kk_o      (kk),
    .m_o       (m_unused)
  );

  cube5_delay_regs #(
    .Width  (3*VW + 1),
    .Stages (gicube_scatter_pkg::RsqLatency)
  ) u_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({zero_q, v_q}),
    .q_o   ({zero_s5, v_s5})
  );

  // ---------------------------------------------------------------------------
  // Stage 6: products V_c * y
  // ---------------------------------------------------------------------------
  logic [3*PW-1:0] prod_d, prod_q;
  logic [KW-1:0]   kk_q;
  logic            zero_q2;

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [PW-1:0] vc, ys;
      vc = {{(PW-VW){v_s5[c*VW + VW-1]}}, v_s5[c*VW +: VW]};
      ys = PW'({1'b0, y});
      prod_d[c*PW +: PW] = vc * ys;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 7: out_c = rnd(prod_c, kk + 3)
  // ---------------------------------------------------------------------------
  logic [3*OW-1:0] out_d, out_q;
  logic [3*SW-1:0] sum_d;  // kept whole for the unused-bit tie-off
  logic            zero_q3;

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic [SW-1:0] shifted;
      shifted = {{KMax{prod_q[c*PW + PW-1]}}, prod_q[c*PW +: PW]} << (KMax - 32'(kk_q));
      sum_d[c*SW +: SW]  = shifted + (SW'(1) << (KMax + 2));
      out_d[c*OW +: OW]  = sum_d[c*SW + KMax + 3 +: OW];
    end
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 1
      q_q     <= q_d;
      v_q     <= v_i;
      zero_q  <= zero_d;
      // Stage 6
      prod_q  <= prod_d;
      kk_q    <= kk;
      zero_q2 <= zero_s5;
      // Stage 7
      out_q   <= out_d;
      zero_q3 <= zero_q2;
    end
  end

  assign vn_o   = out_q;
  assign zero_o = zero_q3;

  logic unused_norm;
  assign unused_norm = ^{m_unused, sum_d};

endmodule
