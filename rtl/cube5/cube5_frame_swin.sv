// cube5_frame_swin: the 3x3 sample window of the frame (docs/numerics/frame.md, "Gradients in the
// frame"): from the stream of anchor beats (per pipeline the samples A = S'(s+1), C = S_s,
// B = S'(s-1)) it assembles, one row and one beam later, each anchor's gradient neighbourhood: C, the
// in-plane neighbours S_s(a-1, b), S_s(a+1, b), S_s(a, b-1), S_s(a, b+1), and B, A. Neighbours
// outside the face read as 0.
//
// Seen in the cycle of sample item v (en high), with u = v - nbr - 1 the anchor beat:
//   C(u)        = centre register      (row FIFO 1 then one beam register)
//   C(u - 1)    = x- register           (one more beam register: lane P-1 gives lane 0's a-1)
//   C(u + 1)    = row FIFO 1 output     (lane 0 gives lane P-1's a+1)
//   C(u - nbr)  = row FIFO 2 output     (row b-1)
//   C(u + nbr)  = y+ register           (row b+1: item v - 1)
//   A(u), B(u)  = a delay of nbr + 1 items
// The first nbr + 1 items of a frame only fill the window; each later item issues one block, one
// cycle later (an output register). Items may come with gaps: everything advances per item.
//
// Edges = 1 (a section of the face): each item also carries S_s(A0 - 1) and S_s(A0 + ns) of its
// row, which travel with C; they are x- of lane 0 on the row's first beat and x+ of lane P-1 on its
// last, in place of the zeros of a whole row.
module cube5_frame_swin #(
  parameter int unsigned P       = 4,
  parameter int unsigned MaxDim  = 64,
  parameter int unsigned SampleW = 16,
  parameter int unsigned DimW    = 7,
  /// 1: items carry the section's edge samples (above).
  parameter int unsigned Edges   = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// New frame.
  input  logic start_i,
  /// nbr, nj, nk and nbr - 1 (the row FIFO length).
  input  logic [DimW-1:0] nbr_i,
  input  logic [DimW-1:0] nj_i,
  input  logic [DimW-1:0] nk_i,
  input  logic [$clog2(MaxDim/P+1)-1:0] row_len_i,

  /// Samples of one anchor beat (cube5_frame_interp's layout: level 0 A, 1 C, 2 B; lane-minor).
  input  logic smp_valid_i,
  input  logic [(3*P+2*Edges)*SampleW-1:0] smp_i,

  /// One anchor beat's neighbourhoods, lane l at [l*7*SampleW +: 7*SampleW] as
  /// C, x-, x+, y-, y+, B, A (SampleW each, LSB first).
  output logic nb_valid_o,
  output logic [7*P*SampleW-1:0] nb_o
);

  localparam int unsigned BeatW = P * SampleW;
  localparam int unsigned RowLenW = $clog2(MaxDim/P+1);
  localparam int unsigned CW      = BeatW + 2 * Edges * SampleW;   // C with the edge samples

  logic [BeatW-1:0] cur_a, cur_c, cur_b;
  assign cur_a = smp_i[0*BeatW +: BeatW];
  assign cur_c = smp_i[1*BeatW +: BeatW];
  assign cur_b = smp_i[2*BeatW +: BeatW];

  logic [CW-1:0]      cur_cx, row1x;
  logic [SampleW-1:0] ctr_elo, ctr_ehi;   // the centre item's S_s(A0 - 1), S_s(A0 + ns)
  logic [BeatW-1:0]   ctr_q;
  logic [CW-1:0]      ctrx_q;
  if (Edges != 0) begin : gen_edges
    assign cur_cx  = {smp_i[3*BeatW +: 2*SampleW], cur_c};
    assign ctr_elo = ctrx_q[BeatW +: SampleW];
    assign ctr_ehi = ctrx_q[BeatW + SampleW +: SampleW];
  end else begin : gen_no_edges
    assign cur_cx  = cur_c;
    assign ctr_elo = '0;
    assign ctr_ehi = '0;
  end

  // ---------------------------------------------------------------------------
  // Delay lines
  // ---------------------------------------------------------------------------
  logic [BeatW-1:0]   row1, row2, yp_q;
  logic [SampleW-1:0] xm_q;     // lane P-1 of the beat before the centre
  logic [2*BeatW-1:0] ab_d;

  cube5_frame_delay #(
    .Width (CW),
    .Depth (MaxDim / P)
  ) u_row1 (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (start_i),
    .en_i    (smp_valid_i),
    .len_i   (row_len_i),
    .d_i     (cur_cx),
    .q_o     (row1x)
  );
  assign row1  = row1x[0 +: BeatW];
  assign ctr_q = ctrx_q[0 +: BeatW];

  cube5_frame_delay #(
    .Width (BeatW),
    .Depth (MaxDim / P)
  ) u_row2 (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (start_i),
    .en_i    (smp_valid_i),
    .len_i   (row_len_i),
    .d_i     (ctr_q),
    .q_o     (row2)
  );

  // A and B of the anchor: nbr + 1 items back (length nbr; nbr <= MaxDim / P).
  logic [RowLenW-1:0] ab_len;
  assign ab_len = RowLenW'(nbr_i);
  cube5_frame_delay #(
    .Width (2 * BeatW),
    .Depth (MaxDim / P)
  ) u_ab (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (start_i),
    .en_i    (smp_valid_i),
    .len_i   (ab_len),
    .d_i     ({cur_b, cur_a}),
    .q_o     (ab_d)
  );

  always_ff @(posedge clk_i) begin
    if (smp_valid_i) begin
      yp_q  <= cur_c;
      ctrx_q <= row1x;
      xm_q  <= ctr_q[(P-1)*SampleW +: SampleW];
    end
  end

  // ---------------------------------------------------------------------------
  // Anchor position: the first nbr + 1 items only fill the window
  // ---------------------------------------------------------------------------
  logic [DimW-1:0] lag_q, lag_d;
  logic            fire;

  assign fire = smp_valid_i && (lag_q == '0);

  always_comb begin
    lag_d = lag_q;
    if (start_i) begin
      lag_d = nbr_i + DimW'(1);
    end else if (smp_valid_i && lag_q != '0) begin
      lag_d = lag_q - DimW'(1);
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
  logic signed [1:0] unused_tx, unused_ty;
  logic first_beat, last_beat, first_row, last_row, first_slice, last_slice;

  cube5_frame_pos #(
    .DimW (DimW),
    .TW   (2),
    .DW   (2)
  ) u_pos (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .start_i       (start_i),
    .step_i        (fire),
    .nbr_i         (nbr_i),
    .nj_i          (nj_i),
    .s_first_i     ('0),
    .s_last_i      (nk_i - DimW'(1)),
    .tx0_i         (2'sd0),
    .ty0_i         (2'sd0),
    .dx_i          (2'sd0),
    .dy_i          (2'sd0),
    .m_o           (pos_m),
    .b_o           (pos_b),
    .s_o           (pos_s),
    .tx_o          (unused_tx),
    .ty_o          (unused_ty),
    .first_beat_o  (first_beat),
    .last_beat_o   (last_beat),
    .first_row_o   (first_row),
    .last_row_o    (last_row),
    .first_slice_o (first_slice),
    .last_slice_o  (last_slice)
  );

  // ---------------------------------------------------------------------------
  // Neighbourhoods
  // ---------------------------------------------------------------------------
  logic [BeatW-1:0] ab_a, ab_b;
  assign ab_a = ab_d[0 +: BeatW];
  assign ab_b = ab_d[BeatW +: BeatW];

  logic [7*P*SampleW-1:0] nb;

  always_comb begin
    for (int unsigned l = 0; l < P; l++) begin
      logic [SampleW-1:0] c, xm, xp, ym, yp;
      c = ctr_q[l*SampleW +: SampleW];
      if (l > 0) begin
        xm = ctr_q[(l-1)*SampleW +: SampleW];
      end else begin
        xm = first_beat ? '0 : xm_q;
        if (Edges != 0 && first_beat) xm = ctr_elo;
      end
      if (l + 1 < P) begin
        xp = ctr_q[(l+1)*SampleW +: SampleW];
      end else begin
        xp = last_beat ? '0 : row1[0 +: SampleW];
        if (Edges != 0 && last_beat) xp = ctr_ehi;
      end
      ym = first_row ? '0 : row2[l*SampleW +: SampleW];
      yp = last_row ? '0 : yp_q[l*SampleW +: SampleW];
      nb[l*7*SampleW +: 7*SampleW] = {ab_a[l*SampleW +: SampleW], ab_b[l*SampleW +: SampleW],
                                      yp, ym, xp, xm, c};
    end
  end

  // Output register (keeps the window's muxes and masks off the gradient units' first stage).
  logic                   nb_valid_q;
  logic [7*P*SampleW-1:0] nb_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      nb_valid_q <= 1'b0;
    end else begin
      nb_valid_q <= fire;
    end
  end

  always_ff @(posedge clk_i) begin
    if (fire) nb_q <= nb;
  end

  assign nb_valid_o = nb_valid_q;
  assign nb_o       = nb_q;

  logic unused_pos;
  assign unused_pos = ^{pos_m, pos_b, pos_s, unused_tx, unused_ty, first_slice, last_slice,
                        row1};

endmodule
