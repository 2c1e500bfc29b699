// gicube_scatter_frame: the frame of the glossy rotation (docs/numerics/gicube_scatter.md, The
// event's direction and glossy rotation; patent [28], [385]-[386]):
//   stage 28  TRIG reads for theta and phi (cos, sin of phi by quadrant); the axis i of the
//             smallest |Ê_c| and Ê in the (i, j, k) frame: a, b, cc
//   stage 29  w = b^2 + cc^2; V = (rnd(w, F), rnd(-a b, F), rnd(-a cc, F)); U = (0, -cc, b)
// Holds the TRIG table (two read ports), written through the configuration port.
module gicube_scatter_frame #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14,
  /// Index bits A of the quarter-wave trigonometry table.
  parameter int unsigned A = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// Ê = normalize(E), S(2.F) components.
  input  logic [3*(F+2)-1:0] eh_i,
  /// Glossy angle theta, 2^-A quarter turns.
  input  logic [A-1:0] theta_i,
  /// Axis angle phi, 2^-(A+2) turns.
  input  logic [A+1:0] phi_i,
  /// TRIG table write.
  input  logic trig_we_i,
  /// TRIG index written.
  input  logic [A-1:0] trig_widx_i,
  /// TRIG entry written: cos at [0 +: F+1], sin at [F+1 +: F+1].
  input  logic [2*F+1:0] trig_wdata_i,
  /// w = b^2 + cc^2, 2F fraction bits, FrameLatency stages after the inputs (as are all outputs).
  output logic [gicube_scatter_pkg::sq_w(F)-1:0] w_o,
  /// V_i, V_j, V_k, signed.
  output logic [3*gicube_scatter_pkg::vv_w(F)-1:0] v_o,
  /// U_j = -cc, U_k = b (U_i = 0), S(2.F).
  output logic [2*(F+2)-1:0] u_o,
  /// cos(theta), U(1.F).
  output logic [F:0] ct_o,
  /// sin(theta), U(1.F).
  output logic [F:0] st_o,
  /// cos(phi), S(2.F).
  output logic [F+1:0] cp_o,
  /// sin(phi), S(2.F).
  output logic [F+1:0] sp_o,
  /// The axis i.
  output logic [1:0] axis_o,
  /// Ê, delayed.
  output logic [3*(F+2)-1:0] eh_o
);

  localparam int unsigned DW  = F + 2;
  localparam int unsigned L2W = gicube_scatter_pkg::sq_w(F);
  localparam int unsigned VvW = gicube_scatter_pkg::vv_w(F);
  localparam int unsigned PrW = 2 * DW + 1;  // products of two S(2.F)

  // ---------------------------------------------------------------------------
  // Stage 28: TRIG reads (theta, phi with its quadrant); the axis i of the smallest |Ê_c|
  // ---------------------------------------------------------------------------
  logic [2*F+1:0] trig_th, trig_ph;

  gicube_scatter_trig #(
    .F (F),
    .A (A)
  ) u_trig (
    .clk_i       (clk_i),
    .cfg_we_i    (trig_we_i),
    .cfg_idx_i   (trig_widx_i),
    .cfg_entry_i (trig_wdata_i),
    .idx0_i      (theta_i),
    .entry0_o    (trig_th),
    .idx1_i      (phi_i[A-1:0]),
    .entry1_o    (trig_ph)
  );

  logic [F:0]      ct_d, st_d;
  logic [DW-1:0]   cp_d, sp_d;               // cos, sin of phi, S(2.F)
  logic [1:0]      axis_d;
  logic [3*DW-1:0] abc_d, abc_q;             // a, b, cc: Ê_i, Ê_j, Ê_k

  always_comb begin
    logic [DW-1:0] cv, sv;
    logic [DW-1:0] mag0, mag1, mag2;
    ct_d = trig_th[0 +: F+1];
    st_d = trig_th[F+1 +: F+1];
    cv   = {1'b0, trig_ph[0 +: F+1]};
    sv   = {1'b0, trig_ph[F+1 +: F+1]};
    unique case (phi_i[A +: 2])
      2'd0:    begin cp_d = cv;       sp_d = sv;       end
      2'd1:    begin cp_d = DW'(-sv); sp_d = cv;       end
      2'd2:    begin cp_d = DW'(-cv); sp_d = DW'(-sv); end
      default: begin cp_d = sv;       sp_d = DW'(-cv); end
    endcase
    // |Ê_c| of an S(2.F) value fits DW bits unsigned.
    mag0 = eh_i[0*DW + DW-1] ? DW'(-eh_i[0*DW +: DW]) : eh_i[0*DW +: DW];
    mag1 = eh_i[1*DW + DW-1] ? DW'(-eh_i[1*DW +: DW]) : eh_i[1*DW +: DW];
    mag2 = eh_i[2*DW + DW-1] ? DW'(-eh_i[2*DW +: DW]) : eh_i[2*DW +: DW];
    if (mag1 < mag0) begin
      axis_d = (mag2 < mag1) ? 2'd2 : 2'd1;
    end else begin
      axis_d = (mag2 < mag0) ? 2'd2 : 2'd0;
    end
    unique case (axis_d)
      2'd1:    abc_d = {eh_i[0*DW +: DW], eh_i[2*DW +: DW], eh_i[1*DW +: DW]};
      2'd2:    abc_d = {eh_i[1*DW +: DW], eh_i[0*DW +: DW], eh_i[2*DW +: DW]};
      default: abc_d = {eh_i[2*DW +: DW], eh_i[1*DW +: DW], eh_i[0*DW +: DW]};
    endcase
  end

  // The angles, the axis and Ê wait one stage beside w, V, U.
  cube5_delay_regs #(
    .Width  (2*(F+1) + 2*DW + 2 + 3*DW),
    .Stages (2)
  ) u_side_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({eh_i, axis_d, sp_d, cp_d, st_d, ct_d}),
    .q_o   ({eh_o, axis_o, sp_o, cp_o, st_o, ct_o})
  );

  // ---------------------------------------------------------------------------
  // Stage 29: w = b^2 + cc^2; V = (rnd(w, F), rnd(-a b, F), rnd(-a cc, F)); U = (0, -cc, b)
  // ---------------------------------------------------------------------------
  logic [L2W-1:0]        w_d, w_q;
  logic [3*VvW-1:0]      v_d, v_q;
  logic [2*DW-1:0]       u_d, u_q;
  logic signed [PrW-1:0] bb, ccs;            // b^2, cc^2 <= 2^(2F+2): the top bit is zero
  logic signed [PrW-1:0] ab, acc;            // -a b, -a cc plus half

  always_comb begin
    logic signed [PrW-1:0] a, b, cc;
    a   = {{(PrW-DW){abc_q[0*DW + DW-1]}}, abc_q[0*DW +: DW]};
    b   = {{(PrW-DW){abc_q[1*DW + DW-1]}}, abc_q[1*DW +: DW]};
    cc  = {{(PrW-DW){abc_q[2*DW + DW-1]}}, abc_q[2*DW +: DW]};
    bb  = b * b;
    ccs = cc * cc;
    ab  = -(a * b) + PrW'(1 << (F - 1));
    acc = -(a * cc) + PrW'(1 << (F - 1));
    w_d = L2W'(bb) + L2W'(ccs);
    v_d[0*VvW +: VvW] = VvW'((w_d + L2W'(1 << (F - 1))) >> F);
    v_d[1*VvW +: VvW] = ab[F +: VvW];
    v_d[2*VvW +: VvW] = acc[F +: VvW];
    u_d = {abc_q[1*DW +: DW], DW'(-abc_q[2*DW +: DW])};
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 28
      abc_q <= abc_d;
      // Stage 29
      w_q   <= w_d;
      v_q   <= v_d;
      u_q   <= u_d;
    end
  end

  assign w_o = w_q;
  assign v_o = v_q;
  assign u_o = u_q;

  // Products beyond the contract's ranges and below the roundings.
  logic unused_frame;
  assign unused_frame = ^{bb, ccs, ab, acc};

endmodule
