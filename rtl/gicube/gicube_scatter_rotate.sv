// gicube_scatter_rotate: the glossy rotation D' = cos(theta) Ê + sin(theta) B / sqrt(w)
// (docs/numerics/gicube_scatter.md, The event's direction and glossy rotation; patent [28],
// [385]-[386]):
//   stage  30     B = rnd(cos(phi) U + sin(phi) V, F), back in x, y, z order; rsq(w) starts
//   stages 31-33  rsq(w)
//   stage  34     sig = rnd(sin(theta) yw, kw + 3) = sin(theta) / sqrt(w)
//   stage  35     D' = rnd(cos(theta) Ê + sig B, F)
module gicube_scatter_rotate #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// w = b^2 + cc^2, 2F fraction bits.
  input  logic [gicube_scatter_pkg::sq_w(F)-1:0] w_i,
  /// V_i, V_j, V_k, signed.
  input  logic [3*gicube_scatter_pkg::vv_w(F)-1:0] v_i,
  /// U_j, U_k, S(2.F).
  input  logic [2*(F+2)-1:0] u_i,
  /// cos(theta), U(1.F).
  input  logic [F:0] ct_i,
  /// sin(theta), U(1.F).
  input  logic [F:0] st_i,
  /// cos(phi), S(2.F).
  input  logic [F+1:0] cp_i,
  /// sin(phi), S(2.F).
  input  logic [F+1:0] sp_i,
  /// The axis i of the (i, j, k) frame.
  input  logic [1:0] axis_i,
  /// Ê, S(2.F) components.
  input  logic [3*(F+2)-1:0] eh_i,
  /// SEED table write {we, index, value} (see gicube_scatter_rsqrt).
  input  logic [gicube_scatter_pkg::seed_wr_w(F)-1:0] seed_wr_i,
  /// D', S(2.F) components, RotateLatency stages after the inputs.
  output logic [3*(F+2)-1:0] dp_o
);

  localparam int unsigned DW    = F + 2;
  localparam int unsigned L2W   = gicube_scatter_pkg::sq_w(F);
  localparam int unsigned VvW   = gicube_scatter_pkg::vv_w(F);
  localparam int unsigned BW    = gicube_scatter_pkg::vv_w(F);  // B components, signed
  localparam int unsigned YF    = gicube_scatter_pkg::newton_frac_w(F);
  localparam int unsigned KW    = $clog2(L2W) + 1;
  localparam int unsigned BpW   = DW + VvW + 2;
  localparam int unsigned KwMax = L2W / 2 - 1;
  localparam int unsigned SgPW  = (F + 1) + (YF + 1);
  localparam int unsigned SgSW  = SgPW + KwMax;
  localparam int unsigned SgW   = F + 3;                        // sig, U(3.F)
  localparam int unsigned DpW   = SgW + BW + 2;
  localparam int unsigned SideW = 3*BW + 2*(F + 1) + 3*DW;      // B, ct, st, Ê

  // ---------------------------------------------------------------------------
  // Stages 30-33: rsq(w); stage 30 also forms B
  // ---------------------------------------------------------------------------
  logic [YF:0]   yw;
  logic [KW-1:0] kw;
  logic [YF+1:0] mw_unused;

  gicube_scatter_rsqrt #(
    .QW (L2W),
    .F  (F),
    .KW (KW)
  ) u_rsq_w (
    .clk_i     (clk_i),
    .en_i      (en_i),
    .q_i       (w_i),
    .seed_wr_i (seed_wr_i),
    .y_o       (yw),
    .kk_o      (kw),
    .m_o       (mw_unused)
  );

  logic [3*BW-1:0]       bw_d, bw_q, bw_s33, bw_q2;   // B in x, y, z order
  logic signed [BpW-1:0] bi, bj, bk;         // B_i, B_j, B_k plus half, before the rounding shift

  always_comb begin
    logic signed [BpW-1:0] cp, sp, uj, uk, vi, vj, vk;
    logic [3*BW-1:0] frame;                  // B_i, B_j, B_k
    cp = {{(BpW-DW){cp_i[DW-1]}}, cp_i};
    sp = {{(BpW-DW){sp_i[DW-1]}}, sp_i};
    uj = {{(BpW-DW){u_i[DW-1]}}, u_i[0 +: DW]};
    uk = {{(BpW-DW){u_i[2*DW-1]}}, u_i[DW +: DW]};
    vi = {{(BpW-VvW){v_i[0*VvW + VvW-1]}}, v_i[0*VvW +: VvW]};
    vj = {{(BpW-VvW){v_i[1*VvW + VvW-1]}}, v_i[1*VvW +: VvW]};
    vk = {{(BpW-VvW){v_i[2*VvW + VvW-1]}}, v_i[2*VvW +: VvW]};
    bi = sp * vi + BpW'(1 << (F - 1));
    bj = cp * uj + sp * vj + BpW'(1 << (F - 1));
    bk = cp * uk + sp * vk + BpW'(1 << (F - 1));
    frame = {bk[F +: BW], bj[F +: BW], bi[F +: BW]};
    unique case (axis_i)
      2'd1:    bw_d = {frame[1*BW +: BW], frame[0*BW +: BW], frame[2*BW +: BW]};
      2'd2:    bw_d = {frame[0*BW +: BW], frame[2*BW +: BW], frame[1*BW +: BW]};
      default: bw_d = frame;
    endcase
  end

  // B, cos(theta), sin(theta) and Ê wait beside rsq(w): stages 31-33.
  logic [F:0]      ct_q, ct_s33, ct_q2, st_q, st_s33;
  logic [3*DW-1:0] eh_q, eh_s33, eh_q2;

  cube5_delay_regs #(
    .Width  (SideW),
    .Stages (gicube_scatter_pkg::RsqLatency - 1)
  ) u_side_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({eh_q, st_q, ct_q, bw_q}),
    .q_o   ({eh_s33, st_s33, ct_s33, bw_s33})
  );

  // ---------------------------------------------------------------------------
  // Stage 34: sig = rnd(sin(theta) yw, kw + 3) = sin(theta) / sqrt(w)
  // ---------------------------------------------------------------------------
  logic [SgSW-1:0] sg_shifted;
  logic [SgW-1:0]  sig_d, sig_q;

  always_comb begin
    sg_shifted = (SgSW'(SgPW'(st_s33) * SgPW'(yw)) << (KwMax - 32'(kw)))
                 + (SgSW'(1) << (KwMax + 2));
    sig_d      = sg_shifted[KwMax + 3 +: SgW];
  end

  // ---------------------------------------------------------------------------
  // Stage 35: D' = rnd(cos(theta) Ê + sig B, F)
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0]  dp_d, dp_q;
  logic [3*DpW-1:0] dps_all;                 // cos(theta) Ê + sig B plus half, per component

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [DpW-1:0] ct, eh, sg, bc;
      ct  = DpW'({1'b0, ct_q2});
      eh  = {{(DpW-DW){eh_q2[c*DW + DW-1]}}, eh_q2[c*DW +: DW]};
      sg  = DpW'({1'b0, sig_q});
      bc  = {{(DpW-BW){bw_q2[c*BW + BW-1]}}, bw_q2[c*BW +: BW]};
      dps_all[c*DpW +: DpW] = ct * eh + sg * bc + DpW'(1 << (F - 1));
      dp_d[c*DW +: DW]      = dps_all[c*DpW + F +: DW];
    end
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 30
      bw_q  <= bw_d;
      ct_q  <= ct_i;
      st_q  <= st_i;
      eh_q  <= eh_i;
      // Stage 34
      sig_q <= sig_d;
      bw_q2 <= bw_s33;
      ct_q2 <= ct_s33;
      eh_q2 <= eh_s33;
      // Stage 35
      dp_q  <= dp_d;
    end
  end

  assign dp_o = dp_q;

  // Bits below the roundings and above the contract's ranges.
  logic unused_rotate;
  assign unused_rotate = ^{bi, bj, bk, sg_shifted, dps_all, mw_unused};

endmodule
