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
  input  logic clk_i,
  /// Pipeline advance: every stage loads.
  input  logic en_i,
  /// Operand.
  input  logic [QW-1:0] q_i,

  /// SEED table write (all copies of the table receive the same writes).
  input  logic cfg_we_i,
  /// SEED index.
  input  logic [gicube_scatter_pkg::seed_idx_w(F)-1:0] cfg_idx_i,
  /// SEED value, U(0.SF).
  input  logic [gicube_scatter_pkg::seed_frac_w(F)-1:0] cfg_seed_i,

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
  logic [SF-1:0] seed_q [2**SI];

  always_ff @(posedge clk_i) begin
    if (cfg_we_i) seed_q[cfg_idx_i] <= cfg_seed_i;
  end

  // ---------------------------------------------------------------------------
  // Stage A: exponent and mantissa
  // ---------------------------------------------------------------------------
  logic [Q2-1:0]    q_even, q_top;
  logic [Q2+MW-1:0] q_pad;  // q_top with MW zeros below, for any Q2 versus MW
  logic [KW-1:0]    kk_a;
  logic [MW-1:0]    m_a;

  always_comb begin
    q_even = Q2'(q_i);
    kk_a   = '0;
    for (int unsigned i = 0; i < Pairs; i++) begin
      if (q_even[2*i +: 2] != 2'b00) kk_a = KW'(i);
    end
    // The leading pair moves to the top two bits: a left shift by Q2 - 2 - 2 kk.
    q_top = q_even << (Q2 - 2 - 2 * 32'(kk_a));
    q_pad = {q_top, {MW{1'b0}}};
    m_a   = q_pad[Q2+MW-1 -: MW];
  end

  logic [MW-1:0] m_b_q;
  logic [KW-1:0] kk_b_q;
  logic          zero_b_q;

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      m_b_q    <= m_a;
      kk_b_q   <= kk_a;
      zero_b_q <= (q_i == '0);
    end
  end

  // ---------------------------------------------------------------------------
  // Stage B: seed and pp = rnd(m y0, SF)
  // ---------------------------------------------------------------------------
  logic [SF-1:0]    y0_b;
  logic [MW+SF-1:0] pp_full;
  logic [MW-1:0]    pp_b;

  always_comb begin
    y0_b    = seed_q[m_b_q[MW-1 -: SI]];
    pp_full = (MW+SF)'(m_b_q) * (MW+SF)'(y0_b) + (MW+SF)'(1 << (SF - 1));
    pp_b    = pp_full[SF +: MW];
  end

  logic [MW-1:0] pp_c_q, m_c_q;
  logic [SF-1:0] y0_c_q;
  logic [KW-1:0] kk_c_q;
  logic          zero_c_q;

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      pp_c_q   <= pp_b;
      y0_c_q   <= y0_b;
      m_c_q    <= m_b_q;
      kk_c_q   <= kk_b_q;
      zero_c_q <= zero_b_q;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage C: b = rnd(pp y0, SF), c3 = 3 * 2^NF - b
  // ---------------------------------------------------------------------------
  logic [MW+SF-1:0] b_full;
  logic [MW-1:0]    c3_c;

  always_comb begin
    b_full = (MW+SF)'(pp_c_q) * (MW+SF)'(y0_c_q) + (MW+SF)'(1 << (SF - 1));
    c3_c   = (MW'(3) << MF) - b_full[SF +: MW];
  end

  logic [MW-1:0] c3_d_q, m_d_q;
  logic [SF-1:0] y0_d_q;
  logic [KW-1:0] kk_d_q;
  logic          zero_d_q;

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      c3_d_q   <= c3_c;
      y0_d_q   <= y0_c_q;
      m_d_q    <= m_c_q;
      kk_d_q   <= kk_c_q;
      zero_d_q <= zero_c_q;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage D: y = rnd(y0 c3, SF + 1)
  // ---------------------------------------------------------------------------
  logic [MW+SF-1:0] y_full;
  logic [MF:0]      y_d;

  always_comb begin
    y_full = (MW+SF)'(y0_d_q) * (MW+SF)'(c3_d_q) + (MW+SF)'(1 << SF);
    y_d    = zero_d_q ? '0 : y_full[SF + 1 +: MF + 1];
  end

  logic [MF:0]   y_q;
  logic [MW-1:0] m_q;
  logic [KW-1:0] kk_q;

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      y_q  <= y_d;
      m_q  <= m_d_q;
      kk_q <= kk_d_q;
    end
  end

  assign y_o  = y_q;
  assign kk_o = kk_q;
  assign m_o  = m_q;

  // The rounded-off fractions, and the pad below the mantissa.
  logic unused_rsqrt;
  assign unused_rsqrt = ^{pp_full[SF-1:0], b_full[SF-1:0], y_full[SF:0], q_pad[Q2-1:0]};

endmodule
