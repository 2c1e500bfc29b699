// gicube_scatter_draw: the random decisions of one ray (docs/numerics/gicube_scatter.md, Random
// numbers, Event choice, Glossy angle; patent [28], [380], [385]). The ray's bits are mangled into
// a 96-bit pool (gicube_scatter_hash, stages 1-2); stage 3 draws the event from r1..r3 against the
// material probabilities and folds the Irwin-Hall sum h; stage 4 scales h by the glossiness into
// the angle theta. phi and the ISO index are pool fields that ride along.
module gicube_scatter_draw #(
  /// Fraction bits M of the material fields.
  parameter int unsigned M = 8,
  /// Index bits A of the quarter-wave trigonometry table.
  parameter int unsigned A = 8,
  /// Index bits I of the isotropic direction LUT.
  parameter int unsigned I = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// The ray's mangling source.
  input  logic [31:0] ray_bits_i,
  /// refl, refr, iso, gloss, U(1.M) each, LSB first (raw: above 2^M reads as 1.0).
  input  logic [4*(M+1)-1:0] mat_i,
  /// Drawn event (gicube_scatter_pkg::Ev*), DrawLatency stages after the inputs.
  output logic [1:0] drawn_o,
  /// Glossy angle theta, 2^-A quarter turns.
  output logic [A-1:0] theta_o,
  /// Axis angle phi, 2^-(A+2) turns.
  output logic [A+1:0] phi_o,
  /// Index into the ISO table.
  output logic [I-1:0] iso_idx_o
);

  localparam int unsigned MW1       = M + 1;
  localparam int unsigned PhiW      = A + 2;
  localparam int unsigned PhiLsb    = 7 * M;        // after r1, r2, r3, u0..u3
  localparam int unsigned IsoIdxLsb = PhiLsb + PhiW;
  localparam int unsigned ThW       = 2 * M + 2;    // gloss' h < 2^(2M+2)
  localparam int unsigned ThShift   = 2 * M + 1 - A;

  // ---------------------------------------------------------------------------
  // Stages 1-2: the pool; the saturated material fields wait beside the hash
  // ---------------------------------------------------------------------------
  logic [95:0]      pool;
  logic [4*MW1-1:0] mat_sat, mat_s2;   // refl', refr', iso', gloss' = min(raw, 2^M)

  gicube_scatter_hash u_hash (
    .clk_i      (clk_i),
    .en_i       (en_i),
    .ray_bits_i (ray_bits_i),
    .pool_o     (pool)
  );

  always_comb begin
    for (int unsigned f = 0; f < 4; f++) begin
      logic [MW1-1:0] raw;
      raw = mat_i[f*MW1 +: MW1];
      mat_sat[f*MW1 +: MW1] = raw[M] ? MW1'(1 << M) : raw;
    end
  end

  cube5_delay_regs #(
    .Width  (4*MW1),
    .Stages (gicube_scatter_pkg::HashLatency)
  ) u_mat_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   (mat_sat),
    .q_o   (mat_s2)
  );

  // ---------------------------------------------------------------------------
  // Stage 3: the drawn event, h = |u0 + u1 + u2 + u3 + 2 - 2^(M+1)|, phi, the ISO index
  // ---------------------------------------------------------------------------
  logic [1:0]      drawn_d;
  logic [M:0]      h_d, h_q;
  logic [PhiW-1:0] phi_d;
  logic [I-1:0]    isoi_d;
  logic [MW1-1:0]  gloss_d, gloss_q;

  always_comb begin
    logic [M+2:0] s;  // sum of four M-bit uniforms, plus the +2 and the sign of the fold
    logic [M-1:0] r1, r2, r3;
    r1 = pool[0 +: M];
    r2 = pool[M +: M];
    r3 = pool[2*M +: M];
    if ({1'b0, r1} < mat_s2[0 +: MW1])            drawn_d = gicube_scatter_pkg::EvReflect;
    else if ({1'b0, r2} < mat_s2[MW1 +: MW1])     drawn_d = gicube_scatter_pkg::EvRefract;
    else if ({1'b0, r3} < mat_s2[2*MW1 +: MW1])   drawn_d = gicube_scatter_pkg::EvIso;
    else                                          drawn_d = gicube_scatter_pkg::EvPass;
    s = (M+3)'(pool[3*M +: M]) + (M+3)'(pool[4*M +: M]) + (M+3)'(pool[5*M +: M])
        + (M+3)'(pool[6*M +: M]) + (M+3)'(2);
    // h = |s - 2^(M+1)|: s lies in [2, 4 (2^M - 1) + 2] < 2^(M+2).
    h_d     = (s >= (M+3)'(2 << M)) ? (M+1)'(s - (M+3)'(2 << M)) : (M+1)'((M+3)'(2 << M) - s);
    phi_d   = pool[PhiLsb +: PhiW];
    isoi_d  = pool[IsoIdxLsb +: I];
    gloss_d = mat_s2[3*MW1 +: MW1];
  end

  // The event, phi and the ISO index wait one stage beside theta.
  cube5_delay_regs #(
    .Width  (2 + PhiW + I),
    .Stages (2)
  ) u_side_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({isoi_d, phi_d, drawn_d}),
    .q_o   ({iso_idx_o, phi_o, drawn_o})
  );

  // ---------------------------------------------------------------------------
  // Stage 4: theta = min(rnd(gloss' h, 2M + 1 - A), 2^A - 1)
  // ---------------------------------------------------------------------------
  logic [A-1:0] theta_d, theta_q;
  logic [ThW:0] th_full;

  always_comb begin
    th_full = (ThW+1)'(gloss_q) * (ThW+1)'(h_q) + (ThW+1)'(1 << (ThShift - 1));
    if ((th_full >> ThShift) >= (ThW+1)'(1 << A)) theta_d = '1;
    else                                           theta_d = th_full[ThShift +: A];
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage 3
      h_q     <= h_d;
      gloss_q <= gloss_d;
      // Stage 4
      theta_q <= theta_d;
    end
  end

  assign theta_o = theta_q;

  // Pool bits beyond the fields; the bits of gloss' h below the rounding.
  logic unused_draw;
  assign unused_draw = ^{pool, th_full};

endmodule
