// cube5_frame_interp: the samples of the frame (docs/numerics/frame.md, "Samples and rays" and
// "Gradients in the frame"): from the stream of memory beats, the voxel window (cube5_frame_vwin)
// and, per pipeline, three cube5_trilin units that interpolate at each anchor (a, b) of slice s the
// bilinear samples of slices s-1, s and s+1 with slice s's weights: B = S'(s-1), C = S_s, A = S'(s+1).
//
// The anchor beat u is the memory beat t = u + nbs + nbr + 1 (one slice, one row and one beam
// behind the memory), so each beat that arrives after the first nbs + nbr + 1 of a frame issues one
// item to the 3P interpolators (through one register of corners). Zero rules of the contract: a corner beyond the far faces (a + 1 =
// ni, b + 1 = nj) and a slice outside 0 .. nk-1 read as 0. The interpolators never stall (their
// outputs are always taken); the caller sends exactly as many beats as the frame needs. Beats may
// come with gaps (beat_valid_i low): every window, counter and register advances per beat.
//
// Edges = 1 (a section [A0, A0 + ns) of the face, docs/numerics/frame.md, "Sections"): each beat
// carries the edge voxels lo, hi0, hi1 (columns A0 - 1, A0 + ns, A0 + ns + 1) beside its lanes, as
// cube5_section_buf hands them over on a row's first and last beat. The last lane's corner a + 1
// at the row's last beat is hi0 (not 0), and two more interpolators per beat give S_s at A0 - 1
// (from lo and lane 0) and at A0 + ns (from hi0 and hi1): the gradient's x- of the first anchor
// and x+ of the last. They are 0 at the face's own edges (edge_lo_on_i, edge_hi_on_i low).
module cube5_frame_interp #(
  parameter int unsigned P       = 4,
  parameter int unsigned MaxDim  = 64,
  /// Longest row in anchors (cube5_frame_vwin): MaxDim, or the widest section.
  parameter int unsigned MaxRow  = MaxDim,
  parameter int unsigned VoxelW  = 12,
  parameter int unsigned WeightW = 8,
  parameter int unsigned FracW   = 4,
  /// Bits of a dimension, T_x and DX (see cube5_frame_pos).
  parameter int unsigned DimW    = 7,
  parameter int unsigned TW      = 25,
  parameter int unsigned DW      = 18,
  /// 1: beats carry a section's edge voxels (above); 0: whole rows, zeros past the row.
  parameter int unsigned Edges   = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// New frame (the parameters below are stable from here to the frame's end).
  input  logic start_i,
  input  logic [DimW-1:0] nbr_i,
  input  logic [DimW-1:0] nj_i,
  /// The sweep's first and last slice, T_x and T_y of the first (cube5_frame_pos).
  input  logic [DimW-1:0] s_first_i,
  input  logic [DimW-1:0] s_last_i,
  input  logic signed [TW-1:0] tx0_i,
  input  logic signed [TW-1:0] ty0_i,
  input  logic signed [DW-1:0] dx_i,
  input  logic signed [DW-1:0] dy_i,
  /// nbr - 1, nbs - 1 (FIFO lengths) and nbs + nbr + 1 (beats before the first anchor).
  input  logic [$clog2(MaxDim/P+1)-1:0] row_len_i,
  input  logic [$clog2(MaxDim*MaxDim/P+1)-1:0] slice_len_i,
  input  logic [$clog2(MaxDim*MaxDim/P+1):0] lag_i,

  /// Edges = 1: the section does not start at a = 0 (lo is a voxel of the face), does not end at
  /// a = ni (hi0 is); otherwise the edge samples are 0. Ignored with Edges = 0.
  input  logic edge_lo_on_i,
  input  logic edge_hi_on_i,

  /// One memory beat (or a flush beat of zeros); lane l at [l*VoxelW +: VoxelW], then (Edges = 1)
  /// lo, hi0, hi1.
  input  logic beat_valid_i,
  input  logic [(P+3*Edges)*VoxelW-1:0] beat_i,

  /// Samples of one anchor beat: level L (0 = A = S'(s+1), 1 = C = S_s, 2 = B = S'(s-1)), lane l
  /// at [(L*P + l)*SampleW +: SampleW], U(VoxelW.FracW); with Edges = 1 then S_s(A0 - 1) and
  /// S_s(A0 + ns) of the beat's row (meaningful on the row's first and last beat only).
  output logic smp_valid_o,
  output logic [(3*P+2*Edges)*cube5_pkg::sample_w(VoxelW, FracW)-1:0] smp_o
);

  localparam int unsigned SampleW = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned BeatW   = (P + 3 * Edges) * VoxelW;   // a beat with its edge voxels
  localparam int unsigned NTri    = 3 * P + 2 * Edges;
  localparam int unsigned TriInW  = cube5_pkg::trilin_in_w(VoxelW, WeightW);
  localparam int unsigned StepW   = cube5_frame_pkg::StepW;
  localparam int unsigned LagW    = $clog2(MaxDim*MaxDim/P+1) + 1;

  if (Edges > 1) begin : gen_bad_edges
    $fatal(1, "cube5_frame_interp: Edges must be 0 or 1");
  end
  if (WeightW > StepW) begin : gen_bad_weight_w
    $fatal(1, "cube5_frame_interp: WeightW must not exceed StepW");
  end

  // ---------------------------------------------------------------------------
  // Voxel window
  // ---------------------------------------------------------------------------
  logic [12*BeatW-1:0] taps;

  cube5_frame_vwin #(
    .P      (P),
    .VoxelW (VoxelW),
    .MaxDim (MaxDim),
    .MaxRow (MaxRow),
    .Extra  (3 * Edges)
  ) u_vwin (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .clear_i     (start_i),
    .en_i        (beat_valid_i),
    .row_len_i   (row_len_i),
    .slice_len_i (slice_len_i),
    .beat_i      (beat_i),
    .taps_o      (taps)
  );

  // ---------------------------------------------------------------------------
  // Anchor position: the first nbs + nbr + 1 beats only fill the window
  // ---------------------------------------------------------------------------
  logic [LagW-1:0] lag_q, lag_d;
  logic            fire;

  assign fire = beat_valid_i && (lag_q == '0);

  always_comb begin
    lag_d = lag_q;
    if (start_i) begin
      lag_d = lag_i;
    end else if (beat_valid_i && lag_q != '0) begin
      lag_d = lag_q - LagW'(1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      lag_q <= '0;
    end else begin
      lag_q <= lag_d;
    end
  end

  logic [DimW-1:0] pos_m, pos_b, pos_s;
  logic signed [TW-1:0] tx, ty;
  logic first_beat, last_beat, first_row, last_row, first_slice, last_slice;

  cube5_frame_pos #(
    .DimW (DimW),
    .TW   (TW),
    .DW   (DW)
  ) u_pos (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .start_i       (start_i),
    .step_i        (fire),
    .nbr_i         (nbr_i),
    .nj_i          (nj_i),
    .s_first_i     (s_first_i),
    .s_last_i      (s_last_i),
    .tx0_i         (tx0_i),
    .ty0_i         (ty0_i),
    .dx_i          (dx_i),
    .dy_i          (dy_i),
    .m_o           (pos_m),
    .b_o           (pos_b),
    .s_o           (pos_s),
    .tx_o          (tx),
    .ty_o          (ty),
    .first_beat_o  (first_beat),
    .last_beat_o   (last_beat),
    .first_row_o   (first_row),
    .last_row_o    (last_row),
    .first_slice_o (first_slice),
    .last_slice_o  (last_slice)
  );

  // Weights of slice s: the fractions truncated to WeightW bits (never 1.0).
  logic [WeightW-1:0] wx, wy;
  assign wx = tx[StepW-1 -: WeightW];
  assign wy = ty[StepW-1 -: WeightW];

  // ---------------------------------------------------------------------------
  // Corners: lane l's 2x2 voxels at level L, with the zero rules
  // ---------------------------------------------------------------------------
  logic [3*P*TriInW-1:0]  tri_in;      // the lanes' interpolators
  logic [NTri*TriInW-1:0] tri_all;     // and the section's two edge interpolators

  // Edge voxels of the lo_prev (row b) and hi_prev (row b + 1) taps, level L at
  // [L*3*VoxelW +: 3*VoxelW] as lo, hi0, hi1 (zeros when Edges = 0). Levels 0 and 2 read hi0 only
  // (the corners a + 1 of the last lane), level 1 all three.
  logic [9*VoxelW-1:0] eg_lo, eg_hi;
  logic                unused_eg;
  if (Edges != 0) begin : gen_edges
    for (genvar lv = 0; lv < 3; lv++) begin : gen_level
      assign eg_lo[lv*3*VoxelW +: 3*VoxelW] = taps[(4*lv + 0)*BeatW + P*VoxelW +: 3*VoxelW];
      assign eg_hi[lv*3*VoxelW +: 3*VoxelW] = taps[(4*lv + 2)*BeatW + P*VoxelW +: 3*VoxelW];
    end
  end else begin : gen_no_edges
    assign eg_lo = '0;
    assign eg_hi = '0;
  end
  assign unused_eg = ^{eg_lo, eg_hi};
  logic                  unused_taps;   // of the next beats only lane 0 is read

  always_comb begin
    unused_taps = 1'b0;
    for (int unsigned lv = 0; lv < 3; lv++) begin
      unused_taps ^= ^taps[(4*lv + 1)*BeatW +: BeatW] ^ ^taps[(4*lv + 3)*BeatW +: BeatW];
    end
  end

  always_comb begin
    for (int unsigned lv = 0; lv < 3; lv++) begin
      logic             lvl_on;
      logic [BeatW-1:0]  lo_prev, hi_prev;
      logic [VoxelW-1:0] lo_next, hi_next;   // lane 0 of the next beat
      lvl_on = !((lv == 0 && last_slice) || (lv == 2 && first_slice));
      lo_prev = taps[(4*lv + 0)*BeatW +: BeatW];
      lo_next = taps[(4*lv + 1)*BeatW +: VoxelW];
      hi_prev = taps[(4*lv + 2)*BeatW +: BeatW];
      hi_next = taps[(4*lv + 3)*BeatW +: VoxelW];
      for (int unsigned l = 0; l < P; l++) begin
        logic [VoxelW-1:0] v00, v10, v01, v11;
        v00 = lo_prev[l*VoxelW +: VoxelW];
        v01 = hi_prev[l*VoxelW +: VoxelW];
        if (l + 1 < P) begin
          v10 = lo_prev[(l+1)*VoxelW +: VoxelW];
          v11 = hi_prev[(l+1)*VoxelW +: VoxelW];
        end else begin
          // Past the row: the section's hi0 (Edges = 1), or 0 at the face's edge.
          v10 = lo_next;
          v11 = hi_next;
          if (last_beat) begin
            v10 = '0;
            v11 = '0;
            if (Edges != 0 && edge_hi_on_i) begin
              v10 = eg_lo[(3*lv + 1)*VoxelW +: VoxelW];
              v11 = eg_hi[(3*lv + 1)*VoxelW +: VoxelW];
            end
          end
        end
        if (last_row) begin
          v01 = '0;
          v11 = '0;
        end
        if (!lvl_on) begin
          v00 = '0;
          v10 = '0;
          v01 = '0;
          v11 = '0;
        end
        // v[0..7] = corners x + 2y + 4z (the z+1 corners are 0), wx, wy, wz = 0, mode Lerp.
        tri_in[(lv*P + l)*TriInW +: TriInW] = {cube5_pkg::TrilinModeLerp, WeightW'(0), wy, wx,
                                               {4*VoxelW{1'b0}}, v11, v01, v10, v00};
      end
    end
  end

  // The section's edge samples at level 1 (slice s, never masked): e = 0 at A0 - 1 from lo and
  // lane 0, e = 1 at A0 + ns from hi0 and hi1; row b + 1 is 0 past the last row.
  if (Edges != 0) begin : gen_edge_tri
    logic [2*TriInW-1:0] tri_edge;
    always_comb begin
      for (int unsigned e = 0; e < 2; e++) begin
        logic [VoxelW-1:0] v00, v10, v01, v11;
        if (e == 0) begin
          v00 = eg_lo[3*VoxelW +: VoxelW];
          v10 = taps[(4 + 0)*BeatW +: VoxelW];
          v01 = eg_hi[3*VoxelW +: VoxelW];
          v11 = taps[(4 + 2)*BeatW +: VoxelW];
        end else begin
          v00 = eg_lo[4*VoxelW +: VoxelW];
          v10 = eg_lo[5*VoxelW +: VoxelW];
          v01 = eg_hi[4*VoxelW +: VoxelW];
          v11 = eg_hi[5*VoxelW +: VoxelW];
        end
        if (last_row) begin
          v01 = '0;
          v11 = '0;
        end
        if ((e == 0 && !edge_lo_on_i) || (e == 1 && !edge_hi_on_i)) begin
          v00 = '0;
          v10 = '0;
          v01 = '0;
          v11 = '0;
        end
        tri_edge[e*TriInW +: TriInW] = {cube5_pkg::TrilinModeLerp, WeightW'(0), wy, wx,
                                        {4*VoxelW{1'b0}}, v11, v01, v10, v00};
      end
    end
    assign tri_all = {tri_edge, tri_in};
  end else begin : gen_no_edge_tri
    assign tri_all = tri_in;
  end

  // ---------------------------------------------------------------------------
  // Corner register (keeps the window's muxes and masks off the interpolators' first stage)
  // ---------------------------------------------------------------------------
  logic                  tri_in_valid_q;
  logic [NTri*TriInW-1:0] tri_in_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      tri_in_valid_q <= 1'b0;
    end else begin
      tri_in_valid_q <= fire;
    end
  end

  always_ff @(posedge clk_i) begin
    if (fire) tri_in_q <= tri_all;
  end

  // ---------------------------------------------------------------------------
  // 3P interpolators, never stalled; Pipe = TrilinPipe (every multiplier between registers,
  // latency TrilinLatency)
  // ---------------------------------------------------------------------------
  logic [NTri-1:0] tri_ready, tri_valid;

  for (genvar i = 0; i < NTri; i++) begin : gen_trilin
    cube5_trilin #(
      .VoxelW  (VoxelW),
      .WeightW (WeightW),
      .FracW   (FracW),
      .Pipe    (cube5_frame_pkg::TrilinPipe)
    ) u_trilin (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (tri_in_valid_q),
      .in_ready_o  (tri_ready[i]),
      .in_data_i   (tri_in_q[i*TriInW +: TriInW]),
      .out_valid_o (tri_valid[i]),
      .out_ready_i (1'b1),
      .out_data_o  (smp_o[i*SampleW +: SampleW])
    );
  end

  assign smp_valid_o = tri_valid[0];

  // Unused position bits: the weights need only the fractions, the masks only the flags.
  logic unused_pos;
  assign unused_pos = ^{pos_m, pos_b, pos_s, tx[TW-1:StepW], ty[TW-1:StepW], first_beat,
                        first_row, tri_valid[NTri-1:1], unused_taps,
                        unused_eg, edge_lo_on_i, edge_hi_on_i};
  if (WeightW < StepW) begin : gen_unused_frac
    logic unused_frac;
    assign unused_frac = ^{tx[StepW-WeightW-1:0], ty[StepW-WeightW-1:0]};
  end

`ifndef SYNTHESIS
  // The interpolators never stall: their output is always taken.
  InterpAlwaysReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      tri_in_valid_q |-> &tri_ready)
    else $error("cube5_frame_interp: an interpolator was not ready");
`endif

endmodule
