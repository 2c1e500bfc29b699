// gicube_scatter_surface: the ray meets the surface (docs/numerics/gicube_scatter.md, The normal,
// Reflection, Refraction; patent [28], [385]-[386]). From the direction D and the normal N:
//   stage  8  dn = D . N
//   stage  9  N' = N turned to face the ray, c = rnd(|dn|, F)
//   stage 10  c^2; the reflection R = D + rnd(c N', F - 1); ec = rnd(eta c, M); rnd(eta D, M)
//   stage 11  s2 = max(|D|^2 - c^2, 0)
module gicube_scatter_surface #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14,
  /// Fraction bits M of the material fields.
  parameter int unsigned M = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// Ray direction D, S(2.F) components.
  input  logic [3*(F+2)-1:0] d_i,
  /// Normal N = normalize(G), S(2.F) components.
  input  logic [3*(F+2)-1:0] n_i,
  /// |D|^2, 2F fraction bits.
  input  logic [gicube_scatter_pkg::sq_w(F)-1:0] l2_i,
  /// Index ratio eta, U(2.M).
  input  logic [M+1:0] eta_i,
  /// s2 = max(|D|^2 - c^2, 0), SurfaceLatency stages after the inputs (as are all outputs).
  output logic [gicube_scatter_pkg::sq_w(F)-1:0] s2_o,
  /// |D|^2, delayed.
  output logic [gicube_scatter_pkg::sq_w(F)-1:0] l2_o,
  /// Reflection R, S(6.F) components.
  output logic [3*gicube_scatter_pkg::ev_w(F)-1:0] r_o,
  /// D, delayed.
  output logic [3*(F+2)-1:0] d_o,
  /// N', S(2.F) components.
  output logic [3*(F+2)-1:0] np_o,
  /// ec = rnd(eta c, M).
  output logic [gicube_scatter_pkg::ec_w(F)-1:0] ec_o,
  /// rnd(eta D_c, M), signed components.
  output logic [3*gicube_scatter_pkg::ed_w(F)-1:0] ed_o
);

  localparam int unsigned DW  = F + 2;
  localparam int unsigned ETW = M + 2;
  localparam int unsigned EW  = gicube_scatter_pkg::ev_w(F);
  localparam int unsigned L2W = gicube_scatter_pkg::sq_w(F);
  localparam int unsigned EcW = gicube_scatter_pkg::ec_w(F);
  localparam int unsigned EdW = gicube_scatter_pkg::ed_w(F);
  localparam int unsigned DnW = 2 * DW + 2;     // D . N, signed
  localparam int unsigned CW  = F + 2;          // c, U(2.F)
  localparam int unsigned EpW = M + F + 6;      // eta * (c or D_c)

  // ---------------------------------------------------------------------------
  // Stage 8: dn = D . N
  // ---------------------------------------------------------------------------
  logic signed [DnW-1:0] dn_d, dn_q;
  logic [3*DW-1:0]       d_q, d_q2, d_q3, d_q4, n_q;
  logic [L2W-1:0]        l2_q, l2_q2, l2_q3, l2_q4;
  logic [ETW-1:0]        eta_q, eta_q2;

  gicube_scatter_dot3 #(
    .VW (DW),
    .OW (DnW)
  ) u_dn (
    .x_i (d_i),
    .y_i (n_i),
    .z_o (dn_d)
  );

  // ---------------------------------------------------------------------------
  // Stage 9: turn the normal to face the ray; c = rnd(|dn|, F)
  // ---------------------------------------------------------------------------
  logic [CW-1:0]   c_d, c_q;
  logic [3*DW-1:0] np_d, np_q, np_q2, np_q3;
  logic [DnW-1:0]  absdn;

  always_comb begin
    logic flip;
    flip  = !dn_q[DnW-1] && dn_q != '0;
    absdn = dn_q[DnW-1] ? DnW'(-dn_q) : DnW'(dn_q);
    c_d   = CW'((absdn + DnW'(1 << (F - 1))) >> F);
    for (int unsigned c = 0; c < 3; c++) begin
      np_d[c*DW +: DW] = flip ? DW'(-$signed(n_q[c*DW +: DW])) : n_q[c*DW +: DW];
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 10: c^2; R = D + rnd(c N', F - 1); ec = rnd(eta c, M); rnd(eta D_c, M)
  // ---------------------------------------------------------------------------
  logic [L2W-1:0]   c2_d, c2_q;
  logic [3*EW-1:0]  r_d, r_q, r_q2;
  logic [EpW-1:0]   ec_full;
  logic [EcW-1:0]   ec_d, ec_q, ec_q2;
  logic [3*EdW-1:0] ed_d, ed_q, ed_q2;

  always_comb begin
    c2_d    = L2W'(c_q) * L2W'(c_q);
    ec_full = EpW'(eta_q2) * EpW'(c_q) + EpW'(1 << (M - 1));
    ec_d    = ec_full[M +: EcW];
  end

  gicube_scatter_madd3 #(
    .AW (CW + 1),
    .XW (DW),
    .YW (DW),
    .PW (2 * F + 6),
    .S  (F - 1),
    .OW (EW)
  ) u_reflect (
    .a_i ({1'b0, c_q}),
    .x_i (np_q),
    .y_i (d_q2),
    .z_o (r_d)
  );

  gicube_scatter_madd3 #(
    .AW (ETW + 1),
    .XW (DW),
    .YW (1),
    .PW (EpW),
    .S  (M),
    .OW (EdW)
  ) u_eta_d (
    .a_i ({1'b0, eta_q2}),
    .x_i (d_q2),
    .y_i ('0),
    .z_o (ed_d)
  );

  // ---------------------------------------------------------------------------
  // Stage 11: s2 = max(|D|^2 - c^2, 0)
  // ---------------------------------------------------------------------------
  logic [L2W-1:0] s2_d, s2_q;
  assign s2_d = (l2_q3 > c2_q) ? l2_q3 - c2_q : '0;

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 8
      dn_q   <= dn_d;
      d_q    <= d_i;
      n_q    <= n_i;
      l2_q   <= l2_i;
      eta_q  <= eta_i;
      // Stage 9
      c_q    <= c_d;
      np_q   <= np_d;
      d_q2   <= d_q;
      l2_q2  <= l2_q;
      eta_q2 <= eta_q;
      // Stage 10
      c2_q   <= c2_d;
      r_q    <= r_d;
      ec_q   <= ec_d;
      ed_q   <= ed_d;
      d_q3   <= d_q2;
      np_q2  <= np_q;
      l2_q3  <= l2_q2;
      // Stage 11
      s2_q   <= s2_d;
      r_q2   <= r_q;
      ec_q2  <= ec_q;
      ed_q2  <= ed_q;
      d_q4   <= d_q3;
      np_q3  <= np_q2;
      l2_q4  <= l2_q3;
    end
  end

  assign s2_o = s2_q;
  assign l2_o = l2_q4;
  assign r_o  = r_q2;
  assign d_o  = d_q4;
  assign np_o = np_q3;
  assign ec_o = ec_q2;
  assign ed_o = ed_q2;

  // ec beyond its range; |dn| below the rounding.
  logic unused_surface;
  assign unused_surface = ^{ec_full, absdn};

endmodule
