// gicube_scatter_refract: Snell's law's square root and total internal reflection
// (docs/numerics/gicube_scatter.md, Refraction; patent [28], [385]-[386]):
//   stage  12     t = rnd(eta^2 s2, 2M), k = |D|^2 - t; TIR iff k < 0
//   stages 13-16  (y, kk, m) = rsq(max(k, 0))
//   stage  17     sqrt(k) = rnd(m y, MF + YF - kk)
//   stage  18     coef = ec - sqrt(k)
module gicube_scatter_refract #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14,
  /// Fraction bits M of the material fields.
  parameter int unsigned M = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// s2 = max(|D|^2 - c^2, 0).
  input  logic [gicube_scatter_pkg::sq_w(F)-1:0] s2_i,
  /// |D|^2.
  input  logic [gicube_scatter_pkg::sq_w(F)-1:0] l2_i,
  /// eta^2, 2M fraction bits.
  input  logic [gicube_scatter_pkg::eta2_w(M)-1:0] e2_i,
  /// ec = rnd(eta c, M).
  input  logic [gicube_scatter_pkg::ec_w(F)-1:0] ec_i,
  /// SEED table write {we, index, value} (see gicube_scatter_rsqrt).
  input  logic [gicube_scatter_pkg::seed_wr_w(F)-1:0] seed_wr_i,
  /// coef = ec - sqrt(k), signed, RefractLatency stages after the inputs.
  output logic [gicube_scatter_pkg::ed_w(F)-1:0] coef_o,
  /// Total internal reflection (k < 0), delayed as coef_o.
  output logic tir_o
);

  localparam int unsigned L2W  = gicube_scatter_pkg::sq_w(F);
  localparam int unsigned E2W  = gicube_scatter_pkg::eta2_w(M);
  localparam int unsigned EcW  = gicube_scatter_pkg::ec_w(F);
  localparam int unsigned CoW  = gicube_scatter_pkg::ed_w(F);
  localparam int unsigned YF   = gicube_scatter_pkg::newton_frac_w(F);
  localparam int unsigned KW   = $clog2(L2W) + 1;
  localparam int unsigned CW   = F + 2;                  // sqrt(k), U(2.F)
  localparam int unsigned TW   = E2W + L2W;              // eta^2 s2
  localparam int unsigned SqPW = 2 * YF + 3;             // m y
  localparam int unsigned SqSW = SqPW + (L2W / 2);       // after << kk (kk < L2W / 2)

  // ---------------------------------------------------------------------------
  // Stage 12: k = |D|^2 - rnd(eta^2 s2, 2M); TIR iff k < 0
  // ---------------------------------------------------------------------------
  logic [TW-1:0]  t_full;
  logic [TW:0]    k_full;                    // signed: l2 - t
  logic [L2W-1:0] kq_d, kq_q;
  logic           tir_d;

  always_comb begin
    t_full = TW'(e2_i) * TW'(s2_i) + TW'(1 << (2 * M - 1));
    k_full = (TW+1)'(l2_i) - ((TW+1)'(t_full) >> (2 * M));
    tir_d  = k_full[TW];
    kq_d   = tir_d ? '0 : k_full[L2W-1:0];
  end

  // tir and ec wait beside rsq(k) and sqrt(k): stages 12-17.
  logic           tir_s17;
  logic [EcW-1:0] ec_s17;

  cube5_delay_regs #(
    .Width  (1 + EcW),
    .Stages (gicube_scatter_pkg::RsqLatency + 2)
  ) u_side_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({tir_d, ec_i}),
    .q_o   ({tir_s17, ec_s17})
  );

  // ---------------------------------------------------------------------------
  // Stages 13-16: rsq(k)
  // ---------------------------------------------------------------------------
  logic [YF:0]   yk;
  logic [KW-1:0] kk;
  logic [YF+1:0] mk;

  gicube_scatter_rsqrt #(
    .QW (L2W),
    .F  (F),
    .KW (KW)
  ) u_rsq_k (
    .clk_i     (clk_i),
    .en_i      (en_i),
    .q_i       (kq_q),
    .seed_wr_i (seed_wr_i),
    .y_o       (yk),
    .kk_o      (kk),
    .m_o       (mk)
  );

  // ---------------------------------------------------------------------------
  // Stage 17: the variable shift MF + YF - kk as a left shift by kk and a fixed 2 YF shift
  // ---------------------------------------------------------------------------
  logic [SqSW-1:0] sq_shifted;
  logic [CW-1:0]   sqrtk_d, sqrtk_q;

  always_comb begin
    sq_shifted = (SqSW'(SqPW'(mk) * SqPW'(yk)) << kk) + (SqSW'(1) << (2 * YF - 1));
    sqrtk_d    = sq_shifted[2 * YF +: CW];
  end

  // ---------------------------------------------------------------------------
  // Stage 18: coef = ec - sqrt(k)
  // ---------------------------------------------------------------------------
  logic [CoW-1:0] coef_d, coef_q;
  logic           tir_q;
  assign coef_d = CoW'(ec_s17) - CoW'(sqrtk_q);

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 12
      kq_q    <= kq_d;
      // Stage 17
      sqrtk_q <= sqrtk_d;
      // Stage 18
      coef_q  <= coef_d;
      tir_q   <= tir_s17;
    end
  end

  assign coef_o = coef_q;
  assign tir_o  = tir_q;

  // Bits below the roundings and above the contract's ranges.
  logic unused_refract;
  assign unused_refract = ^{t_full, k_full, sq_shifted};

endmodule
