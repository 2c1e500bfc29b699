// gicube_scatter_rsqrt: rsq(q) of docs/numerics/gicube_scatter.md (Normalization): 1/sqrt(q) as
// y * 2^-(YF + kk), from a seed LUT and one Newton step, in four register stages:
//   A  leading pair of q -> kk; q shifted so that the pair is on top -> mantissa m in [1, 4)
//   B  seed y0 = SEED[top SI bits of m]; pp = rnd(m y0, SF)          (~ sqrt(m))
//   C  b = rnd(pp y0, SF); c3 = 3 - b                                (~ 3 - m y0^2)
//   D  y = rnd(y0 c3, SF + 1)                                        (y0 (3 - m y0^2) / 2)
// q = 0 gives y = 0, kk = 0, m = 0. The SEED table is loaded through the configuration port.
module gicube_scatter_rsqrt #(
  /// Bits of q (unsigned).
  parameter int unsigned QW = 32,
  /// Direction fraction bits F; the seed and Newton widths derive from it.
  parameter int unsigned F  = 14,
  /// Bits of the exponent kk (at least $clog2 of the number of bit pairs in q).
  parameter int unsigned KW = 5
) (
  /// Clock.
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// Operand.
  input  logic [QW-1:0] q_i,

  /// SEED table write {we, index, value U(0.SF)}; every copy of the table receives the same writes.
  input  logic [gicube_scatter_pkg::seed_wr_w(F)-1:0] seed_wr_i,

  /// y, U(1.YF), four stages after q_i.
  output logic [gicube_scatter_pkg::newton_frac_w(F):0] y_o,
  /// kk: q = m 4^kk (m in [1, 4)).
  output logic [KW-1:0] kk_o,
  /// m, U(2.MF), truncated.
  output logic [gicube_scatter_pkg::newton_frac_w(F)+1:0] m_o
);

  localparam int unsigned SI = gicube_scatter_pkg::seed_idx_w(F);
  localparam int unsigned SF = gicube_scatter_pkg::seed_frac_w(F);
  localparam int unsigned MF = gicube_scatter_pkg::newton_frac_w(F);  // = NF = YF
  localparam int unsigned MW = MF + 2;                                // mantissa bits
  localparam int unsigned Q2 = QW + (QW % 2);                         // q padded to pairs
  localparam int unsigned Pairs = Q2 / 2;

  if (QW < 2 || QW > 64) begin : gen_bad_qw
    $fatal(1, "gicube_scatter_rsqrt: QW must be 2..64");
  end
  if ((1 << KW) < Pairs) begin : gen_bad_kw
    $fatal(1, "gicube_scatter_rsqrt: KW too narrow for QW");
  end

  // ---------------------------------------------------------------------------
  // SEED table: written by the configuration port, read asynchronously in stage B
  // ---------------------------------------------------------------------------
  logic          seed_we;
  logic [SI-1:0] seed_idx;
  logic [SF-1:0] seed_val;
  logic [SF-1:0] seed_q [2**SI];

  assign {seed_we, seed_idx, seed_val} = seed_wr_i;

  always_ff @(posedge clk_i) begin
    if (seed_we) seed_q[seed_idx] <= seed_val;
  end

  // ---------------------------------------------------------------------------
  // Stage A: exponent and mantissa
  // ---------------------------------------------------------------------------
  logic [Q2-1:0]    q_even, q_top;
  logic [Q2+MW-1:0] q_pad;  // q_top with MW zeros below, for any Q2 versus MW
  logic [KW-1:0]    kk_d, kk_q;
  logic [MW-1:0]    m_d, m_q;
  logic             zero_d, zero_q, zero_q2, zero_q3;

  always_comb begin
    q_even = Q2'(q_i);
    kk_d   = '0;
    for (int unsigned i = 0; i < Pairs; i++) begin
      if (q_even[2*i +: 2] != 2'b00) kk_d = KW'(i);
    end
    // The leading pair moves to the top two bits: a left shift by Q2 - 2 - 2 kk.
    q_top  = q_even << (Q2 - 2 - 2 * 32'(kk_d));
    q_pad  = {q_top, {MW{1'b0}}};
    m_d    = q_pad[Q2+MW-1 -: MW];
    zero_d = (q_i == '0);
  end

  // m and kk leave the unit beside y: stages B, C, D carry them unchanged.
  cube5_delay_regs #(
    .Width  (MW + KW),
    .Stages (3)
  ) u_m_kk_wait (
    .clk_i (clk_i),
    .en_i  (en_i),
    .d_i   ({m_q, kk_q}),
    .q_o   ({m_o, kk_o})
  );

  // ---------------------------------------------------------------------------
  // Stage B: seed y0 and pp = rnd(m y0, SF)
  // ---------------------------------------------------------------------------
  logic [SF-1:0]    y0_d, y0_q, y0_q2;
  logic [MW+SF-1:0] pp_full;
  logic [MW-1:0]    pp_d, pp_q;

  always_comb begin
    y0_d    = seed_q[m_q[MW-1 -: SI]];
    pp_full = (MW+SF)'(m_q) * (MW+SF)'(y0_d) + (MW+SF)'(1 << (SF - 1));
    pp_d    = pp_full[SF +: MW];
  end

  // ---------------------------------------------------------------------------
  // Stage C: b = rnd(pp y0, SF), c3 = 3 * 2^NF - b
  // ---------------------------------------------------------------------------
  logic [MW+SF-1:0] b_full;
  logic [MW-1:0]    c3_d, c3_q;

  always_comb begin
    b_full = (MW+SF)'(pp_q) * (MW+SF)'(y0_q) + (MW+SF)'(1 << (SF - 1));
    c3_d   = (MW'(3) << MF) - b_full[SF +: MW];
  end

  // ---------------------------------------------------------------------------
  // Stage D: y = rnd(y0 c3, SF + 1)
  // ---------------------------------------------------------------------------
  logic [MW+SF-1:0] y_full;
  logic [MF:0]      y_d, y_q;

  always_comb begin
    y_full = (MW+SF)'(y0_q2) * (MW+SF)'(c3_q) + (MW+SF)'(1 << SF);
    y_d    = zero_q3 ? '0 : y_full[SF + 1 +: MF + 1];
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      // Stage A
      m_q     <= m_d;
      kk_q    <= kk_d;
      zero_q  <= zero_d;
      // Stage B
      y0_q    <= y0_d;
      pp_q    <= pp_d;
      zero_q2 <= zero_q;
      // Stage C
      c3_q    <= c3_d;
      y0_q2   <= y0_q;
      zero_q3 <= zero_q2;
      // Stage D
      y_q     <= y_d;
    end
  end

  assign y_o = y_q;

  // The rounded-off fractions, and the pad below the mantissa.
  logic unused_rsqrt;
  assign unused_rsqrt = ^{pp_full[SF-1:0], b_full[SF-1:0], y_full[SF:0], q_pad[Q2-1:0]};

endmodule
