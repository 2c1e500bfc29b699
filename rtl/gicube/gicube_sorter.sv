// gicube_sorter: per-queue importance counters and the pipelined insertion queue sorter of the
// GI-Cube block processor (patent [29], [370]-[374]; docs/numerics/gicube_sorter.md).
//
// Each accepted update item is one logical cycle: the item's queue counter is updated (add or set,
// saturated to U(ImpW.0)); an update to the active queue (S[0]) only changes its count and, when it
// reaches zero, empties it; an update to any other queue wipes that queue's old entry from every
// buffer and enters the new importance at the top (C[0]). In every other cycle (a slot cycle) a
// background scan of the counters re-offers its queue at the top if that queue is non-empty, not
// held, and would fit (larger than the last rank's entry, or that is empty), so no queue that fell
// off the last rank is forgotten. Every rank compares its
// comparison buffer with its selected buffer: the larger stays, the smaller moves to the next
// rank's comparison buffer, so entries filter down one rank per cycle, several in flight at once.
// S[0] is the active queue and counts as infinite. An empty selected buffer with entries below it
// (an open hole) lets entries in flight pass, and the topmost hole closes in the same cycle: the
// ranks from it down move up one (from rank 0 when the active queue empties or none is active).
//
// Lockstep wrapper: the state advances only on an input transfer and the registered state is the
// output item (one per input, latency 1); in_ready is low while that output is stalled, so random
// idle and back-pressure never change the logical schedule.
module gicube_sorter #(
  /// R, ranks, 2..64 and <= 2^QueueW.
  parameter int unsigned Ranks  = 32,
  /// Queue number width, 1..8; 2^QueueW queues.
  parameter int unsigned QueueW = 7,
  /// Importance width, 2..24, U(ImpW.0).
  parameter int unsigned ImpW   = 16,
  /// Importance of a full queue (256 rays in [371]); 1..2^ImpW-1, so a full queue never saturates.
  parameter int unsigned QueueLen = 256
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Update item valid.
  input  logic in_valid_i,
  /// Unit can take an update this cycle.
  output logic in_ready_o,
  /// op (2), queue (QueueW), value (ImpW + 1, two's complement), LSB first.
  input  logic [gicube_pkg::sorter_in_w(QueueW, ImpW)-1:0] in_data_i,

  /// State output valid.
  output logic out_valid_o,
  /// Consumer takes the state this cycle.
  input  logic out_ready_i,
  /// emptied, shifted, dropped, offered, imp_q (ImpW), scan (QueueW), then S[r], C[r] for
  /// r = 0..Ranks-1, each valid, queue, importance (LSB first); empty buffers are all zeros.
  output logic [gicube_pkg::sorter_out_w(Ranks, QueueW, ImpW)-1:0] out_data_o
);

  localparam int unsigned Queues = 1 << QueueW;
  localparam int unsigned ValW   = ImpW + 1;
  localparam int unsigned SumW   = ImpW + 2;
  localparam int unsigned EntryW = gicube_pkg::sorter_entry_w(QueueW, ImpW);
  localparam int unsigned OutW   = gicube_pkg::sorter_out_w(Ranks, QueueW, ImpW);
  localparam int unsigned RankLsb = 4 + ImpW + QueueW;  // first bit of S[0] in the output

  // Elaboration checks mirror SorterConfig::validate in the model.
  if (QueueW < 1 || QueueW > 8) begin : gen_bad_queue_w
    $fatal(1, "gicube_sorter: QueueW must be 1..8");
  end
  if (Ranks < 2 || Ranks > 64) begin : gen_bad_ranks
    $fatal(1, "gicube_sorter: Ranks must be 2..64");
  end
  if (Ranks > Queues) begin : gen_bad_ranks_queues
    $fatal(1, "gicube_sorter: Ranks must not exceed the 2^QueueW queues");
  end
  if (ImpW < 2 || ImpW > 24) begin : gen_bad_imp_w
    $fatal(1, "gicube_sorter: ImpW must be 2..24");
  end
  if (QueueLen < 1 || QueueLen > (1 << ImpW) - 1) begin : gen_bad_queue_len
    $fatal(1, "gicube_sorter: ImpW cannot count a full queue of QueueLen (QueueLen > 2^ImpW - 1)");
  end

  // ---------------------------------------------------------------------------
  // Handshake: one logical cycle per accepted item
  // ---------------------------------------------------------------------------
  logic out_valid_q, out_valid_d;
  logic in_fire;

  assign in_ready_o  = !out_valid_q || out_ready_i;
  assign in_fire     = in_valid_i && in_ready_o;
  assign out_valid_d = in_fire ? 1'b1 : (out_ready_i ? 1'b0 : out_valid_q);

  logic [1:0]        op;
  logic [QueueW-1:0] qin;
  logic [ValW-1:0]   val;

  assign op  = in_data_i[0 +: 2];
  assign qin = in_data_i[2 +: QueueW];
  assign val = in_data_i[2 + QueueW +: ValW];

  // ---------------------------------------------------------------------------
  // State: counters, the scan pointer, and per rank the selected (s*) and comparison (c*) buffers
  // ---------------------------------------------------------------------------
  logic [Queues*ImpW-1:0] cnt_q, cnt_d;
  logic [QueueW-1:0]       scan_q, scan_d;
  logic [Ranks-1:0]        sv_q, sv_d, cv_q, cv_d;          // valids
  logic [Ranks*QueueW-1:0] sq_q, sq_d, cq_q, cq_d;          // queue numbers
  logic [Ranks*ImpW-1:0]   si_q, si_d, ci_q, ci_d;          // importances
  logic                    emptied_q, shifted_q, dropped_q, offered_q;
  logic [ImpW-1:0]         impq_q, impq_d;

  // ---------------------------------------------------------------------------
  // Counter update: new = clamp(base + value), base = 0 for Set
  // ---------------------------------------------------------------------------
  logic            upd;
  logic [ImpW-1:0] cur, newv;
  logic [SumW-1:0] sum;  // two's complement, exact

  assign upd = (op == gicube_pkg::SorterOpAdd) || (op == gicube_pkg::SorterOpSet);

  assign cur = cnt_q[qin*ImpW +: ImpW];

  always_comb begin
    sum = {2'b00, (op == gicube_pkg::SorterOpSet) ? ImpW'(0) : cur} + {val[ValW-1], val};
    if (sum[SumW-1]) begin
      newv = '0;                      // below zero
    end else if (sum[ImpW]) begin
      newv = '1;                      // above ImpMax
    end else begin
      newv = sum[ImpW-1:0];
    end
  end

  // One write port: counter k takes the new value when the item updates queue k.
  for (genvar k = 0; k < Queues; k++) begin : gen_cnt
    assign cnt_d[k*ImpW +: ImpW] = (upd && qin == QueueW'(k)) ? newv : cnt_q[k*ImpW +: ImpW];
  end

  assign impq_d = upd ? newv : cur;

  // ---------------------------------------------------------------------------
  // Classify: the active queue's own update, or a modified importance for another queue
  // ---------------------------------------------------------------------------
  logic hit_active, emptied, touch;

  // For the active queue the counter is also in S[0] (its entry shows the live count), so whether
  // it empties is decided from si_q[0], off the path through the counter read multiplexer.
  logic [SumW-1:0] sum_active;

  assign sum_active = {2'b00, (op == gicube_pkg::SorterOpSet) ? ImpW'(0) : si_q[0 +: ImpW]}
                    + {val[ValW-1], val};
  assign hit_active = upd && sv_q[0] && (sq_q[0 +: QueueW] == qin);
  assign emptied    = hit_active && (sum_active[SumW-1] || sum_active == '0);
  assign touch      = upd && !hit_active;     // wipe the old copy, maybe enter the new importance

  // ---------------------------------------------------------------------------
  // Re-offer: in a slot cycle the scan offers its queue if it is non-empty and not held
  // ---------------------------------------------------------------------------
  logic            slot, scan_held, offer;
  logic [ImpW-1:0] scan_cnt;

  assign scan_cnt = cnt_q[scan_q*ImpW +: ImpW];  // second read port on the counters

  always_comb begin
    scan_held = 1'b0;
    for (int unsigned r = 0; r < Ranks; r++) begin
      scan_held = scan_held || (sv_q[r] && sq_q[r*QueueW +: QueueW] == scan_q)
                            || (cv_q[r] && cq_q[r*QueueW +: QueueW] == scan_q);
    end
  end

  // It would fit: the last rank's selected buffer is empty or holds a smaller importance.
  logic scan_fits;

  assign scan_fits = !sv_q[Ranks-1] || (scan_cnt > si_q[(Ranks-1)*ImpW +: ImpW]);
  assign slot      = !touch && !emptied;
  assign offer     = slot && (scan_cnt != '0) && !scan_held && scan_fits;
  assign scan_d = slot ? scan_q + QueueW'(1) : scan_q;  // wraps at Q = 2^QueueW

  // The token entering C[0]: the update's new importance, or the re-offered queue.
  logic              tok_v;
  logic [QueueW-1:0] tok_q;
  logic [ImpW-1:0]   tok_i;

  assign tok_v = (touch && newv != '0) || offer;
  assign tok_q = touch ? qin  : scan_q;
  assign tok_i = touch ? newv : scan_cnt;

  // ---------------------------------------------------------------------------
  // Every rank: wipe, then compare C[r] with S[r]; open holes pass their entry down
  // ---------------------------------------------------------------------------
  logic [Ranks-1:0]        s_live, c_live;   // valids after the wipe
  logic [Ranks-1:0]        below;            // some buffer below rank r holds an entry
  logic [Ranks-1:0]        hole;             // open hole: S[r] empty with entries below
  logic [Ranks-1:0]        c_wins;           // C[r] takes S'[r]
  logic [Ranks-1:0]        keep_v, down_v;   // S'[r] and the entry D[r] sent down
  logic [Ranks*QueueW-1:0] keep_q, down_q;
  logic [Ranks*ImpW-1:0]   keep_i, down_i;

  always_comb begin
    for (int unsigned r = 0; r < Ranks; r++) begin
      s_live[r] = sv_q[r] && !(touch && sq_q[r*QueueW +: QueueW] == qin);
      c_live[r] = cv_q[r] && !(touch && cq_q[r*QueueW +: QueueW] == qin);
    end
  end

  for (genvar r = 0; r < Ranks; r++) begin : gen_below
    if (r + 1 < Ranks) begin : gen_some
      assign below[r] = |(s_live[Ranks-1:r+1] | c_live[Ranks-1:r+1]);
    end else begin : gen_last
      assign below[r] = 1'b0;
    end
  end

  always_comb begin
    for (int unsigned r = 0; r < Ranks; r++) begin
      hole[r] = (r != 0) && !s_live[r] && below[r];
      if (r == 0) begin
        // S[0] is the active queue (infinite): C[0] takes S'[0] only if S[0] is empty, and
        // otherwise goes down uncompared.
        c_wins[r] = !s_live[r];
        keep_v[r] = s_live[r] || c_live[r];
        down_v[r] = s_live[r] && c_live[r];
      end else if (hole[r]) begin
        c_wins[r] = 1'b0;
        keep_v[r] = 1'b0;
        down_v[r] = c_live[r];
      end else begin
        // Ties keep the incumbent: C wins only when strictly larger.
        c_wins[r] = !s_live[r] || (c_live[r] && ci_q[r*ImpW +: ImpW] > si_q[r*ImpW +: ImpW]);
        keep_v[r] = s_live[r] || c_live[r];
        down_v[r] = s_live[r] && c_live[r];
      end
      keep_q[r*QueueW +: QueueW] = c_wins[r] ? cq_q[r*QueueW +: QueueW] : sq_q[r*QueueW +: QueueW];
      keep_i[r*ImpW +: ImpW]     = c_wins[r] ? ci_q[r*ImpW +: ImpW]     : si_q[r*ImpW +: ImpW];
      // An open hole sends its C down (c_wins is 0 there, so the C data are picked).
      down_q[r*QueueW +: QueueW] = c_wins[r] ? sq_q[r*QueueW +: QueueW] : cq_q[r*QueueW +: QueueW];
      down_i[r*ImpW +: ImpW]     = c_wins[r] ? si_q[r*ImpW +: ImpW]     : ci_q[r*ImpW +: ImpW];
    end
    // The active queue's entry shows its live count; it leaves when that reaches zero.
    if (hit_active) begin
      keep_i[0 +: ImpW] = newv;
    end
    if (emptied) begin
      keep_v[0] = 1'b0;
    end
  end

  // ---------------------------------------------------------------------------
  // Shift up from rank h: rank 0 when S'[0] is empty, else the topmost open hole
  // ---------------------------------------------------------------------------
  logic [Ranks-1:0] closable;  // rank r can be h
  logic [Ranks-1:0] up;        // r >= h: rank r takes the results of rank r + 1
  logic [Ranks-1:0] at_h;      // r == h
  logic             shift, dropped;

  // D[r-1] at position r (nothing comes from above rank 0).
  logic [Ranks-1:0]        above_v;
  logic [Ranks*QueueW-1:0] above_q;
  logic [Ranks*ImpW-1:0]   above_i;

  assign above_v = {down_v[Ranks-2:0], 1'b0};
  assign above_q = {down_q[(Ranks-1)*QueueW-1:0], QueueW'(0)};
  assign above_i = {down_i[(Ranks-1)*ImpW-1:0], ImpW'(0)};

  assign closable = {hole[Ranks-1:1], !keep_v[0]};

  for (genvar r = 0; r < Ranks; r++) begin : gen_up
    assign up[r] = |closable[r:0];
  end

  assign at_h = up & ~{up[Ranks-2:0], 1'b0};

  assign shift   = up[Ranks-1];
  // An entry leaves: off the last rank without a shift, or at the hole when two entries in flight
  // would share its comparison buffer (the one that passed the hole leaves; the scan re-offers it).
  assign dropped = (down_v[Ranks-1] && !shift) || |(at_h & above_v & down_v);

  always_comb begin
    sv_d = '0;
    sq_d = keep_q;
    si_d = keep_i;
    cv_d = '0;
    cq_d = down_q;
    ci_d = down_i;
    for (int unsigned r = 0; r < Ranks; r++) begin
      if (!up[r]) begin
        sv_d[r]                  = keep_v[r];
        sq_d[r*QueueW +: QueueW] = keep_q[r*QueueW +: QueueW];
        si_d[r*ImpW +: ImpW]     = keep_i[r*ImpW +: ImpW];
        cv_d[r]                  = above_v[r];
        cq_d[r*QueueW +: QueueW] = above_q[r*QueueW +: QueueW];
        ci_d[r*ImpW +: ImpW]     = above_i[r*ImpW +: ImpW];
      end else begin
        if (r + 1 < Ranks) begin
          sv_d[r]                  = keep_v[r+1];
          sq_d[r*QueueW +: QueueW] = keep_q[(r+1)*QueueW +: QueueW];
          si_d[r*ImpW +: ImpW]     = keep_i[(r+1)*ImpW +: ImpW];
        end
        if (at_h[r] && above_v[r]) begin
          // The hole's comparison buffer takes the entry from above; D[r], if any, leaves.
          cv_d[r]                  = 1'b1;
          cq_d[r*QueueW +: QueueW] = above_q[r*QueueW +: QueueW];
          ci_d[r*ImpW +: ImpW]     = above_i[r*ImpW +: ImpW];
        end else begin
          cv_d[r]                  = down_v[r];
          cq_d[r*QueueW +: QueueW] = down_q[r*QueueW +: QueueW];
          ci_d[r*ImpW +: ImpW]     = down_i[r*ImpW +: ImpW];
        end
      end
    end
    // The token enters C[0] (never together with D[0], which reaches C[0] only in the cycle
    // the active queue empties: no update token then, and not a slot cycle).
    if (tok_v) begin
      cv_d[0]           = 1'b1;
      cq_d[0 +: QueueW] = tok_q;
      ci_d[0 +: ImpW]   = tok_i;
    end
  end

  // ---------------------------------------------------------------------------
  // Registers: valids, counters, the scan pointer and the output valid reset; datapath not
  // ---------------------------------------------------------------------------
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      out_valid_q <= 1'b0;
      sv_q        <= '0;
      cv_q        <= '0;
      cnt_q       <= '0;
      scan_q      <= '0;
    end else begin
      out_valid_q <= out_valid_d;
      if (in_fire) begin
        sv_q   <= sv_d;
        cv_q   <= cv_d;
        cnt_q  <= cnt_d;
        scan_q <= scan_d;
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (in_fire) begin
      sq_q      <= sq_d;
      si_q      <= si_d;
      cq_q      <= cq_d;
      ci_q      <= ci_d;
      emptied_q <= emptied;
      shifted_q <= shift;
      dropped_q <= dropped;
      offered_q <= offer;
      impq_q    <= impq_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Output: the registered state, empty buffers as zeros
  // ---------------------------------------------------------------------------
  logic [OutW-1:0] state;

  always_comb begin
    state = '0;
    state[0] = emptied_q;
    state[1] = shifted_q;
    state[2] = dropped_q;
    state[3] = offered_q;
    state[4 +: ImpW] = impq_q;
    state[4 + ImpW +: QueueW] = scan_q;
    for (int unsigned r = 0; r < Ranks; r++) begin
      state[RankLsb + (2*r)*EntryW +: EntryW] =
          sv_q[r] ? {si_q[r*ImpW +: ImpW], sq_q[r*QueueW +: QueueW], 1'b1} : '0;
      state[RankLsb + (2*r+1)*EntryW +: EntryW] =
          cv_q[r] ? {ci_q[r*ImpW +: ImpW], cq_q[r*QueueW +: QueueW], 1'b1} : '0;
    end
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = state;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3). Written as immediate assertions (on a
  // registered copy) rather than with $stable: the C++ that Verilator 5.006 emits for sampling a
  // signal this wide (1555 bits at r32, or the 2048 counter bits) in a concurrent assertion does
  // not compile.
  logic            stalled_q;
  logic [OutW-1:0] stalled_data_q;

  always_ff @(posedge clk_i) begin
    stalled_q      <= rst_ni && out_valid_o && !out_ready_i;
    stalled_data_q <= out_data_o;
  end

  always_ff @(posedge clk_i) begin
    if (rst_ni && stalled_q) begin
      OutputHoldsWhileStalled: assert (out_valid_o && out_data_o == stalled_data_q)
        else $error("gicube_sorter: output changed while stalled");
    end
    // The active entry's importance is its counter (the emptied decision above relies on it).
    if (rst_ni && sv_q[0]) begin
      ActiveEntryShowsItsCounter: assert (si_q[0 +: ImpW] == cnt_q[sq_q[0 +: QueueW]*ImpW +: ImpW])
        else $error("gicube_sorter: S[0] importance differs from its counter");
    end
  end

  // D[0] reaches C[0] only in the cycle the active queue empties, which makes no token.
  TokenNeverMeetsShiftedEntry: assert property (@(posedge clk_i) disable iff (!rst_ni)
      in_fire |-> !(up[0] && down_v[0] && tok_v))
    else $error("gicube_sorter: a token and a shifted-up entry collide in C[0]");

  // An active queue is never wiped: its updates make no token.
  ActiveQueueNeverWiped: assert property (@(posedge clk_i) disable iff (!rst_ni)
      in_fire && sv_q[0] |-> s_live[0])
    else $error("gicube_sorter: the active queue was wiped");

  // The scan only offers a queue that no buffer holds: every queue is held at most once.
  OfferIsNotHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      in_fire && offer |-> !touch && !scan_held)
    else $error("gicube_sorter: the scan offered a queue that is held");
`endif

endmodule
