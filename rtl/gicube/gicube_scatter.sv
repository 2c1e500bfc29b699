// gicube_scatter: the GI-Cube scattering unit (patent [28], [380], [385]-[386];
// docs/numerics/gicube_scatter.md). From a ray's direction, the estimated gradient and the
// sample's material it draws an event with random numbers mangled from the ray's bits (reflect,
// refract with total internal reflection falling back to reflection, isotropic from a random
// direction LUT, or pass), makes reflections and refractions glossy by a random rotation, and
// normalizes the result. No state besides the tables: each item is a pure function of its bits.
//
// A 42-stage pipeline that advances as a whole (one enable), one ray per clock when never
// stalled. This module holds the handshake, the configuration decode and the wiring; the stages
// are modules of their own (the table in the contract's Timing section), and fields that only
// wait for a later stage ride in cube5_delay_regs delay lines. Stage numbers in the banners and
// the `_sNN` suffixes are the register stages of the contract's timing table.
module gicube_scatter #(
  /// Direction fraction bits F: directions are S(2.F).
  parameter int unsigned DirFracW = 14,
  /// Gradient component bits, S(GradW.0).
  parameter int unsigned GradW    = 21,
  /// Fraction bits M of the material fields.
  parameter int unsigned MatW     = 8,
  /// Index bits A of the quarter-wave trigonometry table.
  parameter int unsigned AngW     = 8,
  /// Index bits I of the isotropic direction LUT.
  parameter int unsigned IsoW     = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Synchronous reset, active low: clears the valids only (no datapath or table reset).
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// dir[3] S(2.F), grad[3] S(GradW), refl, refr, iso, gloss U(1.M), eta U(2.M), ray_bits (32),
  /// LSB first.
  input  logic [gicube_scatter_pkg::in_w(DirFracW, GradW, MatW)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// dir[3] S(2.F), event (2), tir, zero_grad, zero_dir, LSB first.
  output logic [gicube_scatter_pkg::out_w(DirFracW)-1:0] out_data_o,

  /// Table write (SEED, TRIG, ISO; address map in the contract).
  input  logic cfg_valid_i,
  /// Table select [11:10], index [9:0].
  input  logic [gicube_scatter_pkg::CfgAddrW-1:0] cfg_addr_i,
  /// Table entry, LSB first.
  input  logic [gicube_scatter_pkg::cfg_data_w(DirFracW)-1:0] cfg_data_i
);

  localparam int unsigned F    = DirFracW;
  localparam int unsigned M    = MatW;
  localparam int unsigned A    = AngW;
  localparam int unsigned I    = IsoW;
  localparam int unsigned DW   = F + 2;       // direction component, S(2.F)
  localparam int unsigned MW1  = M + 1;       // U(1.M) material field
  localparam int unsigned ETW  = M + 2;       // eta, U(2.M)
  localparam int unsigned PhiW = A + 2;
  localparam int unsigned EW   = gicube_scatter_pkg::ev_w(F);
  localparam int unsigned L2W  = gicube_scatter_pkg::sq_w(F);
  localparam int unsigned E2W  = gicube_scatter_pkg::eta2_w(M);
  localparam int unsigned EcW  = gicube_scatter_pkg::ec_w(F);
  localparam int unsigned EdW  = gicube_scatter_pkg::ed_w(F);
  localparam int unsigned VvW  = gicube_scatter_pkg::vv_w(F);
  localparam int unsigned SI   = gicube_scatter_pkg::seed_idx_w(F);
  localparam int unsigned SF   = gicube_scatter_pkg::seed_frac_w(F);
  localparam int unsigned SWrW = gicube_scatter_pkg::seed_wr_w(F);
  localparam int unsigned L    = gicube_scatter_pkg::Latency;

  // Register stages of the stage modules (gicube_scatter_pkg); the delay lines are sized from them.
  localparam int unsigned NormL = gicube_scatter_pkg::NormLatency;
  localparam int unsigned SurfL = gicube_scatter_pkg::SurfaceLatency;
  localparam int unsigned RefrL = gicube_scatter_pkg::RefractLatency;
  localparam int unsigned SelL  = gicube_scatter_pkg::SelectLatency;
  localparam int unsigned FrmL  = gicube_scatter_pkg::FrameLatency;
  localparam int unsigned RotL  = gicube_scatter_pkg::RotateLatency;

  // Elaboration checks mirror ScatterConfig::validate in the model.
  if (DirFracW < 6 || DirFracW > 14) begin : gen_bad_f
    $fatal(1, "gicube_scatter: DirFracW must be 6..14");
  end
  if (GradW < 4 || GradW > 24) begin : gen_bad_grad_w
    $fatal(1, "gicube_scatter: GradW must be 4..24");
  end
  if (MatW < 4 || MatW > 10) begin : gen_bad_mat_w
    $fatal(1, "gicube_scatter: MatW must be 4..10");
  end
  if (AngW < 4 || AngW > 10 || AngW > 2 * MatW) begin : gen_bad_ang_w
    $fatal(1, "gicube_scatter: AngW must be 4..10 and at most 2 * MatW");
  end
  if (IsoW < 4 || IsoW > 10) begin : gen_bad_iso_w
    $fatal(1, "gicube_scatter: IsoW must be 4..10");
  end
  // The stage modules chain up to the contract's latency; the draw fits beside the first normalize.
  if (NormL + SurfL + RefrL + SelL + NormL + FrmL + RotL + NormL != L
      || gicube_scatter_pkg::DrawLatency > NormL) begin : gen_bad_latency
    $fatal(1, "gicube_scatter: the stage latencies do not add up to Latency");
  end

  // ---------------------------------------------------------------------------
  // Handshake: the whole pipeline advances when its last stage is empty or taken
  // ---------------------------------------------------------------------------
  logic         en;
  logic [L-1:0] vld_d, vld_q;

  assign en         = !vld_q[L-1] || out_ready_i;
  assign in_ready_o = en;
  assign vld_d      = en ? {vld_q[L-2:0], in_valid_i} : vld_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) vld_q <= '0;
    else         vld_q <= vld_d;
  end

  assign out_valid_o = vld_q[L-1];

  // ---------------------------------------------------------------------------
  // Configuration port: one write bus, three tables (five SEED copies)
  // ---------------------------------------------------------------------------
  logic [1:0]      cfg_sel;
  logic [10:0]     cfg_idx;  // one bit wider than the field so 2^10 compares correctly
  logic            seed_we, trig_we, iso_we;
  logic [SWrW-1:0] seed_wr;

  assign cfg_sel = cfg_addr_i[11:10];
  assign cfg_idx = {1'b0, cfg_addr_i[9:0]};
  assign seed_we = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelSeed
                   && cfg_idx < 11'(1 << SI);
  assign trig_we = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelTrig
                   && cfg_idx < 11'(1 << A);
  assign iso_we  = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelIso
                   && cfg_idx < 11'(1 << I);
  assign seed_wr = {seed_we, cfg_idx[SI-1:0], cfg_data_i[SF-1:0]};

  // ---------------------------------------------------------------------------
  // Input fields; |D|^2 and eta^2 (stage 0)
  // ---------------------------------------------------------------------------
  localparam int unsigned GradLsb = 3 * DW;
  localparam int unsigned ReflLsb = GradLsb + 3 * GradW;
  localparam int unsigned EtaLsb  = ReflLsb + 4 * MW1;
  localparam int unsigned RayLsb  = EtaLsb + ETW;

  logic [3*DW-1:0]    in_dir;
  logic [3*GradW-1:0] in_grad;
  logic [4*MW1-1:0]   in_mat;   // refl, refr, iso, gloss (raw)
  logic [ETW-1:0]     in_eta;
  logic [31:0]        in_ray;
  logic [L2W-1:0]     in_l2;
  logic [E2W-1:0]     in_e2;

  always_comb begin
    in_dir  = in_data_i[0 +: 3*DW];
    in_grad = in_data_i[GradLsb +: 3*GradW];
    in_mat  = in_data_i[ReflLsb +: 4*MW1];
    in_eta  = in_data_i[EtaLsb +: ETW];
    in_ray  = in_data_i[RayLsb +: 32];
    in_e2   = E2W'(in_eta) * E2W'(in_eta);
  end

  gicube_scatter_dot3 #(
    .VW (DW),
    .OW (L2W)
  ) u_l2 (
    .x_i (in_dir),
    .y_i (in_dir),
    .z_o (in_l2)
  );

  // ---------------------------------------------------------------------------
  // Stages 1-7: N = normalize(G); beside it the random draw (stages 1-4)
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] n_s7;
  logic            zg_s7;

  gicube_scatter_norm #(
    .VW (GradW),
    .F  (F)
  ) u_norm_g (
    .clk_i     (clk_i),
    .en_i      (en),
    .v_i       (in_grad),
    .seed_wr_i (seed_wr),
    .vn_o      (n_s7),
    .zero_o    (zg_s7)
  );

  logic [1:0]      drawn_s4;
  logic [A-1:0]    theta_s4;
  logic [PhiW-1:0] phi_s4;
  logic [I-1:0]    isoi_s4;

  gicube_scatter_draw #(
    .M (M),
    .A (A),
    .I (I)
  ) u_draw (
    .clk_i      (clk_i),
    .en_i       (en),
    .ray_bits_i (in_ray),
    .mat_i      (in_mat),
    .drawn_o    (drawn_s4),
    .theta_o    (theta_s4),
    .phi_o      (phi_s4),
    .iso_idx_o  (isoi_s4)
  );

  // Fields that wait: D, |D|^2, eta for the surface; eta^2 for the refraction; the random draw
  // and the zero-gradient flag for the event selection.
  localparam int unsigned RndW = 2 + A + PhiW + I;
  logic [3*DW-1:0] d_s7;
  logic [L2W-1:0]  l2_s7;
  logic [ETW-1:0]  eta_s7;
  logic [E2W-1:0]  e2_s11;
  logic [1:0]      drawn_s18;
  logic [A-1:0]    theta_s18;
  logic [PhiW-1:0] phi_s18;
  logic [I-1:0]    isoi_s18;
  logic            zg_s18;

  cube5_delay_regs #(
    .Width  (3*DW + L2W + ETW),
    .Stages (NormL)
  ) u_geo_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({in_eta, in_l2, in_dir}),
    .q_o   ({eta_s7, l2_s7, d_s7})
  );

  cube5_delay_regs #(
    .Width  (E2W),
    .Stages (NormL + SurfL)
  ) u_e2_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (in_e2),
    .q_o   (e2_s11)
  );

  cube5_delay_regs #(
    .Width  (RndW),
    .Stages (NormL - gicube_scatter_pkg::DrawLatency + SurfL + RefrL)
  ) u_rnd_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({isoi_s4, phi_s4, theta_s4, drawn_s4}),
    .q_o   ({isoi_s18, phi_s18, theta_s18, drawn_s18})
  );

  cube5_delay_regs #(
    .Width  (1),
    .Stages (SurfL + RefrL)
  ) u_zg_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (zg_s7),
    .q_o   (zg_s18)
  );

  // ---------------------------------------------------------------------------
  // Stages 8-11: dn, N', c; R, rnd(eta c, M), rnd(eta D, M); s2
  // ---------------------------------------------------------------------------
  logic [L2W-1:0]   s2_s11, l2_s11;
  logic [3*EW-1:0]  r_s11, r_s18;
  logic [3*DW-1:0]  d_s11, d_s18, np_s11, np_s18;
  logic [EcW-1:0]   ec_s11;
  logic [3*EdW-1:0] ed_s11, ed_s18;

  gicube_scatter_surface #(
    .F (F),
    .M (M)
  ) u_surface (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (d_s7),
    .n_i   (n_s7),
    .l2_i  (l2_s7),
    .eta_i (eta_s7),
    .s2_o  (s2_s11),
    .l2_o  (l2_s11),
    .r_o   (r_s11),
    .d_o   (d_s11),
    .np_o  (np_s11),
    .ec_o  (ec_s11),
    .ed_o  (ed_s11)
  );

  // The vectors of the event selection wait beside the refraction's square root.
  cube5_delay_regs #(
    .Width  (3*DW + 3*EdW + 3*DW + 3*EW),
    .Stages (RefrL)
  ) u_vec_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({np_s11, ed_s11, d_s11, r_s11}),
    .q_o   ({np_s18, ed_s18, d_s18, r_s18})
  );

  // ---------------------------------------------------------------------------
  // Stages 12-18: k, TIR; sqrt(k); coef
  // ---------------------------------------------------------------------------
  logic [EdW-1:0] coef_s18;
  logic           tir_s18;

  gicube_scatter_refract #(
    .F (F),
    .M (M)
  ) u_refract (
    .clk_i     (clk_i),
    .en_i      (en),
    .s2_i      (s2_s11),
    .l2_i      (l2_s11),
    .e2_i      (e2_s11),
    .ec_i      (ec_s11),
    .seed_wr_i (seed_wr),
    .coef_o    (coef_s18),
    .tir_o     (tir_s18)
  );

  // ---------------------------------------------------------------------------
  // Stages 19-20: T; the final event; E = D, R, T or ISO[iso_idx]
  // ---------------------------------------------------------------------------
  logic [3*EW-1:0] e_s20;
  logic [A-1:0]    theta_s20, theta_s27;
  logic [PhiW-1:0] phi_s20, phi_s27;
  logic [3:0]      flags_s20, flags_s42;

  gicube_scatter_select #(
    .F (F),
    .A (A),
    .I (I)
  ) u_select (
    .clk_i       (clk_i),
    .en_i        (en),
    .coef_i      (coef_s18),
    .np_i        (np_s18),
    .ed_i        (ed_s18),
    .r_i         (r_s18),
    .d_i         (d_s18),
    .tir_i       (tir_s18),
    .zero_grad_i (zg_s18),
    .drawn_i     (drawn_s18),
    .theta_i     (theta_s18),
    .phi_i       (phi_s18),
    .iso_idx_i   (isoi_s18),
    .iso_we_i    (iso_we),
    .iso_widx_i  (cfg_idx[I-1:0]),
    .iso_wdata_i (cfg_data_i[3*DW-1:0]),
    .e_o         (e_s20),
    .theta_o     (theta_s20),
    .phi_o       (phi_s20),
    .flags_o     (flags_s20)
  );

  // ---------------------------------------------------------------------------
  // Stages 21-27: Ê = normalize(E); the angles wait; the flags wait for the output
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] eh_s27;
  logic            ez_unused;

  gicube_scatter_norm #(
    .VW (EW),
    .F  (F)
  ) u_norm_e (
    .clk_i     (clk_i),
    .en_i      (en),
    .v_i       (e_s20),
    .seed_wr_i (seed_wr),
    .vn_o      (eh_s27),
    .zero_o    (ez_unused)
  );

  cube5_delay_regs #(
    .Width  (A + PhiW),
    .Stages (NormL)
  ) u_ang_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({phi_s20, theta_s20}),
    .q_o   ({phi_s27, theta_s27})
  );

  cube5_delay_regs #(
    .Width  (4),
    .Stages (NormL + FrmL + RotL + NormL)
  ) u_flags_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (flags_s20),
    .q_o   (flags_s42)
  );

  // ---------------------------------------------------------------------------
  // Stages 28-29: TRIG reads, the axis i; w, V, U
  // ---------------------------------------------------------------------------
  logic [L2W-1:0]   w_s29;
  logic [3*VvW-1:0] v_s29;
  logic [2*DW-1:0]  u_s29;
  logic [F:0]       ct_s29, st_s29;
  logic [DW-1:0]    cp_s29, sp_s29;
  logic [1:0]       axis_s29;
  logic [3*DW-1:0]  eh_s29;

  gicube_scatter_frame #(
    .F (F),
    .A (A)
  ) u_frame (
    .clk_i        (clk_i),
    .en_i         (en),
    .eh_i         (eh_s27),
    .theta_i      (theta_s27),
    .phi_i        (phi_s27),
    .trig_we_i    (trig_we),
    .trig_widx_i  (cfg_idx[A-1:0]),
    .trig_wdata_i (cfg_data_i[2*F+1:0]),
    .w_o          (w_s29),
    .v_o          (v_s29),
    .u_o          (u_s29),
    .ct_o         (ct_s29),
    .st_o         (st_s29),
    .cp_o         (cp_s29),
    .sp_o         (sp_s29),
    .axis_o       (axis_s29),
    .eh_o         (eh_s29)
  );

  // ---------------------------------------------------------------------------
  // Stages 30-35: B, rsq(w), sig; D' = rnd(cos(theta) Ê + sig B, F)
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] dp_s35;

  gicube_scatter_rotate #(
    .F (F)
  ) u_rotate (
    .clk_i     (clk_i),
    .en_i      (en),
    .w_i       (w_s29),
    .v_i       (v_s29),
    .u_i       (u_s29),
    .ct_i      (ct_s29),
    .st_i      (st_s29),
    .cp_i      (cp_s29),
    .sp_i      (sp_s29),
    .axis_i    (axis_s29),
    .eh_i      (eh_s29),
    .seed_wr_i (seed_wr),
    .dp_o      (dp_s35)
  );

  // ---------------------------------------------------------------------------
  // Stages 36-42: dir = normalize(D')
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] dir_s42;
  logic            zd_s42;

  gicube_scatter_norm #(
    .VW (DW),
    .F  (F)
  ) u_norm_out (
    .clk_i     (clk_i),
    .en_i      (en),
    .v_i       (dp_s35),
    .seed_wr_i (seed_wr),
    .vn_o      (dir_s42),
    .zero_o    (zd_s42)
  );

  assign out_data_o = {zd_s42, flags_s42, dir_s42};

  // Unused table data and the zero flag of E (E is never zero: |E| follows |D| or an ISO entry).
  logic unused_top;
  assign unused_top = ^{ez_unused, cfg_data_i, cfg_idx[10]};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_scatter: output changed while stalled");
`endif

endmodule
