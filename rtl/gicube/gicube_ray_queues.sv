// gicube_ray_queues: the fixed-size ray queues of the GI-Cube block processor (patent [370]-[372];
// docs/numerics/gicube_ray_queues.md). 2^QueueW FIFO queues of QueueLen rays of DataW bits, one
// per block, in one block RAM: queue q owns the slots {q, 0..QueueLen-1}. Each item may dequeue
// the head of one queue (the active queue, one ray per cycle to the pipeline [371]) and enqueue
// one ray into its block's queue. A ray whose queue is full is returned in the output item
// (ovf_data), never dropped [372]. Every queue's count is kept in flops (the importance the queue
// sorter sorts, [373] criterion 1) and reported for the item's two queues, with the total.
//
// The pop and the push both see the counts at the start of the item: a push to a full queue
// overflows even if the same item pops it. So the RAM's write slot (the tail) and read slot (the
// head) differ whenever both are used: the write is skipped when full, the read data is unused
// when empty, and no read-during-write behaviour is relied on.
//
// Lockstep wrapper (as gicube_sorter): the state advances only on an input transfer, the output
// item (registered flags and counts, the RAM's registered read port) follows one clock later, and
// in_ready is low while that output is stalled. One item per clock, latency 1.
module gicube_ray_queues #(
  /// Queue number width, 1..8: 2^QueueW queues (one per block).
  parameter int unsigned QueueW   = 6,
  /// Rays per queue, 1..4096 (256 in [371]).
  parameter int unsigned QueueLen = 64,
  /// Bits of one ray, 1..256 (256: the 32-byte packet of [349]).
  parameter int unsigned DataW    = 256
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// pop (1), pop_q (QueueW), push (1), push_q (QueueW), data (DataW), LSB first.
  input  logic [gicube_pkg::rq_in_w(QueueW, DataW)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the output item this cycle.
  input  logic out_ready_i,
  /// popped, emptied, pushed, overflow, pop_len (LenW), push_len (LenW), total (TotW),
  /// pop_data (DataW, 0 unless popped), ovf_data (DataW, 0 unless overflow), LSB first.
  output logic [gicube_pkg::rq_out_w(QueueW, QueueLen, DataW)-1:0] out_data_o
);

  localparam int unsigned Queues = 1 << QueueW;
  localparam int unsigned LenW   = gicube_pkg::rq_len_w(QueueLen);
  localparam int unsigned TotW   = gicube_pkg::rq_tot_w(QueueW, QueueLen);
  localparam int unsigned SlotW  = (QueueLen > 2) ? $clog2(QueueLen) : 1;
  localparam int unsigned SumW   = LenW + 1;
  localparam int unsigned AddrW  = QueueW + SlotW;

  // Elaboration checks mirror RayQueuesConfig::validate in the model.
  if (QueueW < 1 || QueueW > 8) begin : gen_bad_queue_w
    $fatal(1, "gicube_ray_queues: QueueW must be 1..8");
  end
  if (QueueLen < 1 || QueueLen > 4096) begin : gen_bad_queue_len
    $fatal(1, "gicube_ray_queues: QueueLen must be 1..4096");
  end
  if (DataW < 1 || DataW > 256) begin : gen_bad_data_w
    $fatal(1, "gicube_ray_queues: DataW must be 1..256");
  end

  // ---------------------------------------------------------------------------
  // Handshake: one item per transfer
  // ---------------------------------------------------------------------------
  logic out_valid_q, out_valid_d;
  logic in_fire;

  assign in_ready_o  = !out_valid_q || out_ready_i;
  assign in_fire     = in_valid_i && in_ready_o;
  assign out_valid_d = in_fire || (out_valid_q && !out_ready_i);

  // ---------------------------------------------------------------------------
  // Input fields
  // ---------------------------------------------------------------------------
  logic              pop, push;
  logic [QueueW-1:0] pop_q, push_q;
  logic [DataW-1:0]  data;

  assign pop    = in_data_i[0];
  assign pop_q  = in_data_i[1 +: QueueW];
  assign push   = in_data_i[1 + QueueW];
  assign push_q = in_data_i[2 + QueueW +: QueueW];
  assign data   = in_data_i[2 + 2 * QueueW +: DataW];

  // ---------------------------------------------------------------------------
  // Counts and head pointers (flops), this item's decisions
  // ---------------------------------------------------------------------------
  logic [Queues*LenW-1:0]  len_q, len_d;
  logic [Queues*SlotW-1:0] head_q, head_d;
  logic [TotW-1:0]         total_q, total_d;

  logic [LenW-1:0]  len_pop, len_push, pop_len_d, push_len_d;
  logic [SlotW-1:0] head_pop, head_push, head_next, tail;
  logic [SumW-1:0]  tail_sum;
  logic             popped, pushed, overflow, emptied, same;

  // Read views of the counts and heads with a power-of-two stride, so that the two queues'
  // fields are read through shifters by `q << Sh` (a dense `q * LenW` offset costs MULT18s, a
  // compare per queue costs a priority chain).
  localparam int unsigned LenSh  = $clog2(LenW);
  localparam int unsigned SlotSh = $clog2(SlotW);
  localparam int unsigned LenS   = 1 << LenSh;
  localparam int unsigned SlotS  = 1 << SlotSh;

  logic [Queues*LenS-1:0]  len_view;
  logic [Queues*SlotS-1:0] head_view;

  for (genvar i = 0; i < Queues; i++) begin : gen_view
    assign len_view[i * LenS +: LenS]    = LenS'(len_q[i * LenW +: LenW]);
    assign head_view[i * SlotS +: SlotS] = SlotS'(head_q[i * SlotW +: SlotW]);
  end

  always_comb begin
    len_pop   = len_view[(QueueW + LenSh)'(pop_q) << LenSh +: LenW];
    len_push  = len_view[(QueueW + LenSh)'(push_q) << LenSh +: LenW];
    head_pop  = head_view[(QueueW + SlotSh)'(pop_q) << SlotSh +: SlotW];
    head_push = head_view[(QueueW + SlotSh)'(push_q) << SlotSh +: SlotW];
    same     = (pop_q == push_q);
    popped   = pop && (len_pop != '0);
    pushed   = push && (len_push != LenW'(QueueLen));
    overflow = push && !pushed;
    emptied  = popped && (len_pop == LenW'(1));

    // Head after a pop, and the tail slot of the push queue: head + len, modulo QueueLen.
    head_next = (SumW'(head_pop) + SumW'(1) >= SumW'(QueueLen))
              ? '0 : SlotW'(SumW'(head_pop) + SumW'(1));
    tail_sum  = SumW'(head_push) + SumW'(len_push);
    tail      = (tail_sum >= SumW'(QueueLen)) ? SlotW'(tail_sum - SumW'(QueueLen))
                                              : SlotW'(tail_sum);

    for (int unsigned i = 0; i < Queues; i++) begin
      len_d[i * LenW +: LenW] = len_q[i * LenW +: LenW]
          + LenW'(pushed && (push_q == QueueW'(i)))
          - LenW'(popped && (pop_q == QueueW'(i)));
      head_d[i * SlotW +: SlotW] = (popped && (pop_q == QueueW'(i)))
          ? head_next : head_q[i * SlotW +: SlotW];
    end
    total_d = total_q + TotW'(pushed) - TotW'(popped);

    pop_len_d  = len_pop + LenW'(pushed && same) - LenW'(popped);
    push_len_d = len_push + LenW'(pushed) - LenW'(popped && same);
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      out_valid_q <= 1'b0;
      len_q       <= '0;
      head_q      <= '0;
      total_q     <= '0;
    end else begin
      out_valid_q <= out_valid_d;
      if (in_fire) begin
        len_q   <= len_d;
        head_q  <= head_d;
        total_q <= total_d;
      end
    end
  end

  // ---------------------------------------------------------------------------
  // The queue RAM: write the tail of the push queue, read the head of the pop queue
  // ---------------------------------------------------------------------------
  logic [DataW-1:0] rdata;

  cube5_shader_ram #(
    .Depth (Queues << SlotW),
    .Width (DataW),
    .AddrW (AddrW)
  ) u_ram (
    .clk_i   (clk_i),
    .we_i    (in_fire && pushed),
    .waddr_i ({push_q, tail}),
    .wdata_i (data),
    .re_i    (in_fire),
    .raddr_i ({pop_q, head_pop}),
    .rdata_o (rdata)
  );

  // ---------------------------------------------------------------------------
  // Output register (datapath: no reset)
  // ---------------------------------------------------------------------------
  logic             popped_q, emptied_q, pushed_q, overflow_q;
  logic [LenW-1:0]  pop_len_q, push_len_q;
  logic [DataW-1:0] ovf_data_q;

  always_ff @(posedge clk_i) begin
    if (in_fire) begin
      popped_q   <= popped;
      emptied_q  <= emptied;
      pushed_q   <= pushed;
      overflow_q <= overflow;
      pop_len_q  <= pop_len_d;
      push_len_q <= push_len_d;
      ovf_data_q <= overflow ? data : '0;
    end
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = {ovf_data_q, popped_q ? rdata : {DataW{1'b0}}, total_q, push_len_q,
                        pop_len_q, overflow_q, pushed_q, emptied_q, popped_q};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_ray_queues: output changed while stalled");
  // No queue ever holds more than QueueLen rays, nor all of them more than they can.
  CountsInRange: assert property (@(posedge clk_i) disable iff (!rst_ni)
      len_pop <= LenW'(QueueLen) && len_push <= LenW'(QueueLen)
      && total_q <= TotW'(QueueLen << QueueW))
    else $error("gicube_ray_queues: a count exceeds its queue");
`endif

endmodule
