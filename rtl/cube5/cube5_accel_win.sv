// cube5_accel_win: the compositing window's memory traffic in the accelerator top (cube5_accel
// Window = 1; docs/accel.md, *The compositing window in the top*). It turns cube5_frame's window
// streams into AXI4 transactions on the top's port, with IDs of its own:
//
//   park_* (key {Q, R}, stored coxel) ─► one write burst of Cx bytes (ID IdPark) at
//                                        ParkBase + (Q Wp + R) Cx
//   fin_*  (key of lane 0, mask, P coxels) ─► codes, then single-beat writes (ID IdFin) of the
//                                        beats the P pixels at ImgBase + Q pitch + 4 R touch,
//                                        WSTRB from the mask (R need not be a multiple of P)
//   rq_*   (key) ─► a read burst of Cx bytes (ID IdRs) at the park address; its beats come back
//   rs_*   ◄──────  as the restored coxel, in request order
//
// Cx = max(StoreW bits rounded up to a power-of-two byte count, DataW / 8): a coxel slot is whole
// bus beats at a slot-aligned address (no burst crosses 4 KB). Ordering: a final pixel of row Q
// waits until row Q's clear (the top's row writes of the initial coxel's code) has completed
// (rows_done_i > Q); a restore read waits until every park taken before its request has its B
// response (the frame requests a section's restores only after the earlier sections' parks left
// its park FIFO, so those are the parks the restore may read). Parks go before finals. At most
// Outstanding write bursts and Outstanding restore reads are in flight.
//
// Zero parks (ZeroSkip = 1; docs/accel.md, *Fewer window bytes*): the frame restores coxels in
// exactly the order it parked them (docs/numerics/compos_window.md), so one on-chip bit per park,
// in a FIFO of ZeroDepth bits (block RAM), says whether the parked coxel is all zero bits. Such a
// park writes nothing and its restore reads nothing (its coxel, zeros, is handed over in request
// order behind the reads before it). A park that finds the bit FIFO full is written as before and
// recorded in no FIFO (a count); while such parks are outstanding every park is written, so the
// recorded parks are always older than the unrecorded ones: a restore request is the bit FIFO's
// head when that FIFO is not empty, else an unrecorded park's (a read). frame_start_i empties the
// bit FIFO (a frame that ended without restoring its parks leaves nothing behind).
//
// The ring (Ring = 1; docs/numerics/compos_window.md, *The ring in park order*): the written
// parks, in park order, are one packed bit stream (StoreW bits each, no slot padding) in a ring
// of RB = Wp nj PkBeats beats at ParkBase (the first Wp nj slots' bytes of the slot layout's
// area). Its beats go out as INCR bursts of up to RingBurst beats, cut at address multiples of
// RingBurst beats and at the ring's end, each once its beats are complete; the restores read the
// written beats (B received) in order, in bursts, ahead of the requests, into an on-chip buffer
// and unpack them. A flush (the frame waits for a restore whose bits are still on chip and
// nothing else is on its way) writes the beats held, the last padded with zeros; the pad's place
// (the count of coxels before it) goes to the reader through a small FIFO. A beat is read only
// after its write's B and rewritten only after its read's data is back.
//
// Finals in bursts (FinBurst > 0; docs/numerics/compos_window.md, *Final pixels in bursts*): the
// final items' beats (as above: the bus beats their pixels touch, with strobes) join a *run*
// while each is the run's last beat (strobes merged) or the beat after it, inside one aligned
// block of FinBurst beats; any other beat, or FinWait cycles with no final beat, closes the run:
// its beats (a FIFO) go out as one INCR burst (ID IdFin). Each image byte is written once, as
// before; only the bursts change.
module cube5_accel_win #(
  parameter int unsigned P           = 4,
  /// Bits of a key coordinate (log2(MaxDim) + 1).
  parameter int unsigned DimW        = 7,
  parameter int unsigned AddrW       = 32,
  parameter int unsigned DataW       = 64,
  parameter int unsigned IdW         = 4,
  /// The frame's stored coxel: {terminated, A, B, G, R}, AccW + 1 bits per channel.
  parameter int unsigned AccW        = 20,
  parameter int unsigned ColorW      = 8,
  /// Write bursts in flight, and restore reads in flight.
  parameter int unsigned Outstanding = 16,
  /// 1: all-zero parks cost no bytes (a bit per park on chip); 0: every park is written.
  parameter int unsigned ZeroSkip    = 1,
  /// Bits of the zero-park FIFO (a power of two; 0: MaxDim^2, a section's parks at 45 degrees).
  parameter int unsigned ZeroDepth   = 0,
  /// Depth of the AW and W FIFOs (a power of two).
  parameter int unsigned WDepth      = 8,
  /// 1: the parks are a packed ring in park order, written and read in bursts; 0: a slot per
  /// pixel, one burst per park and per restore.
  parameter int unsigned Ring        = 0,
  /// Ring = 1: the longest burst in beats (a power of two, at most 256 and 4 KB).
  parameter int unsigned RingBurst   = 16,
  /// 0: each final beat is a single-beat burst; else the final items' beats that follow each
  /// other in the image go out as INCR bursts of up to FinBurst beats (a power of two, at most
  /// 256 and 4 KB; docs/numerics/compos_window.md, *Final pixels in bursts*).
  parameter int unsigned FinBurst    = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// The frame's set-up (held while it runs): ImgBase, bytes per image row, ParkBase, pixels
  /// per row as written (Wp), and the rows of the image already cleared.
  input  logic [AddrW-1:0] img_base_i,
  input  logic [AddrW-1:0] row_step_i,
  input  logic [AddrW-1:0] park_base_i,
  input  logic [DimW:0]    row_pixels_i,
  input  logic [DimW:0]    rows_done_i,
  /// A frame starts (its first section command): the zero-park FIFO empties.
  input  logic frame_start_i,
  /// Ring = 1: the frame's rows of anchors (nj), sampled with frame_start_i: the ring is Wp nj
  /// coxel slots' bytes.
  input  logic [DimW-1:0]  park_rows_i,

  // ---- the frame's window streams ----
  input  logic park_valid_i,
  output logic park_ready_o,
  input  logic [2*DimW-1:0] park_key_i,
  input  logic [4*(AccW+1):0] park_cox_i,
  input  logic fin_valid_i,
  output logic fin_ready_o,
  input  logic [2*DimW-1:0] fin_key_i,
  input  logic [P-1:0] fin_mask_i,
  input  logic [P*(4*(AccW+1)+1)-1:0] fin_cox_i,
  input  logic rq_valid_i,
  output logic rq_ready_o,
  input  logic [2*DimW-1:0] rq_key_i,
  output logic rs_valid_o,
  input  logic rs_ready_i,
  output logic [4*(AccW+1):0] rs_cox_o,

  // ---- AXI4: AW, W, B (B of IDs IdPark and IdFin only), AR, R (R of ID IdRs only) ----
  output logic [AddrW-1:0]   awaddr_o,
  output logic [7:0]         awlen_o,
  output logic [IdW-1:0]     awid_o,
  output logic               awvalid_o,
  input  logic               awready_i,
  output logic [DataW-1:0]   wdata_o,
  output logic [DataW/8-1:0] wstrb_o,
  output logic               wlast_o,
  output logic               wvalid_o,
  input  logic               wready_i,
  input  logic               bvalid_i,
  input  logic [IdW-1:0]     bid_i,
  input  logic [1:0]         bresp_i,
  output logic [AddrW-1:0]   araddr_o,
  output logic [7:0]         arlen_o,
  output logic               arvalid_o,
  input  logic               arready_i,
  input  logic               rvalid_i,
  input  logic [DataW-1:0]   rdata_i,
  input  logic [1:0]         rresp_i,
  input  logic               rlast_i,
  output logic               rready_o,

  /// Write beats are queued and not yet on the port: the top starts no new volume read meanwhile
  /// (the memory serves reads first; docs/accel.md, *The compositing window in the top*).
  output logic wr_wait_o,
  /// Nothing taken and not yet written, no burst in flight: the window's traffic has drained.
  output logic idle_o,
  /// Sticky: a B or R response of this unit was not OKAY.
  output logic err_o
);

  localparam int unsigned ChanW    = AccW + 1;
  localparam int unsigned StoreW   = 4 * ChanW + 1;
  localparam int unsigned KeyW     = 2 * DimW;
  localparam int unsigned Bbus     = DataW / 8;
  localparam int unsigned LogBus   = $clog2(Bbus);
  localparam int unsigned StoreLog = $clog2((StoreW + 7) / 8);
  localparam int unsigned CxLog    = (StoreLog > LogBus) ? StoreLog : LogBus;
  localparam int unsigned PkBeats  = (1 << CxLog) / Bbus;       // beats of a coxel slot
  localparam int unsigned PixW     = 32;
  localparam int unsigned FinBytes = 4 * P;
  localparam int unsigned FinBeats = (Bbus - 4 + FinBytes + Bbus - 1) / Bbus;
  localparam int unsigned LineBeats = (FinBeats > PkBeats) ? FinBeats : PkBeats;
  localparam int unsigned LineW    = LineBeats * DataW;
  localparam int unsigned TW       = $clog2(LineBeats + 1);
  localparam int unsigned OutW     = $clog2(Outstanding + 1);
  localparam int unsigned TagW     = 16;
  localparam int unsigned AwW      = IdW + 8 + AddrW;
  localparam int unsigned WW       = 1 + Bbus + DataW;
  localparam logic [IdW-1:0] IdPark = IdW'(1);
  localparam logic [IdW-1:0] IdFin  = IdW'(2);

  if (IdW < 2) begin : gen_bad_id
    $fatal(1, "cube5_accel_win: IdW must be at least 2 (IDs 1 and 2 are the window's)");
  end
  if (DataW < 32 || ColorW > 8) begin : gen_bad_width
    $fatal(1, "cube5_accel_win: DataW must be at least 32 and ColorW at most 8");
  end

  // The park slot of a key: ParkBase (slot-aligned) + (Q Wp + R) Cx.
  function automatic logic [AddrW-1:0] slot_of(logic [KeyW-1:0] key);
    logic [AddrW-1:0] idx;
    idx = AddrW'(key[DimW +: DimW]) * AddrW'(row_pixels_i) + AddrW'(key[0 +: DimW]);
    slot_of = (park_base_i & ~AddrW'((1 << CxLog) - 1)) + (idx << CxLog);
  endfunction

  // ---------------------------------------------------------------------------
  // Stage 1: the next item (a park before a final; a final once its row is cleared).
  // ---------------------------------------------------------------------------
  logic               s1_v_q, s1_park_q, s1_new_q;
  logic               s1_zero_q;  // the park's stored coxel is all zero (found as it is taken)
  logic [AddrW-1:0]   s1_rowoff_q; // a final's row times the row step (multiplied as it is taken)
  logic [KeyW-1:0]    s1_key_q;
  logic [P-1:0]       s1_mask_q;
  logic [P*StoreW-1:0] s1_cox_q;
  logic               s1_ready, take_park, take_fin, s2_take;
  logic               rg_take;    // Ring = 1: a written park leaves stage 1 into the packer
  // A park is decided in its first cycle in stage 1: recorded in the zero FIFO or not, dropped
  // (all zero, recorded: nothing written) or kept for stage 2 (a write).
  logic               p_decide, p_rec, p_drop, p_write;

  assign s1_ready     = !s1_v_q || s2_take || rg_take || p_drop;
  assign take_park    = park_valid_i && s1_ready;
  assign take_fin     = fin_valid_i && !park_valid_i && s1_ready
                        && (DimW + 1)'(fin_key_i[DimW +: DimW]) < rows_done_i;
  assign park_ready_o = take_park;
  assign fin_ready_o  = take_fin;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      s1_v_q   <= 1'b0;
      s1_new_q <= 1'b0;
    end else begin
      if (s1_ready) s1_v_q <= take_park || take_fin;
      s1_new_q <= s1_ready ? take_park : 1'b0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (take_park) begin
      s1_park_q <= 1'b1;
      s1_key_q  <= park_key_i;
      s1_mask_q <= P'(1);
      s1_cox_q  <= (P*StoreW)'(park_cox_i);
      s1_zero_q <= park_cox_i[StoreW-1:0] == '0;
    end else if (take_fin) begin
      s1_park_q <= 1'b0;
      s1_key_q  <= fin_key_i;
      s1_mask_q <= fin_mask_i;
      s1_cox_q  <= fin_cox_i;
      s1_rowoff_q <= AddrW'(fin_key_i[DimW +: DimW]) * row_step_i;
    end
  end

  assign p_decide = s1_v_q && s1_new_q;   // s1_new_q: a park, loaded last cycle
  assign p_drop   = p_decide && p_rec && s1_zero_q;
  assign p_write  = p_decide && !p_drop;

  // ---------------------------------------------------------------------------
  // Stage 2: the burst's address and its beats (data and strobes, LineBeats bus beats).
  // ---------------------------------------------------------------------------
  logic               s2_v_q, s2_park_q, s3_done;
  logic [AddrW-1:0]   s2_addr_q, s2_addr;
  logic [LineW-1:0]   s2_line_q, s2_line;
  logic [LineW/8-1:0] s2_strb_q, s2_strb;
  logic [P*PixW-1:0]  pix;
  logic [FinBytes-1:0] pix_strb;
  logic [AddrW-1:0]   fin_addr;

  // Each lane's pixel codes (cube5_accel_pix, as the read-out's in cube5_accel).
  for (genvar k = 0; k < P; k++) begin : gen_pix
    cube5_accel_pix #(.AccW(AccW), .ColorW(ColorW)) u_pix (
      .cox_i(s1_cox_q[k*StoreW +: 4*ChanW]), .pix_o(pix[k*PixW +: PixW])
    );
    assign pix_strb[4*k +: 4] = {4{s1_mask_q[k]}};
  end

  assign fin_addr = img_base_i + s1_rowoff_q + (AddrW'(s1_key_q[0 +: DimW]) << 2);

  always_comb begin
    if (s1_park_q) begin
      s2_addr = slot_of(s1_key_q);
      s2_line = LineW'(s1_cox_q[StoreW-1:0]);
      s2_strb = (LineW/8)'({PkBeats*Bbus{1'b1}});
    end else begin
      s2_addr = fin_addr & ~AddrW'(Bbus - 1);
      s2_line = LineW'(pix) << (8 * fin_addr[LogBus-1:0]);
      s2_strb = (LineW/8)'(pix_strb) << fin_addr[LogBus-1:0];
    end
  end

  // Stage 2's register hands its item to a two-entry register slice (cube5_axi_slice), from
  // which stage 3 takes it: stage 2 moves on when the slice has room, a register, so stage 1's
  // and 2's readies never wait on stage 3's beat and the W FIFO's room (docs/accel.md,
  // *Synthesis*). Items keep their order.
  logic               s2_move, s3_in_ready, s3_v_q, s3_park_q;
  logic [AddrW-1:0]   s3_addr_q;
  logic [LineW-1:0]   s3_line_q;
  logic [LineW/8-1:0] s3_strb_q;
  assign s2_move = s2_v_q && s3_in_ready;
  assign s2_take = s1_v_q && !p_drop && (!s2_v_q || s3_in_ready) && !(Ring != 0 && s1_park_q);

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      s2_v_q <= 1'b0;
    end else if (s2_take) begin
      s2_v_q <= 1'b1;
    end else if (s2_move) begin
      s2_v_q <= 1'b0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (s2_take) begin
      s2_park_q <= s1_park_q;
      s2_addr_q <= s2_addr;
      s2_line_q <= s2_line;
      s2_strb_q <= s2_strb;
    end
  end

  cube5_axi_slice #(.Width(1 + AddrW + LineW + LineW / 8)) u_s3 (
    .clk_i, .rst_ni,
    .in_valid_i(s2_v_q), .in_ready_o(s3_in_ready),
    .in_data_i({s2_park_q, s2_addr_q, s2_line_q, s2_strb_q}),
    .out_valid_o(s3_v_q), .out_ready_i(s3_done),
    .out_data_o({s3_park_q, s3_addr_q, s3_line_q, s3_strb_q})
  );

  // ---------------------------------------------------------------------------
  // Stage 3: one beat per cycle into the W FIFO, and a burst's address into the AW FIFO (a park:
  // one burst of PkBeats beats; a final: one single-beat burst per beat with a strobe set).
  // ---------------------------------------------------------------------------
  logic [TW-1:0]      t_q;
  logic [DataW-1:0]   beat;
  logic [Bbus-1:0]    beat_strb;
  logic               t_last, need_aw, push_w, push_aw, can, step;
  logic               aw_full, aw_empty, w_full, w_empty, aw_pop, w_pop;
  logic [OutW-1:0]    out_q;      // write bursts in the AW FIFO or in flight, B not yet in
  logic               b_fire;
  logic               rg_use;     // Ring = 1: the ring holds the FIFOs (a burst decided, or its beats)
  logic               rg_aw;      // Ring = 1: a ring burst starts (its AW pushed)
  logic               rg_w;       // Ring = 1: a ring burst's beat into the W FIFO
  logic [AwW-1:0]     rg_aw_d;
  logic [WW-1:0]      rg_w_d;
  logic               fc_in;      // FinBurst > 0: a final's beat (a strobe set) into its run
  logic               fc_ok;      // FinBurst > 0: the run's FIFOs take a beat and a burst
  logic               fm_use;     // FinBurst > 0: a finals burst's AW or beats go into the FIFOs
  logic               fm_busy;    // FinBurst > 0: a finals burst's beats are moving
  logic               fm_aw;      // FinBurst > 0: a finals burst starts (its AW pushed)
  logic               fm_w;       // FinBurst > 0: a finals burst's beat into the W FIFO
  logic [AwW-1:0]     fm_aw_d;
  logic [WW-1:0]      fm_w_d;
  logic               fm_idle;    // FinBurst > 0: no run open, nothing queued

  always_comb begin
    beat      = s3_line_q[0 +: DataW];
    beat_strb = s3_strb_q[0 +: Bbus];
    for (int unsigned n = 1; n < LineBeats; n++) begin
      if (t_q == TW'(n)) begin
        beat      = s3_line_q[n*DataW +: DataW];
        beat_strb = s3_strb_q[n*Bbus +: Bbus];
      end
    end
  end

  assign t_last  = s3_park_q ? (t_q == TW'(PkBeats - 1)) : (t_q == TW'(FinBeats - 1));
  assign need_aw = s3_park_q ? (t_q == '0) : (FinBurst == 0 && |beat_strb);
  assign push_w  = s3_park_q || (FinBurst == 0 && |beat_strb);
  assign fc_in   = !s3_park_q && FinBurst != 0 && |beat_strb;
  assign can     = (!need_aw || (!aw_full && out_q < OutW'(Outstanding))) && (!push_w || !w_full)
                   && (!fc_in || fc_ok);
  // A beat into the AW/W FIFOs waits while a ring or finals burst moves into them.
  assign step    = s3_v_q && can && ((FinBurst == 0) ? !rg_use
                                      : (!(need_aw || push_w) || (!rg_use && !fm_use)));
  assign push_aw = step && need_aw;
  assign s3_done = step && t_last;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      t_q <= '0;
    end else if (step) begin
      t_q <= t_last ? '0 : t_q + TW'(1);
    end
  end

  logic [AwW-1:0] aw_d, aw_q;
  logic [WW-1:0]  w_d, w_q;
  assign aw_d = s3_park_q ? {IdPark, 8'(PkBeats - 1), s3_addr_q}
                          : {IdFin, 8'd0, s3_addr_q + (AddrW'(t_q) << LogBus)};
  assign w_d  = {s3_park_q ? t_last : 1'b1, s3_park_q ? {Bbus{1'b1}} : beat_strb, beat};

  cube5_frame_fifo #(.Width(AwW), .Depth(WDepth)) u_aw (
    .clk_i, .rst_ni, .clear_i(1'b0),
    .push_i(push_aw || rg_aw || fm_aw), .d_i(rg_aw ? rg_aw_d : fm_use ? fm_aw_d : aw_d),
    .pop_i(aw_pop), .q_o(aw_q), .empty_o(aw_empty), .full_o(aw_full)
  );
  cube5_frame_fifo #(.Width(WW), .Depth(WDepth)) u_w (
    .clk_i, .rst_ni, .clear_i(1'b0),
    .push_i((step && push_w) || rg_w || fm_w), .d_i(rg_w ? rg_w_d : fm_use ? fm_w_d : w_d),
    .pop_i(w_pop), .q_o(w_q), .empty_o(w_empty), .full_o(w_full)
  );

  assign {awid_o, awlen_o, awaddr_o} = aw_q;
  assign awvalid_o = !aw_empty;
  assign aw_pop    = awvalid_o && awready_i;
  assign {wlast_o, wstrb_o, wdata_o} = w_q;
  assign wvalid_o  = !w_empty;
  assign w_pop     = wvalid_o && wready_i;
  assign b_fire    = bvalid_i;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      out_q <= '0;
    end else begin
      out_q <= out_q + OutW'(push_aw || rg_aw || fm_aw) - OutW'(b_fire);
    end
  end

  // ---------------------------------------------------------------------------
  // Restores: each request's slot, tagged with the parks taken so far, waits in a FIFO (so that
  // the requests wait for their parks together, not one after another). The FIFO's head moves
  // into a head register, whose tag check (every park taken before it has its B response) is a
  // registered flag computed as the head is loaded; a head whose flag is set moves into the AR
  // register (Cx bytes read), so the read address and its valid come from flip-flops. The beats
  // come back assembled into the restored coxel.
  // ---------------------------------------------------------------------------
  localparam int unsigned RqDepth = 1 << $clog2(Outstanding);
  logic [TagW-1:0]  ptaken_q, pdone_q, rq_tag, hd_tag_q, tag_d;
  logic             rq_empty, rq_full, rq_push, ar_fire, r_fire;
  logic [AddrW-1:0] rq_addr, hd_addr_q, ar_addr_q;
  logic [OutW-1:0]  rs_out_q;     // restores past the head register, not yet handed over
  logic             hd_v_q, hd_ok_q, ar_v_q, hd_move, hd_load;
  logic signed [TagW-1:0] behind;   // parks done minus the head's tag (wraps: compare its sign)
  logic             rs_v_q;
  logic [PkBeats*DataW-1:0] rs_q;
  logic             rq_zero, rq_zero_q, hd_zero_q, rq_ok;
  logic             ord_zero, ord_empty, ord_full, ord_pop, rs_take;

  // ---- the zero-park FIFO: a bit per recorded park, in park order ----
  if (ZeroSkip != 0) begin : gen_zero
    localparam int unsigned ZDepth = (ZeroDepth != 0) ? ZeroDepth : (1 << (2 * (DimW - 1)));
    localparam int unsigned ZPtrW  = $clog2(ZDepth);
    localparam int unsigned UnW    = 2 * DimW + 2;
    logic [ZPtrW:0] zw_q, zr_q;     // bits written, bits read into the head
    logic           zh_v_q;         // the head bit (the RAM's registered output) is valid
    logic           zh_bit;
    logic [UnW-1:0] unrec_q;        // parks written and recorded nowhere, not yet restored
    logic           z_push, z_re, z_pop, z_any, un_pop;
    // The FIFO full and no park unrecorded, kept in registers so that a park's decision starts
    // at flip-flops; each is set from the count's registered value and this cycle's push and pop
    // (one LUT after them, not after an adder).
    logic           z_full_q, unrec_zero_q, z_cnt_full, z_cnt_near, un_inc;
    logic [ZPtrW:0] z_cnt;

    if (ZDepth < 2 || (1 << ZPtrW) != ZDepth) begin : gen_bad_zdepth
      $fatal(1, "cube5_accel_win: ZeroDepth must be 0 or a power of two >= 2");
    end

    assign p_rec  = unrec_zero_q && !z_full_q;
    assign z_push = p_decide && p_rec;
    // A request belongs to the FIFO's head while the FIFO holds a bit (the recorded parks are
    // older than the unrecorded ones), else to an unrecorded park: a read.
    assign z_any  = zh_v_q || zw_q != zr_q;
    assign rq_ok  = !z_any || zh_v_q;
    assign rq_zero = z_any && zh_bit;
    assign z_pop  = rq_push && z_any;
    assign un_pop = rq_push && !z_any;
    assign z_re   = zw_q != zr_q && (!zh_v_q || z_pop);
    assign z_cnt      = zw_q - zr_q;
    assign z_cnt_full = z_cnt == (ZPtrW+1)'(ZDepth);
    assign z_cnt_near = z_cnt == (ZPtrW+1)'(ZDepth - 1);
    assign un_inc     = p_write && !p_rec;

    cube5_section_buf_ram #(.Depth(ZDepth), .Width(1), .AddrW(ZPtrW)) u_zbits (
      .clk_i,
      .we_i(z_push), .waddr_i(zw_q[ZPtrW-1:0]), .wdata_i(p_drop),
      .re_i(z_re), .raddr_i(zr_q[ZPtrW-1:0]), .rdata_o(zh_bit)
    );

    always_ff @(posedge clk_i) begin
      if (!rst_ni || frame_start_i) begin
        zw_q    <= '0;
        zr_q    <= '0;
        zh_v_q  <= 1'b0;
        unrec_q <= '0;
        z_full_q     <= 1'b0;
        unrec_zero_q <= 1'b1;
      end else begin
        zw_q    <= zw_q + (ZPtrW+1)'(z_push);
        zr_q    <= zr_q + (ZPtrW+1)'(z_re);
        if (z_re)       zh_v_q <= 1'b1;
        else if (z_pop) zh_v_q <= 1'b0;
        unrec_q <= unrec_q + UnW'(un_inc) - UnW'(un_pop);
        z_full_q     <= (z_push == z_re) ? z_cnt_full : (z_push && z_cnt_near);
        unrec_zero_q <= (un_inc == un_pop) ? unrec_zero_q : (un_pop && unrec_q == UnW'(1));
      end
    end

`ifndef SYNTHESIS
    WinZeroFlags: assert property (@(posedge clk_i) disable iff (!rst_ni)
        z_full_q == (zw_q - zr_q == (ZPtrW+1)'(ZDepth)) && unrec_zero_q == (unrec_q == '0))
      else $error("cube5_accel_win: the zero FIFO's registered flags disagree with its counts");
    WinZeroKnown: assert property (@(posedge clk_i) disable iff (!rst_ni)
        un_pop |-> unrec_q != '0)
      else $error("cube5_accel_win: a restore request before its park");
`endif
  end else begin : gen_no_zero
    logic unused_zero;
    assign p_rec   = 1'b0;
    assign rq_ok   = 1'b1;
    assign rq_zero = 1'b0;
    assign unused_zero = frame_start_i;
  end

  logic             rg_cx_v, rg_idle;   // Ring = 1: a restored coxel unpacked; nothing in flight
  logic [StoreW-1:0] rg_cx;
  logic [AddrW-1:0] rg_araddr;
  logic [7:0]       rg_arlen;
  logic             rg_arvalid;

  assign rq_ready_o = ((Ring != 0) ? !ord_full : !rq_full) && rq_ok;
  assign rq_push    = rq_valid_i && rq_ready_o;

  cube5_frame_fifo #(.Width(AddrW + TagW + 1), .Depth(RqDepth)) u_rq (
    .clk_i, .rst_ni, .clear_i(1'b0),
    .push_i(rq_push && Ring == 0), .d_i({rq_zero, slot_of(rq_key_i), ptaken_q + TagW'(p_write)}),
    .pop_i(hd_load), .q_o({rq_zero_q, rq_addr, rq_tag}), .empty_o(rq_empty), .full_o(rq_full)
  );

  // The head moves on once its parks are written, a read may start and the AR register is free
  // (a zero request: at once); the head register then takes the FIFO's next request. Its flag
  // compares with the parks done so far (pdone_q: a count that only grows, so a set flag stays
  // true). Every request leaving the head enters the order FIFO (zero or a read), which hands
  // the coxels over in request order.
  assign hd_move = hd_v_q && rs_out_q < OutW'(Outstanding)
                   && (hd_zero_q || (hd_ok_q && (!ar_v_q || arready_i)));
  assign hd_load = !rq_empty && (!hd_v_q || hd_move);
  assign tag_d   = hd_load ? rq_tag : hd_tag_q;
  assign behind  = $signed(pdone_q - tag_d);
  assign ar_fire = ar_v_q && arready_i;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      hd_v_q  <= 1'b0;
      hd_ok_q <= 1'b0;
      ar_v_q  <= 1'b0;
    end else begin
      if (hd_load)      hd_v_q <= 1'b1;
      else if (hd_move) hd_v_q <= 1'b0;
      hd_ok_q <= !behind[TagW-1];
      if (hd_move && !hd_zero_q) ar_v_q <= 1'b1;
      else if (ar_fire)          ar_v_q <= 1'b0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (hd_load) begin
      hd_addr_q <= rq_addr;
      hd_tag_q  <= rq_tag;
      hd_zero_q <= rq_zero_q;
    end
    if (hd_move && !hd_zero_q) ar_addr_q <= hd_addr_q;   // (held while AR waits)
  end

  cube5_frame_fifo #(.Width(1), .Depth(RqDepth)) u_ord (
    .clk_i, .rst_ni, .clear_i(1'b0),
    .push_i((Ring != 0) ? rq_push : hd_move), .d_i((Ring != 0) ? rq_zero : hd_zero_q),
    .pop_i(ord_pop), .q_o(ord_zero),
    .empty_o(ord_empty), .full_o(ord_full)
  );

  assign arvalid_o  = (Ring != 0) ? rg_arvalid : ar_v_q;
  assign araddr_o   = (Ring != 0) ? rg_araddr : ar_addr_q;
  assign arlen_o    = (Ring != 0) ? rg_arlen : 8'(PkBeats - 1);
  assign rready_o   = (Ring != 0) || !rs_v_q;   // Ring = 1: the buffer has room (credits)
  assign r_fire     = rvalid_i && rready_o;
  assign rs_valid_o = !ord_empty && (ord_zero || ((Ring != 0) ? rg_cx_v : rs_v_q));
  assign rs_cox_o   = ord_zero ? '0 : (Ring != 0) ? rg_cx : rs_q[StoreW-1:0];
  assign ord_pop    = rs_valid_o && rs_ready_i;
  assign rs_take    = ord_pop && !ord_zero;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      ptaken_q <= '0;
      pdone_q  <= '0;
      rs_out_q <= '0;
      rs_v_q   <= 1'b0;
    end else begin
      ptaken_q <= ptaken_q + TagW'(p_write);
      pdone_q  <= pdone_q + TagW'(b_fire && bid_i == IdPark);
      rs_out_q <= rs_out_q + OutW'(hd_move) - OutW'(ord_pop && Ring == 0);
      if (r_fire && rlast_i && Ring == 0) rs_v_q <= 1'b1;
      else if (rs_take)      rs_v_q <= 1'b0;
    end
  end

  if (PkBeats > 1) begin : gen_rs_beats
    always_ff @(posedge clk_i) begin
      if (r_fire) rs_q <= {rdata_i, rs_q[PkBeats*DataW-1:DataW]};
    end
  end else begin : gen_rs_beat
    always_ff @(posedge clk_i) begin
      if (r_fire) rs_q <= rdata_i;
    end
  end

  // ---------------------------------------------------------------------------
  // Ring = 1: the written parks as one packed bit stream in a ring at ParkBase, in park order
  // (docs/numerics/compos_window.md, *The ring in park order*). Packer: coxels in, whole beats
  // out into a queue; bursts of the queued beats; the restores' reader: the acknowledged beats,
  // in order, read ahead in bursts, unpacked into coxels.
  // ---------------------------------------------------------------------------
  if (Ring != 0) begin : gen_ring
    localparam int unsigned LogW     = $clog2(DataW);
    localparam int unsigned AccBits  = DataW + StoreW;   // under a beat held, plus a coxel
    localparam int unsigned FillW    = $clog2(AccBits + 1);
    localparam int unsigned CntW     = 2 * DimW + 8;     // beat and coxel counts (they wrap)
    localparam int unsigned QDepth   = 2 * RingBurst;    // beats packed, not yet written
    localparam int unsigned RdDepth  = 4 * RingBurst;    // beats read ahead (the memory serves
                                                         // the fetch's queued reads first)
    localparam int unsigned QW       = $clog2(QDepth + 1);
    localparam int unsigned BLog     = $clog2(RingBurst);
    localparam int unsigned PadDepth = 4;
    localparam int unsigned CxDepth  = 4;
    localparam int unsigned BlDepth  = 1 << $clog2(Outstanding);

    if (RingBurst < 2 || (1 << BLog) != RingBurst || RingBurst > 256 || RingBurst * Bbus > 4096)
    begin : gen_bad_burst
      $fatal(1, "cube5_accel_win: RingBurst must be a power of two, 2 to 256 beats, at most 4 KB");
    end

    logic [AddrW-1:0] base;            // ParkBase, slot-aligned (as the slots')
    logic [DimW-1:0]  rows_q;          // the frame's nj
    logic [CntW-1:0]  ring_n_q;        // beats of the ring: Wp nj PkBeats
    assign base = park_base_i & ~AddrW'((1 << CxLog) - 1);

    always_ff @(posedge clk_i) begin
      if (frame_start_i) rows_q <= park_rows_i;
      ring_n_q <= (CntW'(row_pixels_i) * CntW'(rows_q)) << $clog2(PkBeats);
    end

    // ---- the packer: acc_q holds fill_q bits (LSB first; the bits above are zero) ----
    logic [AccBits-1:0] acc_q, acc_s;
    logic [FillW-1:0]   fill_q, fill_s;
    logic [CntW-1:0]    cin_q;         // coxels packed
    logic               flush_q, emit, pad;
    logic               bq_empty, bq_full, pf_empty, pf_full, pf_pop;
    logic [DataW-1:0]   bq_q;
    logic [CntW-1:0]    pf_q;
    logic [QW-1:0]      bq_n_q;        // queued beats not yet in a burst

    assign emit    = fill_q >= FillW'(DataW) && !bq_full;
    assign fill_s  = emit ? fill_q - FillW'(DataW) : fill_q;
    assign acc_s   = emit ? acc_q >> DataW : acc_q;
    assign rg_take = s1_v_q && s1_park_q && !p_drop && fill_s < FillW'(DataW);
    // A flush pads the partial beat: the next coxel starts at the next beat.
    assign pad     = flush_q && !rg_take && fill_q != '0 && fill_q < FillW'(DataW) && !pf_full
                     && !bq_full;

    always_ff @(posedge clk_i) begin
      if (!rst_ni || frame_start_i) begin
        acc_q  <= '0;
        fill_q <= '0;
        cin_q  <= '0;
      end else if (pad) begin
        acc_q  <= '0;
        fill_q <= '0;
      end else begin
        acc_q  <= rg_take ? acc_s | (AccBits'(s1_cox_q[StoreW-1:0]) << fill_s) : acc_s;
        fill_q <= fill_s + (rg_take ? FillW'(StoreW) : FillW'(0));
        cin_q  <= cin_q + CntW'(rg_take);
      end
    end

    cube5_frame_fifo #(.Width(DataW), .Depth(QDepth)) u_bq (
      .clk_i, .rst_ni, .clear_i(frame_start_i),
      .push_i(emit || pad), .d_i(acc_q[DataW-1:0]), .pop_i(rg_w), .q_o(bq_q),
      .empty_o(bq_empty), .full_o(bq_full)
    );
    // The pads' places: the count of coxels packed before each.
    cube5_frame_fifo #(.Width(CntW), .Depth(PadDepth)) u_pf (
      .clk_i, .rst_ni, .clear_i(frame_start_i),
      .push_i(pad), .d_i(cin_q), .pop_i(pf_pop), .q_o(pf_q), .empty_o(pf_empty), .full_o(pf_full)
    );

    // ---- write bursts: cut at address multiples of RingBurst beats and at the ring's end ----
    logic [CntW-1:0] wpos_q, rpos_q;            // ring positions (beats) of the next write, read
    logic [CntW-1:0] w_iss_q, w_ack_q;          // beats in write bursts; acknowledged (B)
    logic [CntW-1:0] r_iss_q, r_ret_q, r_pop_q; // beats read (AR), returned (R), unpacked
    logic [CntW-1:0] w_lim, w_len, w_room, w_end, r_lim, r_len, r_end, r_avail, r_cred;
    logic [CntW-1:0] w_lim_q, w_room_q;         // w_lim, w_room a cycle late (see rg_go)
    logic [CntW-1:0] r_lim_q, r_avail_q, r_cred_q;  // r_lim, r_avail, r_cred a cycle late
    logic [QW-1:0]   mv_q;                      // beats of the current burst still to move
    logic            rg_go, rg_claim_q;         // a burst decided; it holds the AW/W FIFOs
    logic [QW-1:0]   wb_len_q;                  // the decided burst's beats
    logic [AddrW-1:0] wb_addr_q;                // and its address
    logic            bl_empty, bl_full, bl_pop, ar_go, rg_ar_v_q;
    logic [QW-1:0]   bl_q;
    logic [BLog-1:0] w_off, r_off;

    function automatic logic [CntW-1:0] min2(logic [CntW-1:0] a, logic [CntW-1:0] b);
      min2 = (a < b) ? a : b;
    endfunction

    // A burst is decided (rg_go) a cycle before its AW enters the FIFO (rg_aw): the decision's
    // carry chains end in registers, and the FIFOs' users (step, the finals' mover) see only
    // registered state (rg_claim_q, mv_q). Its limit and the ring's room come from registers a
    // cycle late: wpos_q and w_iss_q move only at rg_aw, at least two cycles before the next
    // rg_go (mv_q counts the burst's beats down first), and r_ret_q only grows, so w_lim_q is
    // w_lim and w_room_q at most w_room whenever rg_go can be true.
    assign w_off  = BLog'(base >> LogBus) + BLog'(wpos_q);
    assign w_end  = ring_n_q - wpos_q;
    assign w_lim  = min2(CntW'(RingBurst) - CntW'(w_off), w_end);
    assign w_len  = min2(CntW'(bq_n_q), w_lim_q);
    assign w_room = ring_n_q - (w_iss_q - r_ret_q);
    assign rg_go  = !rg_claim_q && mv_q == '0 && w_len != '0
                    && (CntW'(bq_n_q) >= w_lim_q || flush_q) && w_len <= w_room_q;
    assign rg_aw  = rg_claim_q && mv_q == '0 && !aw_full && out_q < OutW'(Outstanding) && !fm_busy;
    assign rg_w   = mv_q != '0 && !w_full;
    assign rg_use = rg_claim_q || mv_q != '0;
    assign rg_aw_d = {IdPark, 8'(wb_len_q) - 8'd1, wb_addr_q};
    assign rg_w_d  = {mv_q == QW'(1), {Bbus{1'b1}}, bq_q};
    assign bl_pop  = b_fire && bid_i == IdPark;

    cube5_frame_fifo #(.Width(QW), .Depth(BlDepth)) u_bl (
      .clk_i, .rst_ni, .clear_i(1'b0),
      .push_i(rg_aw), .d_i(wb_len_q), .pop_i(bl_pop), .q_o(bl_q), .empty_o(bl_empty),
      .full_o(bl_full)
    );

    // ---- restore reads: the acknowledged beats in order, ahead, as the buffer has room ----
    logic [AddrW-1:0] rg_addr_q;
    logic [7:0]       rg_len_q;
    logic             rb_empty, rb_full, rb_pop, hd_v, hd_take;
    logic [DataW-1:0] rb_q, hd_beat;
    logic [OutW-1:0]  r_out_q;          // read bursts issued, last beat not yet in

    assign r_off   = BLog'(base >> LogBus) + BLog'(rpos_q);
    assign r_end   = ring_n_q - rpos_q;
    assign r_avail = w_ack_q - r_iss_q;
    assign r_cred  = CntW'(RdDepth) - (r_iss_q - r_pop_q);
    assign r_lim   = min2(CntW'(RingBurst) - CntW'(r_off), r_end);
    // A read waits until the buffer has room for the whole burst (not a beat at a time). As the
    // writes' decision, it reads its limit, the acknowledged beats and the buffer's room from
    // registers a cycle late: rpos_q and r_iss_q move only at ar_go, and the next ar_go waits
    // until the AR register is free (at least two cycles), while w_ack_q and r_pop_q only grow.
    assign r_len   = min2(r_avail_q, r_lim_q);
    assign ar_go   = r_len != '0 && r_len <= r_cred_q && !rg_ar_v_q && r_out_q < OutW'(Outstanding);

    always_ff @(posedge clk_i) begin
      if (!rst_ni || frame_start_i) begin
        wpos_q <= '0;
        rpos_q <= '0;
        w_iss_q <= '0;
        w_ack_q <= '0;
        r_iss_q <= '0;
        r_ret_q <= '0;
        r_pop_q <= '0;
        bq_n_q <= '0;
        mv_q   <= '0;
        rg_claim_q <= 1'b0;
        // Nothing is decided in the cycle after: no room, no beats to read.
        w_lim_q   <= '0;
        w_room_q  <= '0;
        r_lim_q   <= '0;
        r_avail_q <= '0;
        r_cred_q  <= '0;
        rg_ar_v_q <= 1'b0;
        flush_q <= 1'b0;
        r_out_q <= '0;
      end else begin
        w_lim_q   <= w_lim;
        w_room_q  <= w_room;
        r_lim_q   <= r_lim;
        r_avail_q <= r_avail;
        r_cred_q  <= r_cred;
        bq_n_q <= bq_n_q + QW'(emit || pad) - (rg_aw ? wb_len_q : QW'(0));
        if (rg_go) rg_claim_q <= 1'b1;
        if (rg_aw) begin
          rg_claim_q <= 1'b0;
          mv_q    <= wb_len_q;
          w_iss_q <= w_iss_q + CntW'(wb_len_q);
          wpos_q  <= (CntW'(wb_len_q) == w_end) ? '0 : wpos_q + CntW'(wb_len_q);
        end else if (rg_w) begin
          mv_q <= mv_q - QW'(1);
        end
        if (bl_pop) w_ack_q <= w_ack_q + CntW'(bl_q);
        if (ar_go) begin
          rg_ar_v_q <= 1'b1;
          r_iss_q   <= r_iss_q + r_len;
          rpos_q    <= (r_len == r_end) ? '0 : rpos_q + r_len;
        end else if (arready_i) begin
          rg_ar_v_q <= 1'b0;
        end
        r_ret_q <= r_ret_q + CntW'(r_fire);
        r_out_q <= r_out_q + OutW'(ar_go) - OutW'(r_fire && rlast_i);
        r_pop_q <= r_pop_q + CntW'(rb_pop);
        // The frame waits for a restore whose bits are not on their way: write what is held.
        flush_q <= !ord_empty && !ord_zero && !rg_cx_v && rb_empty && !hd_v && r_avail == '0
                   && r_iss_q == r_ret_q && !rg_ar_v_q && bl_empty && mv_q == '0 && !rg_claim_q;
      end
    end

    always_ff @(posedge clk_i) begin
      if (rg_go) begin
        wb_len_q  <= QW'(w_len);
        wb_addr_q <= base + (AddrW'(wpos_q) << LogBus);
      end
      if (ar_go) begin
        rg_addr_q <= base + (AddrW'(rpos_q) << LogBus);
        rg_len_q  <= 8'(r_len - CntW'(1));
      end
    end
    assign rg_arvalid = rg_ar_v_q;
    assign rg_araddr  = rg_addr_q;
    assign rg_arlen   = rg_len_q;

    cube5_frame_fifo #(.Width(DataW), .Depth(RdDepth)) u_rb (
      .clk_i, .rst_ni, .clear_i(frame_start_i),
      .push_i(r_fire), .d_i(rdata_i), .pop_i(rb_pop), .q_o(rb_q), .empty_o(rb_empty),
      .full_o(rb_full)
    );

    // ---- the unpacker: dbuf_q holds dfill_q bits, ending at a beat's end ----
    localparam int unsigned DBits = StoreW + DataW;
    localparam int unsigned DFillW = $clog2(DBits + 1);
    logic [DBits-1:0]  dbuf_q;
    logic [DFillW-1:0] dfill_q, drop;
    logic [CntW-1:0]   cout_q;          // coxels unpacked
    logic              pad_hit, ex, ap, cx_full, cx_empty;

    assign pad_hit = !pf_empty && pf_q == cout_q;
    assign drop    = DFillW'(dfill_q[LogW-1:0]);   // the rest of the beat under way
    assign ex      = !pad_hit && dfill_q >= DFillW'(StoreW) && !cx_full;
    assign ap      = !pad_hit && dfill_q < DFillW'(StoreW) && hd_v;
    assign pf_pop  = pad_hit;

    // The buffer's head beat through a register slice: the unpacker's shift starts at flip-flops,
    // not at the block RAM's output (5.8 ns of clock-to-out on the ECP5 without its register).
    cube5_axi_slice #(.Width(DataW)) u_hd (
      .clk_i, .rst_ni(rst_ni && !frame_start_i),
      .in_valid_i(!rb_empty), .in_ready_o(hd_take), .in_data_i(rb_q),
      .out_valid_o(hd_v), .out_ready_i(ap), .out_data_o(hd_beat)
    );
    assign rb_pop = !rb_empty && hd_take;

    always_ff @(posedge clk_i) begin
      if (!rst_ni || frame_start_i) begin
        dbuf_q  <= '0;
        dfill_q <= '0;
        cout_q  <= '0;
      end else if (pad_hit) begin
        dbuf_q  <= dbuf_q >> drop;
        dfill_q <= dfill_q - drop;
      end else if (ex) begin
        dbuf_q  <= dbuf_q >> StoreW;
        dfill_q <= dfill_q - DFillW'(StoreW);
        cout_q  <= cout_q + CntW'(1);
      end else if (ap) begin
        dbuf_q  <= dbuf_q | (DBits'(hd_beat) << dfill_q);
        dfill_q <= dfill_q + DFillW'(DataW);
      end
    end

    cube5_frame_fifo #(.Width(StoreW), .Depth(CxDepth)) u_cx (
      .clk_i, .rst_ni, .clear_i(frame_start_i),
      .push_i(ex), .d_i(dbuf_q[StoreW-1:0]), .pop_i(rs_take), .q_o(rg_cx),
      .empty_o(cx_empty), .full_o(cx_full)
    );
    assign rg_cx_v = !cx_empty;
    assign rg_idle = mv_q == '0 && !rg_claim_q && bl_empty && r_iss_q == r_ret_q && !rg_ar_v_q;

`ifndef SYNTHESIS
    WinRingRoom: assert property (@(posedge clk_i) disable iff (!rst_ni)
        !(w_len != '0 && w_len > w_room))
      else $error("cube5_accel_win: the ring is full (docs/numerics/compos_window.md bound)");
    WinRingLate: assert property (@(posedge clk_i) disable iff (!rst_ni)
        rg_go |-> w_lim_q == w_lim && w_room_q <= w_room)
      else $error("cube5_accel_win: a ring burst decided on a stale limit or room");
    WinRingReadLate: assert property (@(posedge clk_i) disable iff (!rst_ni)
        ar_go |-> r_lim_q == r_lim && r_avail_q <= r_avail && r_cred_q <= r_cred)
      else $error("cube5_accel_win: a ring read decided on a stale limit, count or room");
    WinRingOrder: assert property (@(posedge clk_i) disable iff (!rst_ni)
        rs_take |-> !cx_empty)
      else $error("cube5_accel_win: a restore handed over before its coxel");
`endif
    logic unused_ring;
    assign unused_ring = ^{bl_full, rb_full, bq_empty};
  end else begin : gen_no_ring
    assign rg_take    = 1'b0;
    assign rg_aw      = 1'b0;
    assign rg_w       = 1'b0;
    assign rg_use     = 1'b0;
    assign rg_aw_d    = '0;
    assign rg_w_d     = '0;
    assign rg_cx_v    = 1'b0;
    assign rg_cx      = '0;
    assign rg_idle    = 1'b1;
    assign rg_arvalid = 1'b0;
    assign rg_araddr  = '0;
    assign rg_arlen   = '0;
    logic unused_rows;
    assign unused_rows = ^{park_rows_i, fm_busy};
  end

  // ---------------------------------------------------------------------------
  // FinBurst > 0: the final items' beats gathered into runs of consecutive beats (the *run*:
  // its first beat's address and length; its last beat, cur, held in registers while later
  // beats may merge into it; the earlier ones in a FIFO), each closed run one INCR burst
  // (docs/numerics/compos_window.md, *Final pixels in bursts*).
  // ---------------------------------------------------------------------------
  if (FinBurst != 0) begin : gen_fin
    localparam int unsigned FLog    = $clog2(FinBurst);
    localparam int unsigned FnW     = $clog2(FinBurst + 1);
    localparam int unsigned FqDepth = 2 * FinBurst;    // beats of closed runs and the open one
    localparam int unsigned FdDepth = 4;               // closed runs waiting for the port
    localparam int unsigned FinWait = 16;              // idle cycles that close a run
    localparam int unsigned WaitW   = $clog2(FinWait);
    localparam int unsigned FdW     = AddrW + 8;

    if (FinBurst < 2 || (1 << FLog) != FinBurst || FinBurst > 256 || FinBurst * Bbus > 4096)
    begin : gen_bad_fin
      $fatal(1, "cube5_accel_win: FinBurst must be 0 or a power of two, 2 to 256 beats, <= 4 KB");
    end

    logic               fc_v_q;        // a run is open (cur holds its last beat)
    logic [AddrW-1:0]   fc_first_q, fc_addr_q, ba;
    logic [DataW-1:0]   fc_data_q, fc_merged;
    logic [Bbus-1:0]    fc_strb_q;
    logic [FnW-1:0]     fc_n_q;        // the run's beats, cur included
    logic [WaitW-1:0]   fc_wait_q;     // cycles with the run open and no final beat
    logic               j_same, j_next, close_in, close_t, fq_push, fd_push;
    logic               fq_full, fq_empty, fd_full, fd_empty;
    logic [WW-2:0]      fq_q;
    logic [FdW-1:0]     fd_q;
    logic [8:0]         fm_mv_q;       // beats of the moving burst still to go

    assign ba      = s3_addr_q + (AddrW'(t_q) << LogBus);
    assign j_same  = fc_v_q && ba == fc_addr_q;
    assign j_next  = fc_v_q && ba == fc_addr_q + AddrW'(Bbus) && FLog'(ba >> LogBus) != '0;
    assign fc_ok   = !fq_full && !fd_full;
    assign close_in = step && fc_in && fc_v_q && !j_same && !j_next;
    assign close_t  = fc_v_q && !(step && fc_in) && fc_wait_q == WaitW'(FinWait - 1) && fc_ok;
    // cur leaves for the FIFO when the next beat follows it or the run closes.
    assign fq_push = (step && fc_in && fc_v_q && !j_same) || close_t;
    assign fd_push = close_in || close_t;
    for (genvar b = 0; b < Bbus; b++) begin : gen_merge
      assign fc_merged[8*b +: 8] = beat_strb[b] ? beat[8*b +: 8] : fc_data_q[8*b +: 8];
    end

    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        fc_v_q    <= 1'b0;
        fc_wait_q <= '0;
      end else begin
        if (step && fc_in) fc_v_q <= 1'b1;
        else if (close_t)  fc_v_q <= 1'b0;
        if ((step && fc_in) || !fc_v_q)        fc_wait_q <= '0;
        else if (fc_wait_q != WaitW'(FinWait - 1)) fc_wait_q <= fc_wait_q + WaitW'(1);
      end
    end

    always_ff @(posedge clk_i) begin
      if (step && fc_in) begin
        if (j_same) begin
          fc_data_q <= fc_merged;
          fc_strb_q <= fc_strb_q | beat_strb;
        end else begin
          fc_data_q <= beat;
          fc_strb_q <= beat_strb;
          fc_addr_q <= ba;
        end
        if (!fc_v_q || !(j_same || j_next)) begin
          fc_first_q <= ba;
          fc_n_q     <= FnW'(1);
        end else if (j_next) begin
          fc_n_q <= fc_n_q + FnW'(1);
        end
      end
    end

    cube5_frame_fifo #(.Width(WW - 1), .Depth(FqDepth)) u_fq (
      .clk_i, .rst_ni, .clear_i(1'b0),
      .push_i(fq_push), .d_i({fc_strb_q, fc_data_q}), .pop_i(fm_w), .q_o(fq_q),
      .empty_o(fq_empty), .full_o(fq_full)
    );
    cube5_frame_fifo #(.Width(FdW), .Depth(FdDepth)) u_fd (
      .clk_i, .rst_ni, .clear_i(1'b0),
      .push_i(fd_push), .d_i({8'(fc_n_q) - 8'd1, fc_first_q}), .pop_i(fm_aw), .q_o(fd_q),
      .empty_o(fd_empty), .full_o(fd_full)
    );

    // The mover: a closed run's AW, then its beats, while no ring burst moves.
    assign fm_aw   = fm_mv_q == '0 && !fd_empty && !rg_use && !aw_full
                     && out_q < OutW'(Outstanding);
    assign fm_w    = fm_mv_q != '0 && !w_full;
    assign fm_busy = fm_mv_q != '0;
    assign fm_use  = fm_aw || fm_busy;
    assign fm_aw_d = {IdFin, fd_q};
    assign fm_w_d  = {fm_mv_q == 9'd1, fq_q};
    assign fm_idle = !fc_v_q && fd_empty && fm_mv_q == '0;

    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        fm_mv_q <= '0;
      end else if (fm_aw) begin
        fm_mv_q <= 9'(fd_q[AddrW +: 8]) + 9'd1;
      end else if (fm_w) begin
        fm_mv_q <= fm_mv_q - 9'd1;
      end
    end

`ifndef SYNTHESIS
    WinFinRun: assert property (@(posedge clk_i) disable iff (!rst_ni)
        fm_w |-> !fq_empty)
      else $error("cube5_accel_win: a finals burst's beat before it was gathered");
`endif
  end else begin : gen_no_fin
    assign fc_ok   = 1'b1;
    assign fm_aw   = 1'b0;
    assign fm_w    = 1'b0;
    assign fm_busy = 1'b0;
    assign fm_use  = 1'b0;
    assign fm_aw_d = '0;
    assign fm_w_d  = '0;
    assign fm_idle = 1'b1;
  end

  // ---------------------------------------------------------------------------
  // Drained, errors
  // ---------------------------------------------------------------------------
  logic err_q;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      err_q <= 1'b0;
    end else if ((b_fire && bresp_i != 2'b00) || (r_fire && rresp_i != 2'b00)) begin
      err_q <= 1'b1;
    end
  end
  assign err_o  = err_q;
  assign wr_wait_o = !w_empty;
  assign idle_o = !s1_v_q && !s2_v_q && !s3_v_q && aw_empty && w_empty && out_q == '0 && rq_empty
                  && !hd_v_q && rs_out_q == '0 && !rs_v_q && ord_empty && rg_idle && fm_idle;
  logic unused_ord;
  assign unused_ord = ord_full;

  // The terminated flags of the final lanes (a pixel is R, G, B, A only).
  logic [P-1:0] unused_term;
  for (genvar k = 0; k < P; k++) begin : gen_unused
    assign unused_term[k] = s1_cox_q[k*StoreW + 4*ChanW];
  end
  logic unused;
  if (PkBeats * DataW > StoreW) begin : gen_unused_pad
    assign unused = ^{unused_term, rs_q[PkBeats*DataW-1:StoreW]};   // the slot's padding
  end else begin : gen_unused_nopad
    assign unused = ^unused_term;
  end

endmodule
