// gicube_queue_front: the queue front end of the GI-Cube block processor (patent [355],
// [370]-[374]; docs/numerics/gicube_queue_front.md; docs/gicube-rtl.md, parts A-D): the ray input
// arbiter (the pipeline's re-queued ray before the host's), two bucketing lanes (gicube_bucket),
// the ray queues with overflow to the host (gicube_ray_queues) and the queue sorter
// (gicube_sorter), all three unchanged. One input item is one processor cycle: pop the active
// queue's head for the pipeline, push the ring's ray (or return it with OVERFLOW set), then take
// the host's ray if fewer than two sorter updates were made and its queue has room, then two
// sorter updates.
//
// The three units are lockstep units with one registered output each; one processor cycle is a
// fixed schedule of four clocks (c = the clock the item is taken):
//   c     bucketing of both rays; ray-queue item A: pop the active queue S[0]
//   c + 1 ray-queue item B: push the ring's ray, probe the host ray's queue
//   c + 2 the updates and the host decided from B; item C: push the host's ray, probe S[0];
//         sorter update 1
//   c + 3 sorter update 2; the output item registered (offered from c + 4, with the next S[0])
// The sub-units' outputs are read in the clock after their item, so their ready is tied high.
module gicube_queue_front #(
  /// Block side n = 2^BlockLog2 voxels, 1..8.
  parameter int unsigned BlockLog2 = 4,
  /// Blocks a side B, 1..6 (B^3 <= 256 queues); B << BlockLog2 <= 4096.
  parameter int unsigned VolBlocks = 4,
  /// Rays per queue, 1..4096 (256 in [371]).
  parameter int unsigned QueueLen  = 64,
  /// Sorter ranks, 2..64 and <= 2^QueueW.
  parameter int unsigned Ranks     = 16
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// take, ring, host, ring_ray (256), host_ray (256), LSB first.
  input  logic [3+2*gicube_pkg::PacketW-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the output item this cycle.
  input  logic out_ready_i,
  /// active, active_q (QueueW), popped, emptied, ring_pushed, ring_ovf, host_taken, host_stall,
  /// ring_q (QueueW), host_q (QueueW), active_len (LenW), total (TotW), pop_ray (256), ovf_ray
  /// (256), LSB first.
  output logic [7+3*gicube_pkg::bucket_queue_w(VolBlocks, 0)+gicube_pkg::rq_len_w(QueueLen)
                +gicube_pkg::rq_tot_w(gicube_pkg::bucket_queue_w(VolBlocks, 0), QueueLen)
                +2*gicube_pkg::PacketW-1:0] out_data_o
);

  localparam int unsigned PacketW = gicube_pkg::PacketW;
  localparam int unsigned QueueW  = gicube_pkg::bucket_queue_w(VolBlocks, 0);
  localparam int unsigned LaneW   = gicube_pkg::bucket_lane_w(VolBlocks, 0);
  localparam int unsigned LenW    = gicube_pkg::rq_len_w(QueueLen);
  localparam int unsigned TotW    = gicube_pkg::rq_tot_w(QueueW, QueueLen);
  localparam int unsigned ImpW    = (LenW < 2) ? 2 : LenW;
  localparam int unsigned ValW    = ImpW + 1;
  localparam int unsigned StartW  = 3 * gicube_pkg::PosW;
  localparam int unsigned StartLsb = gicube_pkg::PacketStartLsb;
  localparam int unsigned OvfBit  = gicube_pkg::PacketFlagsLsb + gicube_pkg::FlagOverflow;
  localparam int unsigned RqOutW  = gicube_pkg::rq_out_w(QueueW, QueueLen, PacketW);
  localparam int unsigned SoInW   = gicube_pkg::sorter_in_w(QueueW, ImpW);
  localparam int unsigned SoOutW  = gicube_pkg::sorter_out_w(Ranks, QueueW, ImpW);
  localparam int unsigned S0Lsb   = 4 + ImpW + QueueW;  // S[0] in the sorter's state output

  // Elaboration checks mirror QueueFrontConfig::validate in the model (the sub-units check the
  // rest of their own ranges).
  if (VolBlocks < 1 || VolBlocks > 6) begin : gen_bad_vol_blocks
    $fatal(1, "gicube_queue_front: VolBlocks must be 1..6 (VolBlocks^3 <= 256 queues)");
  end
  if (QueueLen < 1 || QueueLen > 4096) begin : gen_bad_queue_len
    $fatal(1, "gicube_queue_front: QueueLen must be 1..4096");
  end
  if (Ranks < 2 || Ranks > 64 || Ranks > (1 << QueueW)) begin : gen_bad_ranks
    $fatal(1, "gicube_queue_front: Ranks must be 2..64 and at most 2^QueueW");
  end

  // ---------------------------------------------------------------------------
  // Schedule: phase 0 takes an item, phases 1..3 finish it
  // ---------------------------------------------------------------------------
  logic [1:0] phase_q, phase_d;
  logic       out_valid_q, out_valid_d;
  logic       in_fire;

  assign in_ready_o  = (phase_q == 2'd0) && (!out_valid_q || out_ready_i);
  assign in_fire     = in_valid_i && in_ready_o;
  assign phase_d     = (phase_q != 2'd0) ? phase_q + 2'd1 : (in_fire ? 2'd1 : 2'd0);
  assign out_valid_d = (phase_q == 2'd3) || (out_valid_q && !out_ready_i);

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      phase_q     <= 2'd0;
      out_valid_q <= 1'b0;
    end else begin
      phase_q     <= phase_d;
      out_valid_q <= out_valid_d;
    end
  end

  // ---------------------------------------------------------------------------
  // The item, held for phases 1 and 2 (datapath: no reset)
  // ---------------------------------------------------------------------------
  logic               take, ring_v, host_v;
  logic [PacketW-1:0] ring_ray, host_ray;
  logic               ring_v_q, host_v_q;
  logic [PacketW-1:0] ring_ray_q, host_ray_q;

  assign take     = in_data_i[0];
  assign ring_v   = in_data_i[1];
  assign host_v   = in_data_i[2];
  assign ring_ray = in_data_i[3 +: PacketW];
  assign host_ray = in_data_i[3 + PacketW +: PacketW];

  always_ff @(posedge clk_i) begin
    if (in_fire) begin
      ring_v_q   <= ring_v;
      host_v_q   <= host_v;
      ring_ray_q <= ring_ray;
      host_ray_q <= host_ray;
    end
  end

  // ---------------------------------------------------------------------------
  // B: bucketing, lane 0 the ring's ray, lane 1 the host's
  // ---------------------------------------------------------------------------
  logic [2*LaneW-1:0] bk_out;
  logic               bk_in_ready, bk_out_valid;

  gicube_bucket #(
    .BlockLog2 (BlockLog2),
    .VolBlocks (VolBlocks),
    .ProcLog2  (0),
    .Dist      (gicube_pkg::DistSlab),
    .Lanes     (2)
  ) u_bucket (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_fire),
    .in_ready_o  (bk_in_ready),
    .in_data_i   ({host_ray[StartLsb +: StartW], ring_ray[StartLsb +: StartW]}),
    .out_valid_o (bk_out_valid),
    .out_ready_i (1'b1),
    .out_data_o  (bk_out)
  );

  logic [QueueW-1:0] qr, qh, qr_q, qh_q;

  assign qr = bk_out[0 +: QueueW];
  assign qh = bk_out[LaneW +: QueueW];

  // ---------------------------------------------------------------------------
  // D: the sorter; S[0] is the active queue
  // ---------------------------------------------------------------------------
  logic [SoInW-1:0]  so_in;
  logic              so_valid, so_in_ready, so_out_valid;
  logic [SoOutW-1:0] so_out;
  logic              act_v, act_v_q;
  logic [QueueW-1:0] act, act_q;

  assign act_v = so_out[S0Lsb];
  assign act   = so_out[S0Lsb + 1 +: QueueW];

  gicube_sorter #(
    .Ranks    (Ranks),
    .QueueW   (QueueW),
    .ImpW     (ImpW),
    .QueueLen (QueueLen)
  ) u_sorter (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (so_valid),
    .in_ready_o  (so_in_ready),
    .in_data_i   (so_in),
    .out_valid_o (so_out_valid),
    .out_ready_i (1'b1),
    .out_data_o  (so_out)
  );

  // ---------------------------------------------------------------------------
  // C: the ray queues, items A (phase 0), B (phase 1), C (phase 2)
  // ---------------------------------------------------------------------------
  logic              rq_valid, rq_in_ready, rq_out_valid;
  logic              rq_pop, rq_push;
  logic [QueueW-1:0] rq_pop_q, rq_push_q;
  logic [PacketW-1:0] rq_data;
  logic [RqOutW-1:0] rq_out;

  gicube_ray_queues #(
    .QueueW   (QueueW),
    .QueueLen (QueueLen),
    .DataW    (PacketW)
  ) u_queues (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (rq_valid),
    .in_ready_o  (rq_in_ready),
    .in_data_i   ({rq_data, rq_push_q, rq_push, rq_pop_q, rq_pop}),
    .out_valid_o (rq_out_valid),
    .out_ready_i (1'b1),
    .out_data_o  (rq_out)
  );

  logic               o_popped, o_emptied, o_pushed, o_overflow;
  logic [LenW-1:0]    o_pop_len;
  logic [TotW-1:0]    o_total;
  logic [PacketW-1:0] o_pop_data, o_ovf_data;

  assign o_popped   = rq_out[0];
  assign o_emptied  = rq_out[1];
  assign o_pushed   = rq_out[2];
  assign o_overflow = rq_out[3];
  assign o_pop_len  = rq_out[4 +: LenW];
  assign o_total    = rq_out[4 + 2 * LenW +: TotW];
  assign o_pop_data = rq_out[4 + 2 * LenW + TotW +: PacketW];
  assign o_ovf_data = rq_out[4 + 2 * LenW + TotW + PacketW +: PacketW];

  // ---------------------------------------------------------------------------
  // A: the arbiter's decisions (phase 2, from item B's outcome)
  // ---------------------------------------------------------------------------
  logic            popped_q, stayed, u_pop, u_ring, slot_free, room;
  logic            host_taken, host_stall;
  logic [SoInW-1:0] upd_pop, upd_ring, upd_host, upd1, upd2, upd2_q;

  function automatic logic [SoInW-1:0] add(logic [QueueW-1:0] q, logic minus);
    add = {minus ? {ValW{1'b1}} : ValW'(1), q, gicube_pkg::SorterOpAdd};
  endfunction

  always_comb begin
    stayed     = popped_q && o_pushed && (act_q == qr_q);
    u_pop      = popped_q && !stayed;
    u_ring     = o_pushed && !stayed;
    slot_free  = !(u_pop && u_ring);
    room       = (o_pop_len != LenW'(QueueLen));
    host_taken = host_v_q && slot_free && room;
    host_stall = host_v_q && slot_free && !room;
    upd_pop    = add(act_q, 1'b1);
    upd_ring   = add(qr_q, 1'b0);
    upd_host   = add(qh_q, 1'b0);
    // The updates in order, then Noops (all zeros).
    upd1 = u_pop ? upd_pop : (u_ring ? upd_ring : (host_taken ? upd_host : '0));
    upd2 = (u_pop && u_ring) ? upd_ring : ((u_pop || u_ring) && host_taken ? upd_host : '0);
  end

  // Sub-unit items by phase.
  logic [PacketW-1:0] host_clean;

  always_comb begin
    host_clean          = host_ray_q;
    host_clean[OvfBit]  = 1'b0;
    rq_valid  = in_fire || (phase_q == 2'd1) || (phase_q == 2'd2);
    rq_pop    = 1'b0;
    rq_pop_q  = '0;
    rq_push   = 1'b0;
    rq_push_q = '0;
    rq_data   = '0;
    so_valid  = (phase_q == 2'd2) || (phase_q == 2'd3);
    so_in     = (phase_q == 2'd2) ? upd1 : upd2_q;
    unique case (phase_q)
      2'd0: begin  // item A: pop the active queue
        rq_pop   = take && act_v;
        rq_pop_q = act;
      end
      2'd1: begin  // item B: the ring's ray; probe the host ray's queue
        rq_pop_q  = qh;
        rq_push   = ring_v_q;
        rq_push_q = qr;
        rq_data   = ring_ray_q;
      end
      2'd2: begin  // item C: the host's ray if taken; probe the active queue
        rq_pop_q  = act_q;
        rq_push   = host_taken;
        rq_push_q = qh_q;
        rq_data   = host_clean;
      end
      default: ;
    endcase
  end

  // ---------------------------------------------------------------------------
  // The output item, filled in as the phases decide it (datapath: no reset). It is free from
  // the item's transfer on: in_ready needed the previous one taken.
  // ---------------------------------------------------------------------------
  logic               o_emptied_q, ring_pushed_q, ring_ovf_q, host_taken_q, host_stall_q;
  logic [LenW-1:0]    act_len_q;
  logic [TotW-1:0]    total_q;
  logic [PacketW-1:0] pop_ray_q, ovf_ray_q, ovf_marked;

  always_comb begin
    ovf_marked         = o_ovf_data;
    ovf_marked[OvfBit] = o_overflow;
  end

  always_ff @(posedge clk_i) begin
    if (in_fire) begin
      act_v_q <= act_v;
      act_q   <= act_v ? act : '0;
    end
    if (phase_q == 2'd1) begin
      popped_q    <= o_popped;
      o_emptied_q <= o_emptied;
      pop_ray_q   <= o_pop_data;
      qr_q        <= qr;
      qh_q        <= qh;
    end
    if (phase_q == 2'd2) begin
      ring_pushed_q <= o_pushed;
      ring_ovf_q    <= o_overflow;
      ovf_ray_q     <= ovf_marked;
      host_taken_q  <= host_taken;
      host_stall_q  <= host_stall;
      upd2_q        <= upd2;
    end
    if (phase_q == 2'd3) begin
      act_len_q <= act_v_q ? o_pop_len : '0;
      total_q   <= o_total;
    end
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = {ovf_ray_q, pop_ray_q, total_q, act_len_q, qh_q, qr_q, host_stall_q,
                        host_taken_q, ring_ovf_q, ring_pushed_q, o_emptied_q, popped_q, act_q,
                        act_v_q};

  // The sub-units' handshakes: their ready is tied high, so they always take an item and their
  // output is read in the clock after it; the proc and outside fields of the bucketing are not
  // used (one processor; a position outside the volume buckets to queue 0).
  logic unused_handshakes;
  assign unused_handshakes = ^{bk_in_ready, so_in_ready, rq_in_ready, bk_out_valid, so_out_valid,
                               rq_out_valid, bk_out[QueueW +: LaneW - QueueW],
                               bk_out[LaneW + QueueW +: LaneW - QueueW], rq_out[4 + LenW +: LenW],
                               so_out[0 +: S0Lsb],
                               so_out[S0Lsb + 1 + QueueW +: SoOutW - S0Lsb - 1 - QueueW]};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_queue_front: output changed while stalled");
  // The schedule reads each sub-unit's output in the clock after its item.
  SubUnitsAnswerOnSchedule: assert property (@(posedge clk_i) disable iff (!rst_ni)
      (phase_q == 2'd0 || rq_out_valid) && (phase_q != 2'd1 || bk_out_valid)
      && (phase_q != 2'd3 || so_out_valid))
    else $error("gicube_queue_front: a sub-unit's output is missing on schedule");
  // The host is taken only when fewer than two updates were made: two updates at most.
  TwoUpdatesAtMost: assert property (@(posedge clk_i) disable iff (!rst_ni)
      phase_q == 2'd2 |-> !(u_pop && u_ring && host_taken))
    else $error("gicube_queue_front: three sorter updates in one cycle");
`endif

endmodule
