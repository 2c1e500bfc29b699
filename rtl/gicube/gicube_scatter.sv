// gicube_scatter: the GI-Cube scattering unit (patent [28], [380], [385]-[386];
// docs/numerics/gicube_scatter.md). From a ray's direction, the estimated gradient and the
// sample's material it draws an event with random numbers mangled from the ray's bits (reflect,
// refract with total internal reflection falling back to reflection, isotropic from a random
// direction LUT, or pass), makes reflections and refractions glossy by a random rotation, and
// normalizes the result. No state besides the tables: each item is a pure function of its bits.
//
// A 42-stage pipeline that advances as a whole (one enable), one ray per clock when never
// stalled. Stage numbers in the banners are the register stages of the contract's timing table.
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
  input  logic clk_i,
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

  localparam int unsigned F   = DirFracW;
  localparam int unsigned M   = MatW;
  localparam int unsigned A   = AngW;
  localparam int unsigned I   = IsoW;
  localparam int unsigned DW  = F + 2;       // direction component, S(2.F)
  localparam int unsigned EW  = F + 6;       // event direction component, S(6.F)
  localparam int unsigned MW1 = M + 1;       // U(1.M) material field
  localparam int unsigned ETW = M + 2;       // eta, U(2.M)
  localparam int unsigned L2W = 2 * F + 4;   // |D|^2, k, s2, w: 2F fraction bits
  localparam int unsigned E2W = 2 * M + 4;   // eta^2
  localparam int unsigned SI  = gicube_scatter_pkg::seed_idx_w(F);
  localparam int unsigned SF  = gicube_scatter_pkg::seed_frac_w(F);
  localparam int unsigned YF  = gicube_scatter_pkg::newton_frac_w(F);
  localparam int unsigned KW  = $clog2(L2W) + 1;
  localparam int unsigned L   = gicube_scatter_pkg::Latency;

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
  logic [1:0]  cfg_sel;
  logic [10:0] cfg_idx;  // one bit wider than the field so 2^10 compares correctly
  logic        seed_we, trig_we, iso_we;

  assign cfg_sel = cfg_addr_i[11:10];
  assign cfg_idx = {1'b0, cfg_addr_i[9:0]};
  assign seed_we = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelSeed
                   && cfg_idx < 11'(1 << SI);
  assign trig_we = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelTrig
                   && cfg_idx < 11'(1 << A);
  assign iso_we  = cfg_valid_i && cfg_sel == gicube_scatter_pkg::CfgSelIso
                   && cfg_idx < 11'(1 << I);

  logic [SI-1:0] seed_idx;
  logic [SF-1:0] seed_val;
  assign seed_idx = cfg_idx[SI-1:0];
  assign seed_val = cfg_data_i[SF-1:0];

  logic [3*DW-1:0] iso_q [2**I];
  always_ff @(posedge clk_i) begin
    if (iso_we) iso_q[cfg_idx[I-1:0]] <= cfg_data_i[3*DW-1:0];
  end

  // ---------------------------------------------------------------------------
  // Input fields
  // ---------------------------------------------------------------------------
  localparam int unsigned GradLsb  = 3 * DW;
  localparam int unsigned ReflLsb  = GradLsb + 3 * GradW;
  localparam int unsigned RefrLsb  = ReflLsb + MW1;
  localparam int unsigned IsoLsb   = RefrLsb + MW1;
  localparam int unsigned GlossLsb = IsoLsb + MW1;
  localparam int unsigned EtaLsb   = GlossLsb + MW1;
  localparam int unsigned RayLsb   = EtaLsb + ETW;

  logic [3*DW-1:0]    in_dir;
  logic [3*GradW-1:0] in_grad;
  logic [ETW-1:0]     in_eta;
  logic [4*MW1-1:0]   in_mat;   // refl', refr', iso', gloss' (saturated to 2^M)
  logic [L2W-1:0]     in_l2;
  logic [E2W-1:0]     in_e2;

  always_comb begin
    in_dir  = in_data_i[0 +: 3*DW];
    in_grad = in_data_i[GradLsb +: 3*GradW];
    in_eta  = in_data_i[EtaLsb +: ETW];
    for (int unsigned f = 0; f < 4; f++) begin
      logic [MW1-1:0] raw;
      raw = in_data_i[ReflLsb + f*MW1 +: MW1];
      in_mat[f*MW1 +: MW1] = raw[M] ? MW1'(1 << M) : raw;
    end
    in_l2 = '0;
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [L2W-1:0] dc;
      dc    = {{(L2W-DW){in_dir[c*DW + DW-1]}}, in_dir[c*DW +: DW]};
      in_l2 = in_l2 + L2W'(dc * dc);
    end
    in_e2 = E2W'(in_eta) * E2W'(in_eta);
  end

  // ---------------------------------------------------------------------------
  // Stages 1-7: the normal N = normalize(G); hash; event draw; glossy angle
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] n_s7;
  logic            zg_s7;

  gicube_scatter_norm #(
    .VW (GradW),
    .F  (F)
  ) u_norm_g (
    .clk_i      (clk_i),
    .en_i       (en),
    .v_i        (in_grad),
    .cfg_we_i   (seed_we),
    .cfg_idx_i  (seed_idx),
    .cfg_seed_i (seed_val),
    .vn_o       (n_s7),
    .zero_o     (zg_s7)
  );

  logic [95:0] pool_s2;

  gicube_scatter_hash u_hash (
    .clk_i      (clk_i),
    .en_i       (en),
    .ray_bits_i (in_data_i[RayLsb +: 32]),
    .pool_o     (pool_s2)
  );

  // The geometric fields wait for the normal: D, |D|^2, eta, eta^2.
  localparam int unsigned GeoW = 3*DW + L2W + ETW + E2W;
  logic [GeoW-1:0] geo_s7;

  gicube_scatter_pipe #(
    .W (GeoW),
    .N (7)
  ) u_geo_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({in_e2, in_eta, in_l2, in_dir}),
    .q_o   (geo_s7)
  );

  logic [4*MW1-1:0] mat_s2;

  gicube_scatter_pipe #(
    .W (4*MW1),
    .N (2)
  ) u_mat_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (in_mat),
    .q_o   (mat_s2)
  );

  // Stage 3: the drawn event, the folded Irwin-Hall value h, phi and the ISO index.
  localparam int unsigned PhiW = A + 2;
  localparam int unsigned PhiLsb = 7 * M;
  localparam int unsigned IsoIdxLsb = PhiLsb + PhiW;

  logic [1:0]      drawn_s3;
  logic [M:0]      h_s3;
  logic [PhiW-1:0] phi_s3;
  logic [I-1:0]    isoi_s3;
  logic [MW1-1:0]  gloss_s3;
  logic [1:0]      drawn_d;
  logic [M:0]      h_d;

  always_comb begin
    logic [M+2:0] s;  // sum of four M-bit uniforms, plus the +2 and the sign of the fold
    logic [M-1:0] r1, r2, r3;
    r1 = pool_s2[0 +: M];
    r2 = pool_s2[M +: M];
    r3 = pool_s2[2*M +: M];
    if ({1'b0, r1} < mat_s2[0 +: MW1])            drawn_d = gicube_scatter_pkg::EvReflect;
    else if ({1'b0, r2} < mat_s2[MW1 +: MW1])     drawn_d = gicube_scatter_pkg::EvRefract;
    else if ({1'b0, r3} < mat_s2[2*MW1 +: MW1])   drawn_d = gicube_scatter_pkg::EvIso;
    else                                          drawn_d = gicube_scatter_pkg::EvPass;
    s = (M+3)'(pool_s2[3*M +: M]) + (M+3)'(pool_s2[4*M +: M]) + (M+3)'(pool_s2[5*M +: M])
        + (M+3)'(pool_s2[6*M +: M]) + (M+3)'(2);
    // h = |s - 2^(M+1)|: s lies in [2, 4 (2^M - 1) + 2] < 2^(M+2).
    h_d = (s >= (M+3)'(2 << M)) ? (M+1)'(s - (M+3)'(2 << M)) : (M+1)'((M+3)'(2 << M) - s);
  end

  always_ff @(posedge clk_i) begin
    if (en) begin
      drawn_s3 <= drawn_d;
      h_s3     <= h_d;
      phi_s3   <= pool_s2[PhiLsb +: PhiW];
      isoi_s3  <= pool_s2[IsoIdxLsb +: I];
      gloss_s3 <= mat_s2[3*MW1 +: MW1];
    end
  end

  // Stage 4: theta = min(rnd(gloss' h, 2M + 1 - A), 2^A - 1).
  localparam int unsigned ThW = 2 * M + 2;   // gloss' h < 2^(2M+2)
  localparam int unsigned ThShift = 2 * M + 1 - A;

  logic [A-1:0] theta_d, theta_s4;
  logic [1:0]   drawn_s4;
  logic [PhiW-1:0] phi_s4;
  logic [I-1:0] isoi_s4;
  logic [ThW:0] th_full;

  always_comb begin
    th_full = (ThW+1)'(gloss_s3) * (ThW+1)'(h_s3) + (ThW+1)'(1 << (ThShift - 1));
    if ((th_full >> ThShift) >= (ThW+1)'(1 << A)) theta_d = '1;
    else                                           theta_d = th_full[ThShift +: A];
  end

  always_ff @(posedge clk_i) begin
    if (en) begin
      theta_s4 <= theta_d;
      drawn_s4 <= drawn_s3;
      phi_s4   <= phi_s3;
      isoi_s4  <= isoi_s3;
    end
  end

  // The random fields wait for the stages that use them.
  localparam int unsigned RndW = 2 + A + PhiW + I;
  logic [RndW-1:0] rnd_s7;

  gicube_scatter_pipe #(
    .W (RndW),
    .N (3)
  ) u_rnd_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({isoi_s4, phi_s4, theta_s4, drawn_s4}),
    .q_o   (rnd_s7)
  );

  logic [3*DW-1:0] d_s7;
  logic [L2W-1:0]  l2_s7;
  logic [ETW-1:0]  eta_s7;
  logic [E2W-1:0]  e2_s7;
  assign {e2_s7, eta_s7, l2_s7, d_s7} = geo_s7;

  // ---------------------------------------------------------------------------
  // Stage 8: dn = D . N
  // ---------------------------------------------------------------------------
  localparam int unsigned DnW = 2 * DW + 2;
  logic signed [DnW-1:0] dn_d, dn_s8;

  always_comb begin
    dn_d = '0;
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [DnW-1:0] dc, nc;
      dc   = {{(DnW-DW){d_s7[c*DW + DW-1]}}, d_s7[c*DW +: DW]};
      nc   = {{(DnW-DW){n_s7[c*DW + DW-1]}}, n_s7[c*DW +: DW]};
      dn_d = dn_d + dc * nc;
    end
  end

  logic [3*DW-1:0] d_s8, n_s8;
  logic [L2W-1:0]  l2_s8;
  logic [ETW-1:0]  eta_s8;
  logic [E2W-1:0]  e2_s8;
  logic            zg_s8;
  logic [RndW-1:0] rnd_s8;

  always_ff @(posedge clk_i) begin
    if (en) begin
      dn_s8  <= dn_d;
      d_s8   <= d_s7;
      n_s8   <= n_s7;
      l2_s8  <= l2_s7;
      eta_s8 <= eta_s7;
      e2_s8  <= e2_s7;
      zg_s8  <= zg_s7;
      rnd_s8 <= rnd_s7;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 9: turn the normal to face the ray; c = rnd(|dn|, F)
  // ---------------------------------------------------------------------------
  localparam int unsigned CW = F + 2;        // c, U(2.F)
  logic [CW-1:0]   c_d, c_s9;
  logic [3*DW-1:0] np_d, np_s9;
  logic [DnW-1:0]  absdn;

  always_comb begin
    logic flip;
    flip  = !dn_s8[DnW-1] && dn_s8 != '0;
    absdn = dn_s8[DnW-1] ? DnW'(-dn_s8) : DnW'(dn_s8);
    c_d   = CW'((absdn + DnW'(1 << (F - 1))) >> F);
    for (int unsigned c = 0; c < 3; c++) begin
      np_d[c*DW +: DW] = flip ? DW'(-$signed(n_s8[c*DW +: DW])) : n_s8[c*DW +: DW];
    end
  end

  logic [3*DW-1:0] d_s9;
  logic [L2W-1:0]  l2_s9;
  logic [ETW-1:0]  eta_s9;
  logic [E2W-1:0]  e2_s9;
  logic            zg_s9;
  logic [RndW-1:0] rnd_s9;

  always_ff @(posedge clk_i) begin
    if (en) begin
      c_s9   <= c_d;
      np_s9  <= np_d;
      d_s9   <= d_s8;
      l2_s9  <= l2_s8;
      eta_s9 <= eta_s8;
      e2_s9  <= e2_s8;
      zg_s9  <= zg_s8;
      rnd_s9 <= rnd_s8;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 10: c^2; reflection R; eta c; eta D
  // ---------------------------------------------------------------------------
  localparam int unsigned RpW = 2 * F + 6;   // c N'_c, signed
  localparam int unsigned EcW = F + 4;       // rnd(eta c, M), U(4.F)
  localparam int unsigned EdW = F + 5;       // rnd(eta D_c, M), signed
  localparam int unsigned EpW = M + F + 6;   // eta * (c or D_c), signed

  logic [L2W-1:0]  c2_d;
  logic [3*EW-1:0] r_d;
  logic [EcW-1:0]  ec_d;
  logic [3*EdW-1:0] ed_d;
  logic [EpW-1:0]   ec_full;
  logic [3*RpW-1:0] rp_all;                  // c N'_c + half, kept whole for the tie-off
  logic [3*EpW-1:0] ep_all;                  // eta D_c + half, kept whole for the tie-off

  always_comb begin
    c2_d    = L2W'(c_s9) * L2W'(c_s9);
    ec_full = EpW'(eta_s9) * EpW'(c_s9) + EpW'(1 << (M - 1));
    ec_d    = ec_full[M +: EcW];
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [RpW-1:0] cs, nc;
      logic signed [EW-1:0]  dc;
      logic signed [EpW-1:0] es, ds;
      cs = RpW'({1'b0, c_s9});
      nc = {{(RpW-DW){np_s9[c*DW + DW-1]}}, np_s9[c*DW +: DW]};
      rp_all[c*RpW +: RpW] = cs * nc + RpW'(1 << (F - 2));
      dc = {{(EW-DW){d_s9[c*DW + DW-1]}}, d_s9[c*DW +: DW]};
      r_d[c*EW +: EW] = dc + rp_all[c*RpW + F - 1 +: EW];
      es = EpW'({1'b0, eta_s9});
      ds = {{(EpW-DW){d_s9[c*DW + DW-1]}}, d_s9[c*DW +: DW]};
      ep_all[c*EpW +: EpW] = es * ds + EpW'(1 << (M - 1));
      ed_d[c*EdW +: EdW]   = ep_all[c*EpW + M +: EdW];
    end
  end

  logic [L2W-1:0]   c2_s10, l2_s10;
  logic [3*EW-1:0]  r_s10;
  logic [EcW-1:0]   ec_s10;
  logic [3*EdW-1:0] ed_s10;
  logic [3*DW-1:0]  d_s10, np_s10;
  logic [E2W-1:0]   e2_s10;
  logic             zg_s10;
  logic [RndW-1:0]  rnd_s10;

  always_ff @(posedge clk_i) begin
    if (en) begin
      c2_s10  <= c2_d;
      r_s10   <= r_d;
      ec_s10  <= ec_d;
      ed_s10  <= ed_d;
      d_s10   <= d_s9;
      np_s10  <= np_s9;
      l2_s10  <= l2_s9;
      e2_s10  <= e2_s9;
      zg_s10  <= zg_s9;
      rnd_s10 <= rnd_s9;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 11: s2 = max(|D|^2 - c^2, 0)
  // ---------------------------------------------------------------------------
  logic [L2W-1:0] s2_d, s2_s11;
  assign s2_d = (l2_s10 > c2_s10) ? l2_s10 - c2_s10 : '0;

  // The refraction-side fields travel together from here: ec, eta D, N', and R, D for the mux.
  localparam int unsigned RefW = EcW + 3*EdW + 3*DW;
  localparam int unsigned MuxW = 3*EW + 3*DW;

  logic [RefW-1:0] ref_s11;
  logic [MuxW-1:0] mux_s11;
  logic [L2W-1:0]  l2_s11;
  logic [E2W-1:0]  e2_s11;
  logic            zg_s11;
  logic [RndW-1:0] rnd_s11;

  always_ff @(posedge clk_i) begin
    if (en) begin
      s2_s11  <= s2_d;
      ref_s11 <= {np_s10, ed_s10, ec_s10};
      mux_s11 <= {d_s10, r_s10};
      l2_s11  <= l2_s10;
      e2_s11  <= e2_s10;
      zg_s11  <= zg_s10;
      rnd_s11 <= rnd_s10;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 12: k = |D|^2 - rnd(eta^2 s2, 2M); TIR iff k < 0
  // ---------------------------------------------------------------------------
  localparam int unsigned TW = E2W + L2W;    // eta^2 s2
  logic [TW-1:0]  t_full;
  logic [TW:0]    k_full;                    // signed: l2 - t
  logic [L2W-1:0] kq_d, kq_s12;
  logic           tir_d;

  always_comb begin
    t_full = TW'(e2_s11) * TW'(s2_s11) + TW'(1 << (2 * M - 1));
    k_full = (TW+1)'(l2_s11) - ((TW+1)'(t_full) >> (2 * M));
    tir_d  = k_full[TW];
    kq_d   = tir_d ? '0 : k_full[L2W-1:0];
  end

  localparam int unsigned Side12W = RefW + MuxW + 1 + 1 + RndW;  // + tir + zg
  logic [Side12W-1:0] side_s12, side_s16;

  always_ff @(posedge clk_i) begin
    if (en) begin
      kq_s12   <= kq_d;
      side_s12 <= {rnd_s11, zg_s11, tir_d, mux_s11, ref_s11};
    end
  end

  // ---------------------------------------------------------------------------
  // Stages 13-17: sqrt(k) = rnd(m y, MF + YF - kk) with (y, kk, m) = rsq(k)
  // ---------------------------------------------------------------------------
  logic [YF:0]   yk;
  logic [KW-1:0] kkk;
  logic [YF+1:0] mk;

  gicube_scatter_rsqrt #(
    .QW (L2W),
    .F  (F),
    .KW (KW)
  ) u_rsq_k (
    .clk_i      (clk_i),
    .en_i       (en),
    .q_i        (kq_s12),
    .cfg_we_i   (seed_we),
    .cfg_idx_i  (seed_idx),
    .cfg_seed_i (seed_val),
    .y_o        (yk),
    .kk_o       (kkk),
    .m_o        (mk)
  );

  gicube_scatter_pipe #(
    .W (Side12W),
    .N (gicube_scatter_pkg::RsqLatency)
  ) u_side_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (side_s12),
    .q_o   (side_s16)
  );

  // Stage 17: the variable shift MF + YF - kk as a left shift by kk and a fixed 2 YF shift.
  localparam int unsigned SqPW = 2 * YF + 3;            // m y
  localparam int unsigned SqSW = SqPW + (L2W / 2);      // after << kk (kk < L2W / 2)
  logic [SqSW-1:0] sq_shifted;
  logic [CW-1:0]   sqrtk_d, sqrtk_s17;

  always_comb begin
    sq_shifted = (SqSW'(SqPW'(mk) * SqPW'(yk)) << kkk) + (SqSW'(1) << (2 * YF - 1));
    sqrtk_d    = sq_shifted[2 * YF +: CW];
  end

  logic [Side12W-1:0] side_s17;
  always_ff @(posedge clk_i) begin
    if (en) begin
      sqrtk_s17 <= sqrtk_d;
      side_s17  <= side_s16;
    end
  end

  logic [RefW-1:0] ref_s17;
  logic [MuxW-1:0] mux_s17;
  logic            tir_s17, zg_s17;
  logic [RndW-1:0] rnd_s17;
  assign {rnd_s17, zg_s17, tir_s17, mux_s17, ref_s17} = side_s17;

  logic [EcW-1:0]   ec_s17;
  logic [3*EdW-1:0] ed_s17;
  logic [3*DW-1:0]  np_s17;
  assign {np_s17, ed_s17, ec_s17} = ref_s17;

  // ---------------------------------------------------------------------------
  // Stage 18: coef = rnd(eta c, M) - sqrt(k)
  // ---------------------------------------------------------------------------
  localparam int unsigned CoW = F + 5;
  logic [CoW-1:0] coef_d, coef_s18;
  assign coef_d = CoW'(ec_s17) - CoW'(sqrtk_s17);

  logic [3*EdW-1:0] ed_s18;
  logic [3*DW-1:0]  np_s18;
  logic [MuxW-1:0]  mux_s18;
  logic             tir_s18, zg_s18;
  logic [RndW-1:0]  rnd_s18;

  always_ff @(posedge clk_i) begin
    if (en) begin
      coef_s18 <= coef_d;
      ed_s18   <= ed_s17;
      np_s18   <= np_s17;
      mux_s18  <= mux_s17;
      tir_s18  <= tir_s17;
      zg_s18   <= zg_s17;
      rnd_s18  <= rnd_s17;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 19: T = rnd(eta D, M) + rnd(coef N', F); the final event
  // ---------------------------------------------------------------------------
  localparam int unsigned TpW = CoW + DW + 1;
  logic [3*EW-1:0] t_d;
  logic [3*TpW-1:0] tp_all;                  // coef N'_c + half, kept whole for the tie-off

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [TpW-1:0] co, nc;
      logic signed [EW-1:0]  ed;
      co = {{(TpW-CoW){coef_s18[CoW-1]}}, coef_s18};
      nc = {{(TpW-DW){np_s18[c*DW + DW-1]}}, np_s18[c*DW +: DW]};
      tp_all[c*TpW +: TpW] = co * nc + TpW'(1 << (F - 1));
      ed = {{(EW-EdW){ed_s18[c*EdW + EdW-1]}}, ed_s18[c*EdW +: EdW]};
      t_d[c*EW +: EW] = ed + tp_all[c*TpW + F +: EW];
    end
  end

  logic [1:0]      drawn_s18;
  logic [A-1:0]    theta_s18;
  logic [PhiW-1:0] phi_s18;
  logic [I-1:0]    isoi_s18;
  assign {isoi_s18, phi_s18, theta_s18, drawn_s18} = rnd_s18;

  logic [1:0] event_d;
  logic       tirf_d, zgf_d;

  always_comb begin
    logic surface;
    surface = drawn_s18 == gicube_scatter_pkg::EvReflect
              || drawn_s18 == gicube_scatter_pkg::EvRefract;
    event_d = drawn_s18;
    tirf_d  = 1'b0;
    zgf_d   = 1'b0;
    if (surface && zg_s18) begin
      event_d = gicube_scatter_pkg::EvPass;
      zgf_d   = 1'b1;
    end else if (drawn_s18 == gicube_scatter_pkg::EvRefract && tir_s18) begin
      event_d = gicube_scatter_pkg::EvReflect;
      tirf_d  = 1'b1;
    end
  end

  logic [3*EW-1:0] t_s19;
  logic [MuxW-1:0] mux_s19;
  logic [1:0]      event_s19;
  logic            tirf_s19, zgf_s19;
  logic [A-1:0]    theta_s19;
  logic [PhiW-1:0] phi_s19;
  logic [I-1:0]    isoi_s19;

  always_ff @(posedge clk_i) begin
    if (en) begin
      t_s19     <= t_d;
      mux_s19   <= mux_s18;
      event_s19 <= event_d;
      tirf_s19  <= tirf_d;
      zgf_s19   <= zgf_d;
      theta_s19 <= theta_s18;
      phi_s19   <= phi_s18;
      isoi_s19  <= isoi_s18;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 20: E = D, R, T or ISO[iso_idx]; theta only for reflection and refraction
  // ---------------------------------------------------------------------------
  logic [3*EW-1:0] r_s19;
  logic [3*DW-1:0] d_s19;
  assign {d_s19, r_s19} = mux_s19;

  logic [3*EW-1:0] e_d, e_s20;
  logic [3*DW-1:0] iso_dir;
  logic [A-1:0]    theta_eff;

  always_comb begin
    iso_dir = iso_q[isoi_s19];
    for (int unsigned c = 0; c < 3; c++) begin
      unique case (event_s19)
        gicube_scatter_pkg::EvReflect: e_d[c*EW +: EW] = r_s19[c*EW +: EW];
        gicube_scatter_pkg::EvRefract: e_d[c*EW +: EW] = t_s19[c*EW +: EW];
        gicube_scatter_pkg::EvIso:
          e_d[c*EW +: EW] = {{(EW-DW){iso_dir[c*DW + DW-1]}}, iso_dir[c*DW +: DW]};
        default:
          e_d[c*EW +: EW] = {{(EW-DW){d_s19[c*DW + DW-1]}}, d_s19[c*DW +: DW]};
      endcase
    end
    theta_eff = (event_s19 == gicube_scatter_pkg::EvReflect
                 || event_s19 == gicube_scatter_pkg::EvRefract) ? theta_s19 : '0;
  end

  localparam int unsigned FlagW = 4;          // event, tir, zero_grad
  localparam int unsigned AngSideW = A + PhiW + FlagW;
  logic [AngSideW-1:0] ang_s20, ang_s27;

  always_ff @(posedge clk_i) begin
    if (en) begin
      e_s20   <= e_d;
      ang_s20 <= {zgf_s19, tirf_s19, event_s19, phi_s19, theta_eff};
    end
  end

  // ---------------------------------------------------------------------------
  // Stages 21-27: Ê = normalize(E)
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] eh_s27;
  logic            ez_unused;

  gicube_scatter_norm #(
    .VW (EW),
    .F  (F)
  ) u_norm_e (
    .clk_i      (clk_i),
    .en_i       (en),
    .v_i        (e_s20),
    .cfg_we_i   (seed_we),
    .cfg_idx_i  (seed_idx),
    .cfg_seed_i (seed_val),
    .vn_o       (eh_s27),
    .zero_o     (ez_unused)
  );

  gicube_scatter_pipe #(
    .W (AngSideW),
    .N (gicube_scatter_pkg::NormLatency)
  ) u_ang_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (ang_s20),
    .q_o   (ang_s27)
  );

  // ---------------------------------------------------------------------------
  // Stage 28: TRIG reads (theta, phi with its quadrant); the axis i of the smallest |Ê_c|
  // ---------------------------------------------------------------------------
  logic [A-1:0]     theta_s27;
  logic [PhiW-1:0]  phi_s27;
  logic [FlagW-1:0] flags_s27;
  assign {flags_s27, phi_s27, theta_s27} = ang_s27;

  logic [2*F+1:0] trig_th, trig_ph;

  gicube_scatter_trig #(
    .F (F),
    .A (A)
  ) u_trig (
    .clk_i       (clk_i),
    .cfg_we_i    (trig_we),
    .cfg_idx_i   (cfg_idx[A-1:0]),
    .cfg_entry_i (cfg_data_i[2*F+1:0]),
    .idx0_i      (theta_s27),
    .entry0_o    (trig_th),
    .idx1_i      (phi_s27[A-1:0]),
    .entry1_o    (trig_ph)
  );

  logic [DW-1:0] cp_d, sp_d;                 // cos, sin of phi, S(2.F)
  logic [1:0]    axis_d;
  logic [3*DW-1:0] abc_d;                    // a, b, cc: Ê_i, Ê_j, Ê_k

  always_comb begin
    logic [DW-1:0] cv, sv;
    logic [DW-1:0] mag0, mag1, mag2;
    cv = {1'b0, trig_ph[0 +: F+1]};
    sv = {1'b0, trig_ph[F+1 +: F+1]};
    unique case (phi_s27[A +: 2])
      2'd0:    begin cp_d = cv;      sp_d = sv;      end
      2'd1:    begin cp_d = DW'(-sv); sp_d = cv;      end
      2'd2:    begin cp_d = DW'(-cv); sp_d = DW'(-sv); end
      default: begin cp_d = sv;      sp_d = DW'(-cv); end
    endcase
    // |Ê_c| of an S(2.F) value fits DW bits unsigned.
    mag0 = eh_s27[0*DW + DW-1] ? DW'(-eh_s27[0*DW +: DW]) : eh_s27[0*DW +: DW];
    mag1 = eh_s27[1*DW + DW-1] ? DW'(-eh_s27[1*DW +: DW]) : eh_s27[1*DW +: DW];
    mag2 = eh_s27[2*DW + DW-1] ? DW'(-eh_s27[2*DW +: DW]) : eh_s27[2*DW +: DW];
    if (mag1 < mag0) begin
      axis_d = (mag2 < mag1) ? 2'd2 : 2'd1;
    end else begin
      axis_d = (mag2 < mag0) ? 2'd2 : 2'd0;
    end
    unique case (axis_d)
      2'd1:    abc_d = {eh_s27[0*DW +: DW], eh_s27[2*DW +: DW], eh_s27[1*DW +: DW]};
      2'd2:    abc_d = {eh_s27[1*DW +: DW], eh_s27[0*DW +: DW], eh_s27[2*DW +: DW]};
      default: abc_d = {eh_s27[2*DW +: DW], eh_s27[1*DW +: DW], eh_s27[0*DW +: DW]};
    endcase
  end

  logic [F:0]       ct_s28, st_s28;
  logic [DW-1:0]    cp_s28, sp_s28;
  logic [1:0]       axis_s28;
  logic [3*DW-1:0]  abc_s28, eh_s28;
  logic [FlagW-1:0] flags_s28;

  always_ff @(posedge clk_i) begin
    if (en) begin
      ct_s28    <= trig_th[0 +: F+1];
      st_s28    <= trig_th[F+1 +: F+1];
      cp_s28    <= cp_d;
      sp_s28    <= sp_d;
      axis_s28  <= axis_d;
      abc_s28   <= abc_d;
      eh_s28    <= eh_s27;
      flags_s28 <= flags_s27;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 29: w = b^2 + cc^2; V = (rnd(w, F), rnd(-a b, F), rnd(-a cc, F)); U = (0, -cc, b)
  // ---------------------------------------------------------------------------
  localparam int unsigned VvW = F + 4;       // V components, signed
  localparam int unsigned PrW = 2 * DW + 1;  // products of two S(2.F)
  logic [L2W-1:0]   w_d;
  logic [3*VvW-1:0] v_d;
  logic signed [PrW-1:0] bb, ccs;            // b^2, cc^2 <= 2^(2F+2): the top bit is zero
  logic signed [PrW-1:0] ab, acc;            // -a b, -a cc plus half

  always_comb begin
    logic signed [PrW-1:0] a, b, cc;
    a   = {{(PrW-DW){abc_s28[0*DW + DW-1]}}, abc_s28[0*DW +: DW]};
    b   = {{(PrW-DW){abc_s28[1*DW + DW-1]}}, abc_s28[1*DW +: DW]};
    cc  = {{(PrW-DW){abc_s28[2*DW + DW-1]}}, abc_s28[2*DW +: DW]};
    bb  = b * b;
    ccs = cc * cc;
    ab  = -(a * b) + PrW'(1 << (F - 1));
    acc = -(a * cc) + PrW'(1 << (F - 1));
    w_d = L2W'(bb) + L2W'(ccs);
    v_d[0*VvW +: VvW] = VvW'((w_d + L2W'(1 << (F - 1))) >> F);
    v_d[1*VvW +: VvW] = ab[F +: VvW];
    v_d[2*VvW +: VvW] = acc[F +: VvW];
  end

  logic [L2W-1:0]   w_s29;
  logic [3*VvW-1:0] v_s29;
  logic [2*DW-1:0]  u_s29;                   // U_j = -cc, U_k = b (U_i = 0)
  logic [F:0]       ct_s29, st_s29;
  logic [DW-1:0]    cp_s29, sp_s29;
  logic [1:0]       axis_s29;
  logic [3*DW-1:0]  eh_s29;
  logic [FlagW-1:0] flags_s29;

  always_ff @(posedge clk_i) begin
    if (en) begin
      w_s29     <= w_d;
      v_s29     <= v_d;
      u_s29     <= {abc_s28[1*DW +: DW], DW'(-abc_s28[2*DW +: DW])};
      ct_s29    <= ct_s28;
      st_s29    <= st_s28;
      cp_s29    <= cp_s28;
      sp_s29    <= sp_s28;
      axis_s29  <= axis_s28;
      eh_s29    <= eh_s28;
      flags_s29 <= flags_s28;
    end
  end

  // ---------------------------------------------------------------------------
  // Stages 30-33: rsq(w); stage 30 also forms B = rnd(cos(phi) U + sin(phi) V, F)
  // ---------------------------------------------------------------------------
  logic [YF:0]   yw;
  logic [KW-1:0] kw;
  logic [YF+1:0] mw_unused;

  gicube_scatter_rsqrt #(
    .QW (L2W),
    .F  (F),
    .KW (KW)
  ) u_rsq_w (
    .clk_i      (clk_i),
    .en_i       (en),
    .q_i        (w_s29),
    .cfg_we_i   (seed_we),
    .cfg_idx_i  (seed_idx),
    .cfg_seed_i (seed_val),
    .y_o        (yw),
    .kk_o       (kw),
    .m_o        (mw_unused)
  );

  localparam int unsigned BW  = F + 4;       // B components, signed
  localparam int unsigned BpW = DW + VvW + 2;
  logic [3*BW-1:0] bw_d;                     // B in x, y, z order
  logic signed [BpW-1:0] bi, bj, bk;         // B_i, B_j, B_k plus half, before the rounding shift

  always_comb begin
    logic signed [BpW-1:0] cp, sp, uj, uk, vi, vj, vk;
    logic [3*BW-1:0] frame;                  // B_i, B_j, B_k
    cp = {{(BpW-DW){cp_s29[DW-1]}}, cp_s29};
    sp = {{(BpW-DW){sp_s29[DW-1]}}, sp_s29};
    uj = {{(BpW-DW){u_s29[DW-1]}}, u_s29[0 +: DW]};
    uk = {{(BpW-DW){u_s29[2*DW-1]}}, u_s29[DW +: DW]};
    vi = {{(BpW-VvW){v_s29[0*VvW + VvW-1]}}, v_s29[0*VvW +: VvW]};
    vj = {{(BpW-VvW){v_s29[1*VvW + VvW-1]}}, v_s29[1*VvW +: VvW]};
    vk = {{(BpW-VvW){v_s29[2*VvW + VvW-1]}}, v_s29[2*VvW +: VvW]};
    bi = sp * vi + BpW'(1 << (F - 1));
    bj = cp * uj + sp * vj + BpW'(1 << (F - 1));
    bk = cp * uk + sp * vk + BpW'(1 << (F - 1));
    frame = {bk[F +: BW], bj[F +: BW], bi[F +: BW]};
    unique case (axis_s29)
      2'd1:    bw_d = {frame[1*BW +: BW], frame[0*BW +: BW], frame[2*BW +: BW]};
      2'd2:    bw_d = {frame[0*BW +: BW], frame[2*BW +: BW], frame[1*BW +: BW]};
      default: bw_d = frame;
    endcase
  end

  logic [3*BW-1:0] bw_s30;
  localparam int unsigned RotSideW = 2 * (F + 1) + 3 * DW + FlagW;  // ct, st, Ê, flags
  logic [RotSideW-1:0] rot_s30, rot_s33;

  always_ff @(posedge clk_i) begin
    if (en) begin
      bw_s30  <= bw_d;
      rot_s30 <= {flags_s29, eh_s29, st_s29, ct_s29};
    end
  end

  logic [3*BW-1:0] bw_s33;

  gicube_scatter_pipe #(
    .W (3*BW + RotSideW),
    .N (3)
  ) u_rot_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   ({rot_s30, bw_s30}),
    .q_o   ({rot_s33, bw_s33})
  );

  logic [F:0]       ct_s33, st_s33;
  logic [3*DW-1:0]  eh_s33;
  logic [FlagW-1:0] flags_s33;
  assign {flags_s33, eh_s33, st_s33, ct_s33} = rot_s33;

  // ---------------------------------------------------------------------------
  // Stage 34: sig = rnd(sin(theta) yw, kw + 3) = sin(theta) / sqrt(w)
  // ---------------------------------------------------------------------------
  localparam int unsigned KwMax = L2W / 2 - 1;
  localparam int unsigned SgPW  = (F + 1) + (YF + 1);
  localparam int unsigned SgSW  = SgPW + KwMax;
  localparam int unsigned SgW   = F + 3;     // sig, U(3.F)
  logic [SgSW-1:0] sg_shifted;
  logic [SgW-1:0]  sig_d, sig_s34;

  always_comb begin
    sg_shifted = (SgSW'(SgPW'(st_s33) * SgPW'(yw)) << (KwMax - 32'(kw)))
                 + (SgSW'(1) << (KwMax + 2));
    sig_d      = sg_shifted[KwMax + 3 +: SgW];
  end

  logic [3*BW-1:0]  bw_s34;
  logic [F:0]       ct_s34;
  logic [3*DW-1:0]  eh_s34;
  logic [FlagW-1:0] flags_s34;

  always_ff @(posedge clk_i) begin
    if (en) begin
      sig_s34   <= sig_d;
      bw_s34    <= bw_s33;
      ct_s34    <= ct_s33;
      eh_s34    <= eh_s33;
      flags_s34 <= flags_s33;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 35: D' = rnd(cos(theta) Ê + sig B, F)
  // ---------------------------------------------------------------------------
  localparam int unsigned DpW = SgW + BW + 2;
  logic [3*DW-1:0] dp_d, dp_s35;
  logic [3*DpW-1:0] dps_all;                 // cos(theta) Ê + sig B plus half, per component

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [DpW-1:0] ct, eh, sg, bc;
      ct  = DpW'({1'b0, ct_s34});
      eh  = {{(DpW-DW){eh_s34[c*DW + DW-1]}}, eh_s34[c*DW +: DW]};
      sg  = DpW'({1'b0, sig_s34});
      bc  = {{(DpW-BW){bw_s34[c*BW + BW-1]}}, bw_s34[c*BW +: BW]};
      dps_all[c*DpW +: DpW] = ct * eh + sg * bc + DpW'(1 << (F - 1));
      dp_d[c*DW +: DW]      = dps_all[c*DpW + F +: DW];
    end
  end

  logic [FlagW-1:0] flags_s35, flags_s42;

  always_ff @(posedge clk_i) begin
    if (en) begin
      dp_s35    <= dp_d;
      flags_s35 <= flags_s34;
    end
  end

  // ---------------------------------------------------------------------------
  // Stages 36-42: dir = normalize(D')
  // ---------------------------------------------------------------------------
  logic [3*DW-1:0] dir_s42;
  logic            zd_s42;

  gicube_scatter_norm #(
    .VW (DW),
    .F  (F)
  ) u_norm_out (
    .clk_i      (clk_i),
    .en_i       (en),
    .v_i        (dp_s35),
    .cfg_we_i   (seed_we),
    .cfg_idx_i  (seed_idx),
    .cfg_seed_i (seed_val),
    .vn_o       (dir_s42),
    .zero_o     (zd_s42)
  );

  gicube_scatter_pipe #(
    .W (FlagW),
    .N (gicube_scatter_pkg::NormLatency)
  ) u_flags_wait (
    .clk_i (clk_i),
    .en_i  (en),
    .d_i   (flags_s35),
    .q_o   (flags_s42)
  );

  assign out_data_o = {zd_s42, flags_s42, dir_s42};

  // Bits that the contract's ranges keep at zero or sign copies, and unused table data.
  logic unused_top;
  assign unused_top = ^{ez_unused, pool_s2, ec_full, ep_all, bb, ccs, ab, acc, bi, bj, bk,
                        rp_all, tp_all, dps_all, mw_unused, cfg_data_i, cfg_idx[10], t_full, k_full,
                        sq_shifted, sg_shifted, phi_s27, th_full, absdn};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_scatter: output changed while stalled");
`endif

endmodule
