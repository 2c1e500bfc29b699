// cube5_frame_vwin: the voxel window of the frame (docs/numerics/frame.md, "Order of work in the
// RTL"; patent [47]): from the stream of memory beats x(t) (P voxels each, beams in row order, rows
// in slice order, slices front to back) it holds the three slices and two rows that the samples of
// one anchor beat need, with two slice FIFOs, a row FIFO and two beam registers per slice level.
//
// Seen in the cycle of beat t (en_i high), level L = 0, 1, 2 (slice s+1, s, s-1 of the anchor beat
// u = t - nbs - nbr - 1) offers four beats:
//   hi_cur  = x(t - L*nbs)             row b+1, beat m+1
//   hi_prev = x(t - L*nbs - 1)         row b+1, beat m
//   lo_cur  = x(t - L*nbs - nbr)       row b,   beat m+1
//   lo_prev = x(t - L*nbs - nbr - 1)   row b,   beat m
// with nbr = ni/P beats per row and nbs = ni*nj/P beats per slice. Taps that reach before the first
// beat of the frame or across a row, slice or frame edge hold stale words: the caller masks them
// (the contract's zero rules).
module cube5_frame_vwin #(
  /// Pipelines (voxels per beat).
  parameter int unsigned P      = 4,
  /// Voxel width.
  parameter int unsigned VoxelW = 12,
  /// Largest volume edge.
  parameter int unsigned MaxDim = 64,
  /// Longest row in anchors: MaxDim, or a sectioned frame's widest section (the slice FIFOs hold
  /// MaxRow MaxDim / P beats; slice_len_i stays below that).
  parameter int unsigned MaxRow = MaxDim,
  /// Voxels carried beside the P lanes of each beat (3: a sectioned frame's edge voxels lo, hi0,
  /// hi1; 0: none). They travel through every delay line with their beat.
  parameter int unsigned Extra  = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// New frame: the FIFO pointers return to 0.
  input  logic clear_i,
  /// Beat t arrives.
  input  logic en_i,
  /// nbr - 1 and nbs - 1 (the FIFO lengths; nbr >= 2).
  input  logic [$clog2(MaxDim/P+1)-1:0] row_len_i,
  input  logic [$clog2(MaxDim*MaxDim/P+1)-1:0] slice_len_i,
  /// Beat t, lane l at [l*VoxelW +: VoxelW], then the Extra voxels.
  input  logic [(P+Extra)*VoxelW-1:0] beat_i,

  /// Taps, tap (L, q) at [(4*L + q)*BeatW +: BeatW], BeatW = (P + Extra) VoxelW, q = 0 lo_prev,
  /// 1 lo_cur, 2 hi_prev, 3 hi_cur.
  output logic [12*(P+Extra)*VoxelW-1:0] taps_o
);

  localparam int unsigned BeatW = (P + Extra) * VoxelW;
  localparam int unsigned SliceDepth = MaxRow * MaxDim / P;
  localparam int unsigned SliceLenW  = $clog2(SliceDepth + 1);

  if (MaxRow < 2 * P || MaxRow > MaxDim) begin : gen_bad_max_row
    $fatal(1, "cube5_frame_vwin: MaxRow must be 2 P ..= MaxDim");
  end

  // The slice FIFOs' length (explicitly sized: Yosys ignores a narrowing cast on a port).
  logic [SliceLenW-1:0] slice_len;
  logic                 unused_slice_len;
  assign slice_len        = slice_len_i[SliceLenW-1:0];
  assign unused_slice_len = ^slice_len_i;

  // Per level L at [L*BeatW +: BeatW] (flat vectors: these are registers, not RAMs).
  logic [3*BeatW-1:0] lvl;        // hi_cur of each level
  logic [3*BeatW-1:0] row;        // lo_cur of each level
  logic [3*BeatW-1:0] hi_prev_q;
  logic [3*BeatW-1:0] lo_prev_q;

  assign lvl[0 +: BeatW] = beat_i;

  // Slice FIFOs: level 1 lags level 0 by one slice, level 2 lags level 1 by one slice.
  for (genvar l = 1; l < 3; l++) begin : gen_slice_fifo
    cube5_frame_delay #(
      .Width (BeatW),
      .Depth (SliceDepth)
    ) u_slice (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (clear_i),
      .en_i    (en_i),
      .len_i   (slice_len),
      .d_i     (lvl[(l-1)*BeatW +: BeatW]),
      .q_o     (lvl[l*BeatW +: BeatW])
    );
  end

  // Row FIFOs and beam registers of each level.
  for (genvar l = 0; l < 3; l++) begin : gen_level
    cube5_frame_delay #(
      .Width (BeatW),
      .Depth (MaxDim / P)
    ) u_row (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (clear_i),
      .en_i    (en_i),
      .len_i   (row_len_i),
      .d_i     (lvl[l*BeatW +: BeatW]),
      .q_o     (row[l*BeatW +: BeatW])
    );

    always_ff @(posedge clk_i) begin
      if (en_i) begin
        hi_prev_q[l*BeatW +: BeatW] <= lvl[l*BeatW +: BeatW];
        lo_prev_q[l*BeatW +: BeatW] <= row[l*BeatW +: BeatW];
      end
    end

    assign taps_o[(4*l + 0)*BeatW +: BeatW] = lo_prev_q[l*BeatW +: BeatW];
    assign taps_o[(4*l + 1)*BeatW +: BeatW] = row[l*BeatW +: BeatW];
    assign taps_o[(4*l + 2)*BeatW +: BeatW] = hi_prev_q[l*BeatW +: BeatW];
    assign taps_o[(4*l + 3)*BeatW +: BeatW] = lvl[l*BeatW +: BeatW];
  end

endmodule
