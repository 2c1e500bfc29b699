// cube5_frame_cbuf: the compositing buffer of the frame (patent [46], [165], [240];
// docs/frame-rtl.md): the coxels of the base plane in P banks by ray column r mod P, read and written
// back once per sample, and read out in row-major order after the sweep.
//
// The sample of lane l at anchor beat (s, b, m) belongs to base-plane pixel
// (R, Q) = (P*m + l + offx(s), b + offy(s)) with offx(s) = max_sx - sx(s), offy(s) = max_sy - sy(s).
// Its bank is (l + offx) mod P, so the P lanes of a beat meet P different banks, and the lane of bank
// j is (j - offx) mod P: the beat is rotated by offx mod P on its way in. Since sx changes by at most
// one per slice, the rotation moves by at most one lane per slice: the rotator is the barrel form of
// the nearest-neighbour links of [46], [165]. Bank j's word is {Q, R div P} =
// {Q, m + (offx div P) + (j < offx mod P)}: a fixed row stride of 2 MaxDim / P words.
//
// Per sample beat: cycle 1 reads the P coxels (a word whose valid bit is clear reads as the empty
// coxel) and registers the rotated samples; cycle 2 offers {coxel, sample, depth} to the update units
// (the compositing units, outside); their results are written back at the addresses kept in a FIFO.
// A coxel is read again only in the next slice, at least nbs - nbr - 1 beats later; the frame refuses
// volumes where that is not longer than the update loop (docs/frame-rtl.md). The read-out streams the
// W x H coxels (q outer, r inner; OutLanes = P: P pixels of a row per cycle, one word of every bank)
// and clears each word's valid bit behind it; after reset the buffer
// clears every valid bit once (clear_busy_o) before the first frame.
//
// GeoW > 0 (the frame's DepthTest = 1; docs/numerics/frame.md, "Opaque geometry"): beside each
// bank a geometry table of GeoW-bit words {Z, gR, gG, gB}, one per base-plane pixel at the coxel's
// own address, written through geo_we_i (a table like the frame's others: kept through reset and
// read-outs). It is read with every coxel (upd_geo_o) and every read-out word (out_geo_o): the
// coxel's Z and geometry colour, which the buffer itself never stores.
module cube5_frame_cbuf #(
  parameter int unsigned P      = 4,
  parameter int unsigned MaxDim = 64,
  /// Sample bits per lane (the shaded sample).
  parameter int unsigned PayW   = 44,
  /// Stored coxel bits (the fields the update changes).
  parameter int unsigned CoxW   = 85,
  parameter int unsigned DimW   = 7,
  parameter int unsigned TW     = 25,
  parameter int unsigned DW     = 18,
  /// Geometry table word width (Z and three colours), 0: no table.
  parameter int unsigned GeoW   = 0,
  /// Port width of the geometry words: GeoW, or 1 when there is no table.
  parameter int unsigned GeoPW  = 1,
  /// Pixels per read-out item: 1, or P (the P banks' words at one address, one row's P
  /// consecutive pixels R = P c .. P c + P - 1 per cycle; GeoW = 0 only).
  parameter int unsigned OutLanes = 1,
  /// 1: the compositing window (cube5_frame Window = 1; docs/numerics/compos_window.md): words
  /// {Q mod MaxDim, (R div P) mod WinCols}, the coxel of an entering pixel from win_*_i instead
  /// of the word, the results also out in lane order (wb_cox_o); no read-out.
  parameter int unsigned Window   = 0,
  /// Window = 1: words per bank row, a power of two >= the widest section / P.
  parameter int unsigned WinCols  = 2
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// The buffer is clearing its valid bits after reset (no frame may start).
  output logic clear_busy_o,
  /// The coxel of a word whose valid bit is clear (a ray no sample has reached yet in this frame).
  input  logic [CoxW-1:0] empty_cox_i,

  /// New frame: position counters to the first anchor.
  input  logic start_i,
  input  logic [DimW-1:0] nbr_i,
  input  logic [DimW-1:0] nj_i,
  /// The section's last anchor is the face's (a = ni - 1): only there does a sample past the
  /// x far face exist (1 for a whole-face sweep).
  input  logic            far_x_i,
  /// The sweep's first and last slice, T_x and T_y of the first (cube5_frame_pos).
  input  logic [DimW-1:0] s_first_i,
  input  logic [DimW-1:0] s_last_i,
  input  logic signed [TW-1:0] tx0_i,
  input  logic signed [TW-1:0] ty0_i,
  input  logic signed [DW-1:0] dx_i,
  input  logic signed [DW-1:0] dy_i,
  /// max over the frame of sx(s) and sy(s) (>= 0).
  input  logic [DimW-1:0] max_sx_i,
  input  logic [DimW-1:0] max_sy_i,

  /// Samples of one anchor beat, lane l at [l*PayW +: PayW].
  input  logic in_valid_i,
  input  logic [P*PayW-1:0] in_pay_i,

  /// To the update units, bank j at [j*... +: ...]: the coxel (empty_cox_i when its word was not
  /// written in this frame), the sample, the slice number s of the beat.
  output logic upd_valid_o,
  output logic [P*CoxW-1:0] upd_cox_o,
  output logic [P*PayW-1:0] upd_pay_o,
  output logic [DimW-1:0]   upd_depth_o,
  /// Bank j's sample lies past a far face (anchor a = ni - 1 with fx(s) != 0, or b = nj - 1 with
  /// fy(s) != 0: its interpolation reads the zeros there); MinIP leaves such samples out.
  output logic [P-1:0]      upd_past_o,
  /// Bank j's geometry word (GeoW > 0; else 0), beside upd_cox_o.
  output logic [P*GeoPW-1:0] upd_geo_o,
  /// Back from the update units, in the same order.
  input  logic upd_valid_i,
  input  logic [P*CoxW-1:0] upd_cox_i,

  /// Read-out: start it after the last write-back; W x H pixels.
  input  logic ro_start_i,
  input  logic [DimW:0] w_i,
  input  logic [DimW:0] h_i,
  output logic out_valid_o,
  input  logic out_ready_i,
  /// The pixel's coxel (empty_cox_i when no sample reached it); OutLanes = P: the coxels of
  /// pixels R .. R + P - 1 of one row, lane k at [k*CoxW +: CoxW] (lanes at R + k >= W read the
  /// empty coxel: no sample reaches them).
  output logic [OutLanes*CoxW-1:0] out_cox_o,
  /// The pixel's geometry word (GeoW > 0; else 0).
  output logic [GeoPW-1:0] out_geo_o,
  /// The read-out has issued its last read.
  output logic ro_busy_o,

  /// Geometry table write (GeoW > 0): base-plane pixel (R, Q) gets geo_data_i.
  input  logic geo_we_i,
  input  logic [DimW-1:0] geo_r_i,
  input  logic [DimW-1:0] geo_q_i,
  input  logic [GeoPW-1:0] geo_data_i,

  /// Window = 1, with in_valid_i: lane l's pixel enters the window (its coxel is empty_cox_i, or
  /// win_rs_cox_i where win_restore_i), lane order.
  input  logic [P-1:0] win_enter_i,
  input  logic [P-1:0] win_restore_i,
  input  logic [CoxW-1:0] win_rs_cox_i,
  /// With upd_valid_i: the results in lane order (lane l at [l*CoxW +: CoxW]).
  output logic [P*CoxW-1:0] wb_cox_o
);

  localparam int unsigned StepW = cube5_frame_pkg::StepW;
  localparam int unsigned LogP  = $clog2(P);
  localparam int unsigned LaneW = cube5_frame_pkg::lane_w(P);
  localparam int unsigned QW    = DimW;                // Q <= 2 MaxDim - 2
  localparam int unsigned ColW  = DimW - LogP;         // R div P < 2 MaxDim / P
  localparam int unsigned WinColW = $clog2(WinCols);
  localparam int unsigned AddrW = (Window != 0) ? (QW - 1 + WinColW) : (QW + ColW);
  localparam int unsigned Depth = 1 << AddrW;
  localparam int unsigned WordW = CoxW + 1;            // valid bit on top
  localparam int unsigned OutDepth = 4;

  if (GeoPW != ((GeoW > 0) ? GeoW : 1)) begin : gen_bad_geo
    $fatal(1, "cube5_frame_cbuf: GeoPW must be GeoW (1 without a geometry table)");
  end
  if (P < 1 || (1 << LogP) != P || P > MaxDim) begin : gen_bad_p
    $fatal(1, "cube5_frame_cbuf: P must be a power of two, at most MaxDim");
  end
  if (Window > 1 || (Window != 0 && (GeoW != 0 || WinCols < 2
      || (1 << WinColW) != WinCols))) begin : gen_bad_window
    $fatal(1, "cube5_frame_cbuf: Window = 1 needs no geometry table and WinCols a power of two >= 2");
  end
  if (OutLanes != 1 && (OutLanes != P || GeoW != 0)) begin : gen_bad_lanes
    $fatal(1, "cube5_frame_cbuf: OutLanes must be 1, or P without a geometry table");
  end

  // ---------------------------------------------------------------------------
  // Clear pass after reset
  // ---------------------------------------------------------------------------
  logic             clr_busy_q, clr_busy_d;
  logic [AddrW-1:0] clr_addr_q, clr_addr_d;

  always_comb begin
    clr_busy_d = clr_busy_q;
    clr_addr_d = clr_addr_q;
    if (clr_busy_q) begin
      clr_addr_d = clr_addr_q + AddrW'(1);
      if (clr_addr_q == AddrW'(Depth - 1)) clr_busy_d = 1'b0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      clr_busy_q <= 1'b1;
      clr_addr_q <= '0;
    end else begin
      clr_busy_q <= clr_busy_d;
      clr_addr_q <= clr_addr_d;
    end
  end

  assign clear_busy_o = clr_busy_q;

  // ---------------------------------------------------------------------------
  // Sweep: where the beat's samples go
  // ---------------------------------------------------------------------------
  logic [DimW-1:0] pos_m, pos_b, pos_s;
  logic signed [TW-1:0] tx, ty;
  logic unused_f0, pos_last_beat, unused_f2, pos_last_row, unused_f4, unused_f5;

  cube5_frame_pos #(
    .DimW (DimW),
    .TW   (TW),
    .DW   (DW)
  ) u_pos (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .start_i       (start_i),
    .step_i        (in_valid_i),
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
    .first_beat_o  (unused_f0),
    .last_beat_o   (pos_last_beat),
    .first_row_o   (unused_f2),
    .last_row_o    (pos_last_row),
    .first_slice_o (unused_f4),
    .last_slice_o  (unused_f5)
  );

  // offx = max_sx - floor(T_x / 2^StepW), offy likewise: 0 ..= W - ni, H - nj.
  logic signed [TW-1:0] offx_s, offy_s;
  logic [DimW-1:0]      offx, offy, q_row;
  assign offx_s = TW'($signed({1'b0, max_sx_i})) - (tx >>> StepW);
  assign offy_s = TW'($signed({1'b0, max_sy_i})) - (ty >>> StepW);
  assign offx   = DimW'(offx_s);
  assign offy   = DimW'(offy_s);
  assign q_row  = pos_b + offy;

  logic [LaneW-1:0] rot;        // offx mod P
  logic [DimW-1:0]  col_base;   // m + offx div P
  if (P > 1) begin : gen_rot
    assign rot = offx[LogP-1:0];
  end else begin : gen_no_rot
    assign rot = '0;
  end
  assign col_base = pos_m + (offx >> LogP);

  logic [P*AddrW-1:0] sw_addr;  // bank j's word for this beat
  logic [P*PayW-1:0]  pay_rot;  // bank j's sample
  logic [P-1:0]       past, past_rot;  // lane l's, bank j's sample past a far face
  logic               unused_col;

  always_comb begin
    for (int unsigned l = 0; l < P; l++) begin
      past[l] = ((ty[StepW-1:0] != '0) && pos_last_row)
                || ((tx[StepW-1:0] != '0) && far_x_i && pos_last_beat
                    && (l == P - 1));
    end
  end

  if (P > 1) begin : gen_rotate
    // Bank j serves lane (j - rot) mod P; below rot it holds the next word of the row.
    always_comb begin
      unused_col = 1'b0;
      for (int unsigned j = 0; j < P; j++) begin
        logic [DimW-1:0]  col;
        logic [LaneW-1:0] lane;
        col  = col_base + ((LaneW'(j) < rot) ? DimW'(1) : DimW'(0));
        lane = LaneW'(j) - rot;
        // The word {Q, R div P}, or in the window {Q mod MaxDim, (R div P) mod WinCols}.
        sw_addr[j*AddrW +: AddrW] = (Window != 0) ? AddrW'({q_row[QW-2:0], col[WinColW-1:0]})
                                                  : AddrW'({q_row[QW-1:0], col[ColW-1:0]});
        // A P-way mux by lane (an indexed part-select `lane*PayW` becomes a multiplier in Yosys).
        pay_rot[j*PayW +: PayW]   = in_pay_i[0 +: PayW];
        for (int unsigned l = 1; l < P; l++) begin
          if (lane == LaneW'(l)) pay_rot[j*PayW +: PayW] = in_pay_i[l*PayW +: PayW];
        end
        past_rot[j]               = past[lane];
        unused_col ^= ^col;
      end
    end
  end else begin : gen_single
    assign sw_addr    = (Window != 0) ? AddrW'({q_row[QW-2:0], col_base[WinColW-1:0]})
                                      : AddrW'({q_row[QW-1:0], col_base[ColW-1:0]});
    assign pay_rot    = in_pay_i;
    assign past_rot   = past;
    assign unused_col = ^{rot, col_base, q_row};
  end

  // Write-back addresses wait for the update units' results.
  logic [P*AddrW-1:0] wb_addr;
  logic [LaneW-1:0]   wb_rot;     // Window = 1: the beat's rotation, for the results in lane order
  logic               unused_wb_empty, unused_wb_full;

  if (Window != 0) begin : gen_wb_rot
    cube5_frame_fifo #(
      .Width (P * AddrW + LaneW),
      .Depth (8)
    ) u_wb_addr (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (start_i),
      .push_i  (in_valid_i),
      .d_i     ({rot, sw_addr}),
      .pop_i   (upd_valid_i),
      .q_o     ({wb_rot, wb_addr}),
      .empty_o (unused_wb_empty),
      .full_o  (unused_wb_full)
    );
  end else begin : gen_wb
    cube5_frame_fifo #(
      .Width (P * AddrW),
      .Depth (8)
    ) u_wb_addr (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (start_i),
      .push_i  (in_valid_i),
      .d_i     (sw_addr),
      .pop_i   (upd_valid_i),
      .q_o     (wb_addr),
      .empty_o (unused_wb_empty),
      .full_o  (unused_wb_full)
    );
    assign wb_rot = '0;
  end

  // ---------------------------------------------------------------------------
  // Read-out: q outer, r inner; one read per cycle while the output FIFO has room (OutLanes = P:
  // r steps by P, every bank reads the word {q, r div P})
  // ---------------------------------------------------------------------------
  logic             ro_busy_q, ro_busy_d;
  logic [DimW:0]    ro_r_q, ro_r_d, ro_q_q, ro_q_d;
  logic [2:0]       ro_cred_q, ro_cred_d;      // reads issued and not yet taken
  logic             ro_issue, out_pop;
  logic [AddrW-1:0] ro_addr;
  logic [LaneW-1:0] ro_bank, ro_bank_q;
  logic             ro_rd_q;                   // a read-out word arrives this cycle

  assign ro_issue = ro_busy_q && (ro_cred_q < 3'(OutDepth));
  assign ro_addr  = AddrW'({ro_q_q[QW-1:0], ColW'(ro_r_q >> LogP)});
  if (P > 1) begin : gen_ro_bank
    assign ro_bank = ro_r_q[LogP-1:0];
  end else begin : gen_ro_bank1
    assign ro_bank = '0;
  end

  always_comb begin
    ro_busy_d = ro_busy_q;
    ro_r_d    = ro_r_q;
    ro_q_d    = ro_q_q;
    ro_cred_d = ro_cred_q + (ro_issue ? 3'd1 : 3'd0) - (out_pop ? 3'd1 : 3'd0);
    if (ro_start_i) begin
      ro_busy_d = 1'b1;
      ro_r_d    = '0;
      ro_q_d    = '0;
    end else if (ro_issue) begin
      if (ro_r_q + (DimW+1)'(OutLanes) < w_i) begin
        ro_r_d = ro_r_q + (DimW+1)'(OutLanes);
      end else begin
        ro_r_d = '0;
        ro_q_d = ro_q_q + (DimW+1)'(1);
        if (ro_q_q + (DimW+1)'(1) >= h_i) ro_busy_d = 1'b0;
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      ro_busy_q <= 1'b0;
      ro_cred_q <= '0;
      ro_rd_q   <= 1'b0;
      ro_r_q    <= '0;
      ro_q_q    <= '0;
    end else begin
      ro_busy_q <= ro_busy_d;
      ro_cred_q <= ro_cred_d;
      ro_rd_q   <= ro_issue;
      ro_r_q    <= ro_r_d;
      ro_q_q    <= ro_q_d;
    end
  end

  always_ff @(posedge clk_i) begin
    if (ro_issue) ro_bank_q <= ro_bank;
  end

  assign ro_busy_o = ro_busy_q;

  // ---------------------------------------------------------------------------
  // The banks: one read and one write port each
  // ---------------------------------------------------------------------------
  logic [P*WordW-1:0] rd_word;
  logic [P*GeoPW-1:0] geo_word;
  logic               sw_rd_q;
  logic [P*PayW-1:0]  pay_q;
  logic [DimW-1:0]    depth_q;
  logic [P-1:0]       past_q;

  for (genvar j = 0; j < P; j++) begin : gen_bank
    logic [WordW-1:0] mem_q [Depth];
    logic [WordW-1:0] rd_q;
    logic             we, re;
    logic [AddrW-1:0] wa, ra;
    logic [WordW-1:0] wd;

    always_comb begin
      we = 1'b0;
      wa = clr_addr_q;
      wd = '0;
      if (clr_busy_q) begin
        we = 1'b1;
      end else if (ro_issue) begin
        we = (OutLanes > 1) || (ro_bank == LaneW'(j));
        wa = ro_addr;
      end else if (upd_valid_i) begin
        we = 1'b1;
        wa = wb_addr[j*AddrW +: AddrW];
        wd = {1'b1, upd_cox_i[j*CoxW +: CoxW]};
      end
      re = in_valid_i || ro_issue;
      ra = ro_issue ? ro_addr : sw_addr[j*AddrW +: AddrW];
    end

    always_ff @(posedge clk_i) begin
      if (we) mem_q[wa] <= wd;
    end

    always_ff @(posedge clk_i) begin
      if (re) rd_q <= mem_q[ra];
    end

    assign rd_word[j*WordW +: WordW] = rd_q;

    if (GeoW > 0) begin : gen_geo
      // The geometry table of this bank: written by the host, read beside the coxel.
      logic [GeoW-1:0] geo_q [Depth];
      logic [GeoW-1:0] geo_rd_q;
      logic            geo_we;
      logic [AddrW-1:0] geo_wa;
      logic [DimW-1:0]  geo_col;
      logic             unused_geo_col;
      assign geo_col = geo_r_i >> LogP;
      assign geo_wa  = {geo_q_i[QW-1:0], geo_col[ColW-1:0]};
      assign unused_geo_col = ^geo_col;
      if (P > 1) begin : gen_geo_bank
        assign geo_we = geo_we_i && (geo_r_i[LogP-1:0] == LogP'(j));
      end else begin : gen_geo_bank1
        assign geo_we = geo_we_i;
      end
      always_ff @(posedge clk_i) begin
        if (geo_we) geo_q[geo_wa] <= geo_data_i;
      end
      always_ff @(posedge clk_i) begin
        if (re) geo_rd_q <= geo_q[ra];
      end
      assign geo_word[j*GeoPW +: GeoPW] = geo_rd_q;
    end else begin : gen_no_geo
      assign geo_word[j*GeoPW +: GeoPW] = '0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      sw_rd_q <= 1'b0;
    end else begin
      sw_rd_q <= in_valid_i;
    end
  end

  // Window = 1: bank j's pixel enters (lane (j - rot) mod P's flags), its restored coxel.
  logic [P-1:0]    ent_rot, rst_rot, ent_q, rst_q;
  logic [CoxW-1:0] rs_cox_q;
  always_comb begin
    for (int unsigned j = 0; j < P; j++) begin
      logic [LaneW-1:0] lane;
      lane       = LaneW'(j) - rot;
      ent_rot[j] = (Window != 0) && win_enter_i[lane];
      rst_rot[j] = (Window != 0) && win_restore_i[lane];
    end
  end

  always_ff @(posedge clk_i) begin
    if (in_valid_i) begin
      pay_q    <= pay_rot;
      depth_q  <= pos_s;
      past_q   <= past_rot;
      ent_q    <= ent_rot;
      rst_q    <= rst_rot;
      rs_cox_q <= win_rs_cox_i;
    end
  end

  // A word whose valid bit is clear is the empty coxel (the frame's, by render mode); in the
  // window an entering pixel's coxel is the empty or the restored one, whatever the word holds.
  always_comb begin
    for (int unsigned j = 0; j < P; j++) begin
      if (ent_q[j]) begin
        upd_cox_o[j*CoxW +: CoxW] = rst_q[j] ? rs_cox_q : empty_cox_i;
      end else begin
        upd_cox_o[j*CoxW +: CoxW] = rd_word[j*WordW + CoxW] ? rd_word[j*WordW +: CoxW]
                                                            : empty_cox_i;
      end
    end
  end

  // The results in lane order: lane l's pixel is in bank (l + rot) mod P.
  always_comb begin
    for (int unsigned l = 0; l < P; l++) begin
      logic [LaneW-1:0] bank;
      bank = LaneW'(l) + wb_rot;
      wb_cox_o[l*CoxW +: CoxW] = upd_cox_i[bank*CoxW +: CoxW];
    end
  end
  assign upd_geo_o   = geo_word;
  assign upd_valid_o = sw_rd_q;
  assign upd_pay_o   = pay_q;
  assign upd_depth_o = depth_q;
  assign upd_past_o  = past_q;

  // ---------------------------------------------------------------------------
  // Output FIFO of the read-out
  // ---------------------------------------------------------------------------
  logic [OutLanes*CoxW-1:0] ro_cox;
  logic                     out_empty, unused_out_full;

  if (OutLanes == 1) begin : gen_ro_one
    logic [WordW-1:0] ro_word;
    always_comb begin
      ro_word = rd_word[0 +: WordW];
      for (int unsigned k = 1; k < P; k++) begin
        if (ro_bank_q == LaneW'(k)) ro_word = rd_word[k*WordW +: WordW];
      end
    end
    assign ro_cox  = ro_word[CoxW] ? ro_word[CoxW-1:0] : empty_cox_i;
  end else begin : gen_ro_lanes
    // Bank k holds pixel R + k (R a multiple of P).
    logic unused_ro_bank;
    assign unused_ro_bank = ^ro_bank_q;
    always_comb begin
      for (int unsigned k = 0; k < OutLanes; k++) begin
        ro_cox[k*CoxW +: CoxW] = rd_word[k*WordW + CoxW] ? rd_word[k*WordW +: CoxW] : empty_cox_i;
      end
    end
  end

  if (GeoW > 0) begin : gen_out_geo
    // The read-out word's geometry travels with its coxel.
    logic [GeoW-1:0] ro_geo;
    always_comb begin
      ro_geo = GeoW'(geo_word[0 +: GeoPW]);
      for (int unsigned k = 1; k < P; k++) begin
        if (ro_bank_q == LaneW'(k)) ro_geo = GeoW'(geo_word[k*GeoPW +: GeoPW]);
      end
    end
    cube5_frame_fifo #(
      .Width (CoxW + GeoW),
      .Depth (OutDepth)
    ) u_out (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (ro_start_i),
      .push_i  (ro_rd_q),
      .d_i     ({ro_geo, ro_cox}),
      .pop_i   (out_pop),
      .q_o     ({out_geo_o, out_cox_o}),
      .empty_o (out_empty),
      .full_o  (unused_out_full)
    );
  end else begin : gen_out
    cube5_frame_fifo #(
      .Width (OutLanes * CoxW),
      .Depth (OutDepth)
    ) u_out (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (ro_start_i),
      .push_i  (ro_rd_q),
      .d_i     (ro_cox),
      .pop_i   (out_pop),
      .q_o     (out_cox_o),
      .empty_o (out_empty),
      .full_o  (unused_out_full)
    );
    logic unused_geo_in;
    assign unused_geo_in = ^{geo_we_i, geo_r_i, geo_q_i, geo_data_i};
    assign out_geo_o = '0;
  end

  assign out_valid_o = !out_empty;
  assign out_pop     = out_valid_o && out_ready_i;

  logic unused_cbuf;
  assign unused_cbuf = ^{unused_f0, unused_f2, unused_f4, unused_f5,
                         unused_wb_empty, unused_wb_full, unused_out_full, offx_s, offy_s, tx, ty,
                         unused_col};

`ifndef SYNTHESIS
  CbufOnePhase: assert property (@(posedge clk_i) disable iff (!rst_ni)
      $onehot0({clr_busy_q, ro_busy_q, in_valid_i || upd_valid_i}))
    else $error("cube5_frame_cbuf: clear, sweep and read-out overlap");
  CbufWriteBackExpected: assert property (@(posedge clk_i) disable iff (!rst_ni)
      upd_valid_i |-> !unused_wb_empty)
    else $error("cube5_frame_cbuf: a write-back without its address");
`endif

endmodule
