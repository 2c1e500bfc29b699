// cube5_axi_split: the AXI4 burst splitter shared by cube5_axi_rd and cube5_axi_wr
// (docs/numerics/axi_rd.md, axi_wr.md). Cuts a command (bus-aligned start address, length in beats)
// into INCR bursts of at most MaxBurst beats that never cross a 4 KB boundary, and drives the
// address channel (AR or AW).
//
// Two stages, so the burst-length arithmetic and the parent's issue check are not one path: the
// splitter plans the next burst of the current command into the plan register; the plan is issued
// (loaded into the A register) when the A register is free and the parent's `may_issue_i` holds
// (read: return-FIFO credits and the outstanding count; write: W-buffer beats and the outstanding
// count). `issue_o` and the plan outputs let the parent account for the issued burst.
//
//   command ─► splitter (cur_addr, beats left) ─► plan register ─► A register ─► A channel
module cube5_axi_split #(
  /// Byte address width (13 .. 64).
  parameter int unsigned AddrW = 32,
  /// log2 of the bytes per bus beat.
  parameter int unsigned SizeW = 3,
  /// Bits of a command's length in beats.
  parameter int unsigned BeatsW = 16,
  /// Longest burst in beats: a power of two, 2 .. 256, and MaxBurst << SizeW <= 4096.
  parameter int unsigned MaxBurst = 16,
  /// Width of a burst length: $clog2(MaxBurst) + 1 (1 .. MaxBurst).
  parameter int unsigned BurstW = $clog2(MaxBurst) + 1
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// The splitter can take a command this cycle (idle, or planning its last burst now).
  output logic take_o,
  /// The parent takes a command this cycle (only while take_o).
  input  logic cmd_fire_i,
  /// The command's start address, aligned to the bus.
  input  logic [AddrW-1:0] cmd_addr_i,
  /// The command's beats (ignored when cmd_any_i is low).
  input  logic [BeatsW-1:0] cmd_beats_i,
  /// The command has beats to transfer (0 = nothing: the splitter stays idle).
  input  logic cmd_any_i,

  /// The parent allows the planned burst to issue (its resources hold plan_len_o beats).
  input  logic may_issue_i,
  /// The planned burst is issued this cycle (loaded into the A register).
  output logic issue_o,
  /// Beats of the planned burst (1 .. MaxBurst).
  output logic [BurstW-1:0] plan_len_o,
  /// The planned burst ends its command.
  output logic plan_last_o,

  /// A channel: burst start address.
  output logic [AddrW-1:0] a_addr_o,
  /// A channel: beats in the burst minus one.
  output logic [7:0] a_len_o,
  /// A channel: address valid.
  output logic a_valid_o,
  /// A channel: the subordinate takes the address.
  input  logic a_ready_i
);

  localparam int unsigned MbW  = $clog2(MaxBurst);  // low address bits inside a MaxBurst span
  // Remaining beats, at least one bit wider than a burst length (for the split compare below).
  localparam int unsigned RemW = (BeatsW > BurstW) ? BeatsW : BurstW + 1;

  logic             active_q, active_d;
  logic [AddrW-1:0] cur_addr_q, cur_addr_d;
  logic [RemW-1:0]  rem_q, rem_d;

  logic              plan_valid_q, plan_valid_d;
  logic [AddrW-1:0]  plan_addr_q, plan_addr_d;
  logic [BurstW-1:0] plan_len_q, plan_len_d;
  logic              plan_last_q, plan_last_d;

  logic [AddrW-1:0] aaddr_q, aaddr_d;
  logic [7:0]       alen_q, alen_d;
  logic             avalid_q, avalid_d;

  // This burst's cap: MaxBurst, or the beats to the 4 KB boundary when that is nearer, i.e. when
  // the address lies in the last MaxBurst-beat span below the boundary but not at its start.
  logic [BurstW-1:0] cap, blen;
  logic [MbW-1:0]    span_off;   // beat offset inside the MaxBurst span
  logic              last_span;  // the span ends at the 4 KB boundary
  assign span_off = cur_addr_q[SizeW+MbW-1:SizeW];
  if (SizeW + MbW < 12) begin : gen_last_span
    assign last_span = (cur_addr_q[11:SizeW+MbW] == '1);
  end else begin : gen_one_span
    assign last_span = 1'b1;  // MaxBurst beats are 4 KB: every span ends at a boundary
  end
  // For clock rate the comparison with the cap is split: the high bits of the remaining count
  // (zero or not) in parallel with a BurstW-bit compare of its low bits.
  logic              rem_hi_zero, rem_fits;
  logic [BurstW-1:0] rem_lo;
  assign rem_lo      = rem_q[BurstW-1:0];
  assign rem_hi_zero = ((rem_q >> BurstW) == '0);
  // Every quantity below is computed for both caps (MaxBurst, and the beats to the boundary) from
  // registers, and `capped` selects: no adder or compare waits for the cap's multiplexer.
  logic              capped;     // the burst stops at the 4 KB boundary short of MaxBurst
  logic [BurstW-1:0] cap_b;      // the beats to the boundary, MaxBurst - span_off
  logic              fits_m, fits_b;
  always_comb begin
    capped   = last_span && span_off != '0;
    cap_b    = BurstW'(MaxBurst) - BurstW'(span_off);
    fits_m   = (rem_lo <= BurstW'(MaxBurst));
    fits_b   = ((BurstW + 1)'(rem_lo) + (BurstW + 1)'(span_off)
                <= (BurstW + 1)'(MaxBurst));          // rem_lo <= cap_b, with no subtraction
    cap      = capped ? cap_b : BurstW'(MaxBurst);
    rem_fits = rem_hi_zero && (capped ? fits_b : fits_m);  // this burst ends the command
    blen     = rem_fits ? rem_lo : cap;
  end
  // The next burst's address is the current one advanced by the cap: its span number plus one,
  // with the beat offset inside the span kept, or cleared when the cap is the boundary's (the
  // address lands on the boundary). The bytes below a beat are kept either way.
  logic [AddrW-1:0] next_addr;
  // The beats left after the burst: rem - MaxBurst (the count of spans less one, the offset
  // kept), or rem - (MaxBurst - span_off) = rem - MaxBurst + span_off, whose low bits are a small
  // sum and whose high bits are rem's or rem - MaxBurst's, as that sum carries.
  logic [RemW-1:0]  rem_m, rem_b;
  logic [MbW:0]     lo_sum;
  always_comb begin
    next_addr = cur_addr_q + (AddrW'(1) << (SizeW + MbW));
    if (capped) next_addr[SizeW+MbW-1:SizeW] = '0;
    rem_m  = rem_q - RemW'(MaxBurst);
    lo_sum = {1'b0, rem_q[MbW-1:0]} + {1'b0, span_off};
    rem_b  = {lo_sum[MbW] ? rem_q[RemW-1:MbW] : rem_m[RemW-1:MbW], lo_sum[MbW-1:0]};
  end

  logic a_free, issue, plan_fill, plan_fill_last;
  assign a_free         = !avalid_q || a_ready_i;
  assign issue          = plan_valid_q && a_free && may_issue_i;
  assign plan_fill      = active_q && (!plan_valid_q || issue);
  assign plan_fill_last = plan_fill && rem_fits;

  assign take_o = !active_q || plan_fill_last;

  always_comb begin
    active_d     = active_q;
    cur_addr_d   = cur_addr_q;
    rem_d        = rem_q;
    plan_valid_d = plan_valid_q && !issue;
    plan_addr_d  = plan_addr_q;
    plan_len_d   = plan_len_q;
    plan_last_d  = plan_last_q;
    aaddr_d      = aaddr_q;
    alen_d       = alen_q;
    avalid_d     = avalid_q && !a_ready_i;
    if (issue) begin
      aaddr_d  = plan_addr_q;
      alen_d   = 8'(plan_len_q) - 8'd1;  // MaxBurst = 256 wraps to 255 as it should
      avalid_d = 1'b1;
    end
    if (plan_fill) begin
      plan_valid_d = 1'b1;
      plan_addr_d  = cur_addr_q;
      plan_len_d   = blen;
      plan_last_d  = plan_fill_last;
      // Advanced by the cap, not blen: after a command's last burst both are dead (active_q
      // drops), and before it blen = cap; so the cap's mux stays off these adders' path.
      cur_addr_d   = next_addr;
      rem_d        = capped ? rem_b : rem_m;
      if (plan_fill_last) active_d = 1'b0;
    end
    if (cmd_fire_i) begin
      active_d   = cmd_any_i;
      cur_addr_d = cmd_addr_i;
      rem_d      = RemW'(cmd_beats_i);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      active_q     <= 1'b0;
      plan_valid_q <= 1'b0;
      avalid_q     <= 1'b0;
    end else begin
      active_q     <= active_d;
      plan_valid_q <= plan_valid_d;
      avalid_q     <= avalid_d;
    end
  end

  // Datapath: no reset (qualified by active_q / plan_valid_q / avalid_q).
  always_ff @(posedge clk_i) begin
    cur_addr_q  <= cur_addr_d;
    rem_q       <= rem_d;
    plan_addr_q <= plan_addr_d;
    plan_len_q  <= plan_len_d;
    plan_last_q <= plan_last_d;
    aaddr_q     <= aaddr_d;
    alen_q      <= alen_d;
  end

  assign issue_o     = issue;
  assign plan_len_o  = plan_len_q;
  assign plan_last_o = plan_last_q;
  assign a_addr_o    = aaddr_q;
  assign a_len_o     = alen_q;
  assign a_valid_o   = avalid_q;

endmodule
