// gicube_scatter_select: the event's direction E (docs/numerics/gicube_scatter.md, Refraction,
// Event choice, The event's direction; patent [28], [385]):
//   stage 19  T = rnd(eta D, M) + rnd(coef N', F); the final event (zero gradient: Pass; TIR:
//             Reflect)
//   stage 20  E = D, R, T or ISO[iso_idx]; theta only for reflection and refraction
// Holds the ISO table (2^I random directions), written through the configuration port.
module gicube_scatter_select #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14,
  /// Index bits A of the quarter-wave trigonometry table.
  parameter int unsigned A = 8,
  /// Index bits I of the isotropic direction LUT.
  parameter int unsigned I = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// coef = ec - sqrt(k), signed.
  input  logic [gicube_scatter_pkg::ed_w(F)-1:0] coef_i,
  /// N', S(2.F) components.
  input  logic [3*(F+2)-1:0] np_i,
  /// rnd(eta D_c, M), signed components.
  input  logic [3*gicube_scatter_pkg::ed_w(F)-1:0] ed_i,
  /// Reflection R, S(6.F) components.
  input  logic [3*gicube_scatter_pkg::ev_w(F)-1:0] r_i,
  /// Ray direction D, S(2.F) components.
  input  logic [3*(F+2)-1:0] d_i,
  /// Total internal reflection.
  input  logic tir_i,
  /// The gradient was zero.
  input  logic zero_grad_i,
  /// Drawn event (gicube_scatter_pkg::Ev*).
  input  logic [1:0] drawn_i,
  /// Glossy angle theta.
  input  logic [A-1:0] theta_i,
  /// Axis angle phi.
  input  logic [A+1:0] phi_i,
  /// Index into the ISO table.
  input  logic [I-1:0] iso_idx_i,
  /// ISO table write.
  input  logic iso_we_i,
  /// ISO index written.
  input  logic [I-1:0] iso_widx_i,
  /// ISO entry written: x, y, z, S(2.F) each.
  input  logic [3*(F+2)-1:0] iso_wdata_i,
  /// E, S(6.F) components, SelectLatency stages after the inputs (as are all outputs).
  output logic [3*gicube_scatter_pkg::ev_w(F)-1:0] e_o,
  /// theta for Reflect and Refract, else 0.
  output logic [A-1:0] theta_o,
  /// phi, delayed.
  output logic [A+1:0] phi_o,
  /// {zero_grad, tir, event (2)}: the output flags.
  output logic [3:0] flags_o
);

  localparam int unsigned DW  = F + 2;
  localparam int unsigned EW  = gicube_scatter_pkg::ev_w(F);
  localparam int unsigned EdW = gicube_scatter_pkg::ed_w(F);

  logic [3*DW-1:0] iso_table_q [2**I];

  always_ff @(posedge clk_i) begin
    if (iso_we_i) iso_table_q[iso_widx_i] <= iso_wdata_i;
  end

  // ---------------------------------------------------------------------------
  // Stage 19: T = rnd(eta D, M) + rnd(coef N', F); the final event
  // ---------------------------------------------------------------------------
  logic [3*EW-1:0] t_d, t_q, r_q;
  logic [3*DW-1:0] d_q;
  logic [1:0]      event_d, event_q;
  logic            tirf_d, tirf_q, zgf_d, zgf_q;
  logic [A-1:0]    theta_q, theta_q2;
  logic [A+1:0]    phi_q, phi_q2;
  logic [I-1:0]    isoi_q;

  gicube_scatter_madd3 #(
    .AW (EdW),
    .XW (DW),
    .YW (EdW),
    .PW (EdW + DW + 1),
    .S  (F),
    .OW (EW)
  ) u_transmit (
    .a_i (coef_i),
    .x_i (np_i),
    .y_i (ed_i),
    .z_o (t_d)
  );

  always_comb begin
    logic surface;
    surface = drawn_i == gicube_scatter_pkg::EvReflect
              || drawn_i == gicube_scatter_pkg::EvRefract;
    event_d = drawn_i;
    tirf_d  = 1'b0;
    zgf_d   = 1'b0;
    if (surface && zero_grad_i) begin
      event_d = gicube_scatter_pkg::EvPass;
      zgf_d   = 1'b1;
    end else if (drawn_i == gicube_scatter_pkg::EvRefract && tir_i) begin
      event_d = gicube_scatter_pkg::EvReflect;
      tirf_d  = 1'b1;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 20: E = D, R, T or ISO[iso_idx]; theta only for reflection and refraction
  // ---------------------------------------------------------------------------
  logic [3*EW-1:0] e_d, e_q;
  logic [3*DW-1:0] iso_dir;
  logic [A-1:0]    theta_d;
  logic [3:0]      flags_q;

  always_comb begin
    iso_dir = iso_table_q[isoi_q];
    for (int unsigned c = 0; c < 3; c++) begin
      unique case (event_q)
        gicube_scatter_pkg::EvReflect: e_d[c*EW +: EW] = r_q[c*EW +: EW];
        gicube_scatter_pkg::EvRefract: e_d[c*EW +: EW] = t_q[c*EW +: EW];
        gicube_scatter_pkg::EvIso:
          e_d[c*EW +: EW] = {{(EW-DW){iso_dir[c*DW + DW-1]}}, iso_dir[c*DW +: DW]};
        default:
          e_d[c*EW +: EW] = {{(EW-DW){d_q[c*DW + DW-1]}}, d_q[c*DW +: DW]};
      endcase
    end
    theta_d = (event_q == gicube_scatter_pkg::EvReflect
               || event_q == gicube_scatter_pkg::EvRefract) ? theta_q : '0;
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 19
      t_q      <= t_d;
      r_q      <= r_i;
      d_q      <= d_i;
      event_q  <= event_d;
      tirf_q   <= tirf_d;
      zgf_q    <= zgf_d;
      theta_q  <= theta_i;
      phi_q    <= phi_i;
      isoi_q   <= iso_idx_i;
      // Stage 20
      e_q      <= e_d;
      theta_q2 <= theta_d;
      phi_q2   <= phi_q;
      flags_q  <= {zgf_q, tirf_q, event_q};
    end
  end

  assign e_o     = e_q;
  assign theta_o = theta_q2;
  assign phi_o   = phi_q2;
  assign flags_o = flags_q;

endmodule
