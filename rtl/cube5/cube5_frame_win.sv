// cube5_frame_win: the compositing window's control (cube5_frame Window = 1; issue 12,
// docs/numerics/compos_window.md, *RTL*). The compositing buffer keeps only the coxels of the
// rays the current section reaches; this unit says, per sample beat, which lanes' pixels enter
// the window (their coxel is the initial one, or a restored one) and which leave it (parked, or
// final), requests the restores ahead of the sweep, and holds the three output FIFOs.
//
// Pixel (R, Q) of anchor (a, b) at slice s: R = a + offx(s), Q = b + offy(s). Between slices the
// anchors of a ray move by dsx = sx(s) - sx(s - 1) (likewise y), at most one. For the lanes of one
// beat (anchor a = A0 + P m + l, row b, slice s):
//   enter   s = 0, or a - dsx(s) or b - dsy(s) is outside the section (a column or a row enters);
//   restore a column enters (not the row) and a - dsx(s) is inside the face: an earlier section
//           sampled the ray at slice s - 1 and parked it;
//   leave   s = nk - 1, or a + dsx(s + 1) or b + dsy(s + 1) is outside the section;
//   park    a column leaves (not the row), s < nk - 1 and a + dsx(s + 1) is inside the face: a
//           later section samples the ray; every other leaving pixel is final.
// Rows never park nor restore (a ray that leaves the face in j never comes back), so at most one
// lane of a beat parks and one restores; final pixels go out a beat's lanes at a time.
//
// Admission: the frame's beat admitted as number N (memory or flush) makes the compositing buffer
// read sample beat N - Trig (Trig = nbs + 2 nbr + 2, the windows' lag) some fixed cycles later.
// Before admitting it the unit reserves what that sample beat needs: its restored coxel (already
// in the restore FIFO), a place in the park FIFO and in the final FIFO. Its flags go into a
// descriptor FIFO that the buffer pops when it reads the beat; the leave flags and the pixel
// position follow to the write-back.
//
// Restores: a walker enumerates the restoring pixels of the section (slices 1 ..= nk - 1, the
// entering column's rows) in the order the buffer will take them and requests each (rq_*) while
// fewer than RsDepth are requested and not yet taken: the restore FIFO never overflows
// (rs_ready_o is high). It starts once the parks of earlier sections have left the park FIFO, so
// that the memory has them before their restores are read.
module cube5_frame_win #(
  parameter int unsigned P       = 4,
  parameter int unsigned DimW    = 7,
  parameter int unsigned TW      = 25,
  parameter int unsigned DW      = 18,
  /// Stored coxel bits.
  parameter int unsigned CoxW    = 85,
  /// Bits of Trig (the frame's flush count).
  parameter int unsigned TrigW   = 16,
  /// Park and final FIFO depth (a power of two): at least the beats between admission and
  /// write-back for a sweep without stalls.
  parameter int unsigned Depth   = 32,
  /// Restore FIFO depth (a power of two): restores requested ahead.
  parameter int unsigned RsDepth = 64,
  /// Descriptor FIFO depth (a power of two): the beats admitted and not yet read by the buffer.
  /// The admission's round trip (admit -> the buffer's read of the beat -> the registered full
  /// flag) is about 34 cycles, so 32 admits at most 32 beats per 34 cycles (0.94 beats per
  /// clock); 64 never stops a sweep on it (docs/accel.md, *Throughput against memory bandwidth*).
  parameter int unsigned DescDepth = 32
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// A section starts (the parameters below hold until its end).
  input  logic start_i,
  input  logic [DimW-1:0] nbr_i,
  input  logic [DimW-1:0] nj_i,
  input  logic [DimW-1:0] nk_i,
  /// The section starts at the face's first anchor (a0 = 0), ends at its last (a0 + ns = ni).
  input  logic lo_edge_i,
  input  logic hi_edge_i,
  input  logic signed [DW-1:0] dx_i,
  input  logic signed [DW-1:0] dy_i,
  /// max sx + A0 and max sy: R = (a - A0) + max_sx_i - sx(s), Q = b + max_sy_i - sy(s).
  input  logic [DimW-1:0] max_sx_i,
  input  logic [DimW-1:0] max_sy_i,
  input  logic [TrigW-1:0] trig_i,

  /// Admission: the frame may take a beat (or send a flush beat) this cycle; it does (adm_i).
  output logic adm_ok_o,
  input  logic adm_i,

  /// The buffer reads a sample beat: its lanes' enter and restore flags, the restored coxel.
  input  logic rd_i,
  output logic [P-1:0] rd_enter_o,
  output logic [P-1:0] rd_restore_o,
  output logic [CoxW-1:0] rd_rs_cox_o,

  /// The beat's results, lane order (a = A0 + P m + l), from the compositing units.
  input  logic wb_i,
  input  logic [P*CoxW-1:0] wb_cox_i,

  /// Parked coxels: {Q, R} and the coxel.
  output logic park_valid_o,
  input  logic park_ready_i,
  output logic [2*DimW-1:0] park_key_o,
  output logic [CoxW-1:0] park_cox_o,
  /// Final pixels: {Q, R} of lane 0, the lanes that are final, lane k's coxel (pixel R + k).
  output logic fin_valid_o,
  input  logic fin_ready_i,
  output logic [2*DimW-1:0] fin_key_o,
  output logic [P-1:0] fin_mask_o,
  output logic [P*CoxW-1:0] fin_cox_o,
  /// Restore requests {Q, R}; the coxels come back in this order.
  output logic rq_valid_o,
  input  logic rq_ready_i,
  output logic [2*DimW-1:0] rq_key_o,
  input  logic rs_valid_i,
  output logic rs_ready_o,
  input  logic [CoxW-1:0] rs_cox_i
);

  localparam int unsigned StepW = cube5_frame_pkg::StepW;
  localparam int unsigned LogP  = $clog2(P);
  localparam int unsigned KeyW  = 2 * DimW;
  localparam int unsigned CntW  = $clog2(Depth) + 1;
  localparam int unsigned RsCntW = $clog2(RsDepth) + 1;
  localparam int unsigned DescCntW = $clog2(DescDepth) + 1;
  localparam int unsigned DescW = 4 * P + KeyW;     // enter, restore, leave, final, {Q, R0}

  if (Depth < 2 || (1 << $clog2(Depth)) != Depth || RsDepth < 2
      || (1 << $clog2(RsDepth)) != RsDepth || DescDepth < 2
      || (1 << $clog2(DescDepth)) != DescDepth) begin : gen_bad_depth
    $fatal(1, "cube5_frame_win: Depth, RsDepth and DescDepth must be powers of two >= 2");
  end

  // ---------------------------------------------------------------------------
  // Flags of one beat at (m, b, s) with T_x(s), T_y(s)
  // ---------------------------------------------------------------------------
  function automatic logic signed [1:0] step_of(logic signed [TW-1:0] t, logic signed [DW-1:0] d);
    logic signed [TW-1:0] a, b;
    a = t >>> StepW;
    b = (t - TW'(d)) >>> StepW;
    step_of = 2'(a - b);
  endfunction

  // ---------------------------------------------------------------------------
  // Admission: the position of the next sample beat to be triggered
  // ---------------------------------------------------------------------------
  // For clock rate (docs/accel.md, *Synthesis*) adm_ok_o is a few gates of registers: the flags
  // of the next sample beat to be triggered are computed a beat ahead (the position counter runs
  // one beat in front of the admission and its flags are registered when the admission steps),
  // the trigger count's comparison is a register, and so is each credit's "none left".
  logic [TrigW-1:0] adm_cnt_q;
  logic             trig_q;     // the next admitted beat triggers a sample beat
  logic             adm_step;
  logic             prime_q;    // a section started: the flags of its first beat are not in yet
  logic             pos_step;   // the position counter moves on (it leads the admission by one)
  logic [DimW-1:0]  am, ab, as;
  logic signed [TW-1:0] atx, aty;
  logic af_beat, al_beat, af_row, al_row, af_slice, al_slice;

  assign adm_step = adm_i && trig_q;
  assign pos_step = adm_step || (prime_q && !start_i);

  // trig_i (the frame's flush count, at least 1) is valid from the cycle after start_i.
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      adm_cnt_q <= '0;
      trig_q    <= 1'b0;
      prime_q   <= 1'b0;
    end else if (start_i) begin
      adm_cnt_q <= '0;
      trig_q    <= 1'b0;
      prime_q   <= 1'b1;
    end else begin
      prime_q <= 1'b0;
      if (adm_i && !trig_q) begin
        adm_cnt_q <= adm_cnt_q + TrigW'(1);
        trig_q    <= adm_cnt_q + TrigW'(1) >= trig_i;
      end
    end
  end

  cube5_frame_pos #(
    .DimW (DimW),
    .TW   (TW),
    .DW   (DW)
  ) u_adm_pos (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .start_i       (start_i),
    .step_i        (pos_step),
    .nbr_i         (nbr_i),
    .nj_i          (nj_i),
    .s_first_i     ('0),
    .s_last_i      (nk_i - DimW'(1)),
    .tx0_i         ('0),
    .ty0_i         ('0),
    .dx_i          (dx_i),
    .dy_i          (dy_i),
    .m_o           (am),
    .b_o           (ab),
    .s_o           (as),
    .tx_o          (atx),
    .ty_o          (aty),
    .first_beat_o  (af_beat),
    .last_beat_o   (al_beat),
    .first_row_o   (af_row),
    .last_row_o    (al_row),
    .first_slice_o (af_slice),
    .last_slice_o  (al_slice)
  );

  logic signed [1:0] dsx_p, dsy_p, dsx_n, dsy_n;   // steps into and out of slice s
  logic [P-1:0] f_enter, f_restore, f_leave, f_final;
  logic         row_enter, row_leave;
  logic [DimW-1:0] r0, q0;
  logic signed [TW-1:0] sx_now, sy_now;
  logic unused_adm;

  // The flags of the beat at the position counter (the one after the next to be admitted).
  always_comb begin
    dsx_p     = step_of(atx, dx_i);
    dsy_p     = step_of(aty, dy_i);
    dsx_n     = step_of(atx + TW'(dx_i), dx_i);
    dsy_n     = step_of(aty + TW'(dy_i), dy_i);
    row_enter = !af_slice && ((dsy_p == 2'sd1 && af_row) || (dsy_p == -2'sd1 && al_row));
    row_leave = !al_slice && ((dsy_n == -2'sd1 && af_row) || (dsy_n == 2'sd1 && al_row));
    for (int unsigned l = 0; l < P; l++) begin
      logic first_a, last_a, col_enter, col_leave;
      first_a   = af_beat && (l == 0);
      last_a    = al_beat && (l == P - 1);
      col_enter = !af_slice && ((dsx_p == 2'sd1 && first_a) || (dsx_p == -2'sd1 && last_a));
      col_leave = !al_slice && ((dsx_n == -2'sd1 && first_a) || (dsx_n == 2'sd1 && last_a));
      f_enter[l]   = af_slice || col_enter || row_enter;
      f_restore[l] = col_enter && !row_enter && (dsx_p == 2'sd1 ? !lo_edge_i : !hi_edge_i);
      f_leave[l]   = al_slice || col_leave || row_leave;
      f_final[l]   = f_leave[l]
                     && !(col_leave && !row_leave && (dsx_n == -2'sd1 ? !lo_edge_i : !hi_edge_i));
    end
    sx_now = atx >>> StepW;
    sy_now = aty >>> StepW;
    r0     = DimW'(am << LogP) + max_sx_i - DimW'(sx_now);
    q0     = ab + max_sy_i - DimW'(sy_now);
  end
  assign unused_adm = ^{as, sx_now, sy_now};

  // The next sample beat's descriptor and needs, registered when the position counter steps.
  logic [DescW-1:0] adm_desc_q;
  logic             need_rs, need_park, need_fin;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      need_rs   <= 1'b0;
      need_park <= 1'b0;
      need_fin  <= 1'b0;
    end else if (pos_step) begin
      need_rs   <= |f_restore;
      need_park <= |(f_leave & ~f_final);
      need_fin  <= |f_final;
    end
  end
  always_ff @(posedge clk_i) begin
    if (pos_step) adm_desc_q <= {q0, r0, f_final, f_leave, f_restore, f_enter};
  end

  // Credits: restored coxels present and not yet promised, free places in the park and final
  // FIFOs not yet promised, free descriptors; beside each, whether none is left (a register
  // that follows the count: its next value from the count's compares and the cycle's events).
  logic [RsCntW-1:0] rs_avail_q;
  logic [CntW-1:0]   park_free_q, fin_free_q;
  logic [DescCntW-1:0] desc_cnt_q;
  logic              rs_none_q, park_none_q, fin_none_q, desc_full_q;
  logic              admit, rs_push, park_pop, fin_pop, rd_pop, take_rs, take_park, take_fin;

  assign adm_ok_o  = !trig_q || (!prime_q && !desc_full_q
                                 && (!need_rs || !rs_none_q)
                                 && (!need_park || !park_none_q)
                                 && (!need_fin || !fin_none_q));
  assign admit     = adm_step;
  assign take_rs   = admit && need_rs;
  assign take_park = admit && need_park;
  assign take_fin  = admit && need_fin;
  assign rs_push   = rs_valid_i && rs_ready_o;
  assign park_pop  = park_valid_o && park_ready_i;
  assign fin_pop   = fin_valid_o && fin_ready_i;
  assign rd_pop    = rd_i;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      rs_avail_q  <= '0;
      park_free_q <= CntW'(Depth);
      fin_free_q  <= CntW'(Depth);
      desc_cnt_q  <= '0;
      rs_none_q   <= 1'b1;
      park_none_q <= 1'b0;
      fin_none_q  <= 1'b0;
      desc_full_q <= 1'b0;
    end else begin
      rs_avail_q  <= rs_avail_q + RsCntW'(rs_push) - RsCntW'(take_rs);
      park_free_q <= park_free_q + CntW'(park_pop) - CntW'(take_park);
      fin_free_q  <= fin_free_q + CntW'(fin_pop) - CntW'(take_fin);
      desc_cnt_q  <= desc_cnt_q + DescCntW'(admit) - DescCntW'(rd_pop);
      // A take needs a count of at least one, so with no increment the count ends at zero
      // (full) when it is zero (full) or one short and taken.
      rs_none_q   <= !rs_push && (rs_avail_q == '0 || (rs_avail_q == RsCntW'(1) && take_rs));
      park_none_q <= !park_pop && (park_free_q == '0 || (park_free_q == CntW'(1) && take_park));
      fin_none_q  <= !fin_pop && (fin_free_q == '0 || (fin_free_q == CntW'(1) && take_fin));
      desc_full_q <= !rd_pop && (desc_cnt_q == DescCntW'(DescDepth)
                                 || (desc_cnt_q == DescCntW'(DescDepth - 1) && admit));
    end
  end

  // ---------------------------------------------------------------------------
  // Descriptors: admission -> the buffer's read -> the write-back
  // ---------------------------------------------------------------------------
  logic [DescW-1:0] desc_head, wb_desc;
  logic unused_d0, unused_d1, unused_d2, unused_d3;

  // The head in a register: the buffer's read of a descriptor (enter, restore) starts from a
  // flip-flop, not from the RAM's read mux (docs/accel.md, *Synthesis*).
  cube5_frame_fifo #(
    .Width  (DescW),
    .Depth  (DescDepth),
    .OutReg (1)
  ) u_desc (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (admit),
    .d_i     (adm_desc_q),
    .pop_i   (rd_pop),
    .q_o     (desc_head),
    .empty_o (unused_d0),
    .full_o  (unused_d1)
  );

  assign rd_enter_o   = desc_head[0 +: P];
  assign rd_restore_o = desc_head[P +: P];

  // From the read to the write-back: a fixed latency, at most a few beats in flight.
  cube5_frame_fifo #(
    .Width (DescW),
    .Depth (8)
  ) u_wb_desc (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (rd_pop),
    .d_i     (desc_head),
    .pop_i   (wb_i),
    .q_o     (wb_desc),
    .empty_o (unused_d2),
    .full_o  (unused_d3)
  );

  logic [P-1:0]    wb_leave, wb_final, wb_park;
  logic [KeyW-1:0] wb_key;      // {Q, R0}
  assign wb_leave = wb_desc[2*P +: P];
  assign wb_final = wb_desc[3*P +: P];
  assign wb_key   = wb_desc[4*P +: KeyW];
  assign wb_park  = wb_leave & ~wb_final;

  // ---------------------------------------------------------------------------
  // Park and final FIFOs
  // ---------------------------------------------------------------------------
  logic [KeyW-1:0] park_key;
  logic [CoxW-1:0] park_cox;
  always_comb begin
    park_key = wb_key;
    park_cox = wb_cox_i[0 +: CoxW];
    for (int unsigned l = 0; l < P; l++) begin
      if (wb_park[l]) begin
        park_key = {wb_key[DimW +: DimW], wb_key[0 +: DimW] + DimW'(l)};
        park_cox = wb_cox_i[l*CoxW +: CoxW];
      end
    end
  end

  logic park_empty, fin_empty, unused_pf, unused_ff;

  cube5_frame_fifo #(
    .Width (KeyW + CoxW),
    .Depth (Depth)
  ) u_park (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (wb_i && |wb_park),
    .d_i     ({park_cox, park_key}),
    .pop_i   (park_pop),
    .q_o     ({park_cox_o, park_key_o}),
    .empty_o (park_empty),
    .full_o  (unused_pf)
  );
  assign park_valid_o = !park_empty;

  cube5_frame_fifo #(
    .Width (KeyW + P + P * CoxW),
    .Depth (Depth)
  ) u_fin (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (wb_i && |wb_final),
    .d_i     ({wb_cox_i, wb_final, wb_key}),
    .pop_i   (fin_pop),
    .q_o     ({fin_cox_o, fin_mask_o, fin_key_o}),
    .empty_o (fin_empty),
    .full_o  (unused_ff)
  );
  assign fin_valid_o = !fin_empty;

  // ---------------------------------------------------------------------------
  // Restores: the walker, the requests, the restore FIFO
  // ---------------------------------------------------------------------------
  logic             rs_empty, unused_rf;
  logic             rs_pop;
  assign rs_pop = rd_pop && |rd_restore_o;

  cube5_frame_fifo #(
    .Width (CoxW),
    .Depth (RsDepth)
  ) u_rs (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (rs_push),
    .d_i     (rs_cox_i),
    .pop_i   (rs_pop),
    .q_o     (rd_rs_cox_o),
    .empty_o (rs_empty),
    .full_o  (unused_rf)
  );
  assign rs_ready_o = 1'b1;

  // Requested and not yet taken by the buffer (<= RsDepth: the FIFO has room for every answer).
  logic [RsCntW-1:0] rq_out_q;
  // Parks of earlier sections still in the park FIFO at this section's start.
  logic [CntW-1:0]   old_parks_q;
  // The walker: slice gs (1 ..= nk - 1), row gb, T_x(gs), T_y(gs).
  logic              g_on_q, g_on_d;
  logic [DimW-1:0]   gs_q, gs_d, gb_q, gb_d;
  logic signed [TW-1:0] gtx_q, gtx_d, gty_q, gty_d;
  // rq_out_q != RsDepth in a flip-flop, and the requests through a register slice whose ready is
  // a flip-flop (for clock rate: the walker's step no longer waits on the request's consumer nor
  // on the count's compare; the frame's critical path alone at 30d3a1b, rq_out_q -> g_go ->
  // rq_out_q through rq_ready_i).
  // The room's next value is formed from compares of the count beside the walker's step and
  // the pop, which only select (the line's critical path at 63ba58f ran through the count's adder
  // into that compare). The walker's "last row" (gb_q == nj_i - 1) is a flip-flop too, loaded
  // from compares of registers (that path began at nj_i's decrement).
  logic              rq_room_q, rq_room_d, rq_in_ready, rq_inc;
  logic [RsCntW-1:0] rq_out_d;
  logic              g_last_row_q, g_last_row_d;
  logic              g_go, g_col, g_emit;
  logic signed [1:0] g_dsx, g_dsy;
  logic [DimW-1:0]   g_r, g_q;
  logic signed [TW-1:0] g_sx, g_sy;

  // The walker's slice steps in registers (for clock rate: step_of's carry chains end in a
  // flip-flop instead of running on into g_go and rq_out_q): g_dsx_q = step_of(gtx_q, dx_i)
  // always, loaded with the next slice's step when the walker moves to it.
  logic signed [1:0] g_dsx_q, g_dsy_q, g_dsx_n, g_dsy_n, g_dsx0, g_dsy0;
  logic              g_slice;   // the walker moves to the next slice this cycle
  assign g_dsx_n = step_of(gtx_q + TW'(dx_i), dx_i);
  assign g_dsy_n = step_of(gty_q + TW'(dy_i), dy_i);
  assign g_dsx0  = step_of(TW'(dx_i), dx_i);
  assign g_dsy0  = step_of(TW'(dy_i), dy_i);

  always_comb begin
    g_dsx  = g_dsx_q;
    g_dsy  = g_dsy_q;
    g_sx   = gtx_q >>> StepW;
    g_sy   = gty_q >>> StepW;
    // The slice's entering column restores (from the section before it in sweep order).
    g_col  = (g_dsx == 2'sd1 && !lo_edge_i) || (g_dsx == -2'sd1 && !hi_edge_i);
    // Its row gb: not the entering row.
    g_emit = g_col && !((g_dsy == 2'sd1 && gb_q == '0) || (g_dsy == -2'sd1 && g_last_row_q));
    g_r    = ((g_dsx == 2'sd1) ? DimW'(0) : DimW'(nbr_i << LogP) - DimW'(1)) + max_sx_i - DimW'(g_sx);
    g_q    = gb_q + max_sy_i - DimW'(g_sy);
    g_go   = g_on_q && (old_parks_q == '0) && (!g_emit || (rq_in_ready && rq_room_q));

    g_on_d     = g_on_q;
    gs_d       = gs_q;
    gb_d       = gb_q;
    gtx_d      = gtx_q;
    gty_d      = gty_q;
    g_slice    = 1'b0;
    g_last_row_d = g_last_row_q;
    if (g_go) begin
      if (g_col && !g_last_row_q) begin
        gb_d = gb_q + DimW'(1);
        g_last_row_d = (gb_q == nj_i - DimW'(2));
      end else begin
        g_slice = 1'b1;
        gb_d  = '0;
        g_last_row_d = (nj_i == DimW'(1));
        gs_d  = gs_q + DimW'(1);
        gtx_d = gtx_q + TW'(dx_i);
        gty_d = gty_q + TW'(dy_i);
        if (gs_q == nk_i - DimW'(1)) g_on_d = 1'b0;
      end
    end
    if (start_i) begin
      g_on_d = nk_i != DimW'(1);
      gs_d   = DimW'(1);
      gb_d   = '0;
      g_last_row_d = (nj_i == DimW'(1));
      gtx_d  = TW'(dx_i);
      gty_d  = TW'(dy_i);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      g_on_q      <= 1'b0;
      rq_out_q    <= '0;
      rq_room_q   <= 1'b1;
      old_parks_q <= '0;
    end else begin
      g_on_q      <= g_on_d;
      rq_out_q    <= rq_out_d;
      rq_room_q   <= rq_room_d;
      if (start_i) begin
        // The parks reserved or queued at the end of this cycle: a pop (or a reservation) in
        // the start cycle itself counts (else the walker waits for a park that already left).
        old_parks_q <= CntW'(Depth) - park_free_q - CntW'(park_pop) + CntW'(take_park);
      end else if (park_pop && old_parks_q != '0) begin
        old_parks_q <= old_parks_q - CntW'(1);
      end
    end
  end

  always_ff @(posedge clk_i) begin
    gs_q     <= gs_d;
    gb_q     <= gb_d;
    g_last_row_q <= g_last_row_d;
    gtx_q    <= gtx_d;
    gty_q    <= gty_d;
    if (start_i) begin
      g_dsx_q <= g_dsx0;
      g_dsy_q <= g_dsy0;
    end else if (g_slice) begin
      g_dsx_q <= g_dsx_n;
      g_dsy_q <= g_dsy_n;
    end
  end

  assign rq_inc    = g_go && g_emit;
  assign rq_out_d  = rq_out_q + RsCntW'(rq_inc) - RsCntW'(rs_pop);
  // rq_out_d != RsDepth (the count never exceeds RsDepth).
  assign rq_room_d = !((rq_inc && !rs_pop && rq_out_q == RsCntW'(RsDepth - 1))
                       || (rq_inc == rs_pop && rq_out_q == RsCntW'(RsDepth)));

  cube5_axi_slice #(
    .Width (KeyW)
  ) u_rq (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (rq_inc),
    .in_ready_o  (rq_in_ready),
    .in_data_i   ({g_q, g_r}),
    .out_valid_o (rq_valid_o),
    .out_ready_i (rq_ready_i),
    .out_data_o  (rq_key_o)
  );

  logic unused_win;
  assign unused_win = ^{unused_d0, unused_d1, unused_d2, unused_d3, unused_pf, unused_ff,
                        unused_rf, rs_empty, g_sx, g_sy, wb_desc[0 +: 2*P]};

`ifndef SYNTHESIS
  WinAdmittedWhenOk: assert property (@(posedge clk_i) disable iff (!rst_ni)
      adm_i |-> adm_ok_o)
    else $error("cube5_frame_win: a beat admitted without the window's consent");
  WinTrigNonzero: assert property (@(posedge clk_i) disable iff (!rst_ni)
      $past(start_i) |-> trig_i != '0)
    else $error("cube5_frame_win: a zero trigger count (the flags' register needs one)");
  WinOneRestorePerBeat: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rd_i |-> $onehot0(rd_restore_o))
    else $error("cube5_frame_win: two restores in one beat");
  WinRestorePresent: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rs_pop |-> !rs_empty)
    else $error("cube5_frame_win: a restore taken before it arrived");
  WinDescriptorPresent: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rd_i |-> !unused_d0)
    else $error("cube5_frame_win: a sample beat without its descriptor");
  WinWalkerSteps: assert property (@(posedge clk_i) disable iff (!rst_ni)
      g_on_q |-> g_dsx_q == step_of(gtx_q, dx_i) && g_dsy_q == step_of(gty_q, dy_i))
    else $error("cube5_frame_win: the walker's registered slice steps disagree with its position");
  WinRequestRoomAsCount: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rq_room_q == (rq_out_q != RsCntW'(RsDepth)))
    else $error("cube5_frame_win: the request room flag disagrees with the requests' count");
  WinLastRowAsCount: assert property (@(posedge clk_i) disable iff (!rst_ni)
      g_on_q |-> g_last_row_q == (gb_q == nj_i - DimW'(1)))
    else $error("cube5_frame_win: the walker's last-row flag disagrees with its row");
  WinRequestsHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rq_valid_o && !rq_ready_i |=> rq_valid_o && $stable(rq_key_o))
    else $error("cube5_frame_win: a stalled restore request changed");
`endif

endmodule
