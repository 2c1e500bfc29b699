// cube5_frame_pos: where a stage of the frame is in the sweep (docs/numerics/frame.md, "Slice
// constants"). Every stage that needs the anchor of its current item keeps one of these and steps
// it once per item, so no position travels down the pipelines: beat m of row b of slice s, and the
// slice's ray offsets T_x(s) = s * DX, T_y(s) = s * DY accumulated exactly (no drift).
//
// The sweep may cover a range of slices s_first ..= s_last (the empty slices before and after are
// skipped): the counters start at s_first with T_x(s_first), T_y(s_first) from the set-up. Items
// past the last slice (the flush) keep counting into slice s_last + 1; the frame ignores them.
//
// The geometry (nbr - 1, nj - 1, s_first, s_last) is taken at start_i into registers, so that each
// flag is an equality of two registers: the inputs need hold only in start_i's cycle, and no
// subtraction sits before a flag (in the accelerator the flags feed the compositing window's
// admission of the next beat, docs/accel.md, *Synthesis*).
module cube5_frame_pos #(
  /// Bits of a dimension (MaxDimLog2 + 1).
  parameter int unsigned DimW = 7,
  /// Bits of T_x, T_y: signed, at least DimW + StepW + 2.
  parameter int unsigned TW   = 25,
  /// Bits of DX, DY (S(2.StepW)).
  parameter int unsigned DW   = 18
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Back to the first item of a frame (beat 0, row 0, slice s_first); takes the geometry below.
  input  logic start_i,
  /// The current item moves on.
  input  logic step_i,
  /// Beats per row, ni / P (>= 1).
  input  logic [DimW-1:0] nbr_i,
  /// Rows per slice, nj.
  input  logic [DimW-1:0] nj_i,
  /// The first and last slice of the sweep.
  input  logic [DimW-1:0] s_first_i,
  input  logic [DimW-1:0] s_last_i,
  /// T_x(s_first) = s_first DX, T_y(s_first) = s_first DY.
  input  logic signed [TW-1:0] tx0_i,
  input  logic signed [TW-1:0] ty0_i,
  /// Per-slice ray steps, S(2.StepW).
  input  logic signed [DW-1:0] dx_i,
  input  logic signed [DW-1:0] dy_i,

  /// Beat within the row, row, slice (slice counts on past s_last in the flush).
  output logic [DimW-1:0] m_o,
  output logic [DimW-1:0] b_o,
  output logic [DimW-1:0] s_o,
  /// T_x(s), T_y(s), S(.StepW).
  output logic signed [TW-1:0] tx_o,
  output logic signed [TW-1:0] ty_o,
  /// m = 0, m = nbr - 1, b = 0, b = nj - 1, s = s_first, s = s_last.
  output logic first_beat_o,
  output logic last_beat_o,
  output logic first_row_o,
  output logic last_row_o,
  output logic first_slice_o,
  output logic last_slice_o
);

  logic [DimW-1:0] m_q, m_d, b_q, b_d, s_q, s_d;
  logic signed [TW-1:0] tx_q, tx_d, ty_q, ty_d;
  logic [DimW-1:0] last_m_q, last_b_q, s_first_q, s_last_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      last_m_q  <= '0;
      last_b_q  <= '0;
      s_first_q <= '0;
      s_last_q  <= '0;
    end else if (start_i) begin
      last_m_q  <= nbr_i - DimW'(1);
      last_b_q  <= nj_i - DimW'(1);
      s_first_q <= s_first_i;
      s_last_q  <= s_last_i;
    end
  end

  assign first_beat_o  = (m_q == '0);
  assign last_beat_o   = (m_q == last_m_q);
  assign first_row_o   = (b_q == '0);
  assign last_row_o    = (b_q == last_b_q);
  assign first_slice_o = (s_q == s_first_q);
  assign last_slice_o  = (s_q == s_last_q);

  always_comb begin
    m_d  = m_q;
    b_d  = b_q;
    s_d  = s_q;
    tx_d = tx_q;
    ty_d = ty_q;
    if (start_i) begin
      m_d  = '0;
      b_d  = '0;
      s_d  = s_first_i;
      tx_d = tx0_i;
      ty_d = ty0_i;
    end else if (step_i) begin
      if (!last_beat_o) begin
        m_d = m_q + DimW'(1);
      end else begin
        m_d = '0;
        if (!last_row_o) begin
          b_d = b_q + DimW'(1);
        end else begin
          b_d  = '0;
          s_d  = s_q + DimW'(1);
          tx_d = tx_q + TW'(dx_i);
          ty_d = ty_q + TW'(dy_i);
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      m_q  <= '0;
      b_q  <= '0;
      s_q  <= '0;
      tx_q <= '0;
      ty_q <= '0;
    end else begin
      m_q  <= m_d;
      b_q  <= b_d;
      s_q  <= s_d;
      tx_q <= tx_d;
      ty_q <= ty_d;
    end
  end

  assign m_o  = m_q;
  assign b_o  = b_q;
  assign s_o  = s_q;
  assign tx_o = tx_q;
  assign ty_o = ty_q;

endmodule
