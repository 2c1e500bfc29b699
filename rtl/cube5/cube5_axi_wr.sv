// cube5_axi_wr: AXI4 burst write manager (issue 12; docs/numerics/axi_wr.md). Takes write commands
// (byte address aligned to an item, length in items) and a stream of items (ItemW bits each),
// packs the items into bus beats at their byte lanes (WSTRB marks the lanes a command covers, so
// a first or last beat may be partial), splits each command into INCR bursts of at most MaxBurst
// beats that never cross a 4 KB boundary, keeps up to Outstanding bursts in flight, and reports
// each command's completion (all of its B responses received) in command order with the first
// non-OKAY BRESP among its bursts and a running count.
//
// Data before address: a burst's AW is issued only when all of its beats wait in the W buffer, so
// the W channel never waits for the item stream inside a burst. The W buffer is one write port
// and one registered read port with no reset on the array (block RAM or LUT RAM).
//
//   command ─► cube5_axi_split (splitter ─► plan register ─► AW register) ─► AW channel
//          └─► packer command FIFO (lane, items) ─┐      │ burst lengths ─► WLAST count
//   items ─► packer (lane, strobes) ─► W buffer (RAM) ─► read register ─► W channel
//   B channel ─► {last-of-command per burst} ─► completion register ─► out {count, resp}
`include "cube5_axi_ports.svh"

module cube5_axi_wr #(
  /// Byte address width of the AXI port (13 .. 64).
  parameter int unsigned AddrW = 32,
  /// Data bus width in bits: 8 .. 1024, a power of two.
  parameter int unsigned DataW = 64,
  /// Item width in bits: a power of two, 8 .. DataW.
  parameter int unsigned ItemW = 32,
  /// Bits of a command's length in items (1 .. 32).
  parameter int unsigned LenW = 16,
  /// Longest burst in beats: a power of two, 2 .. 256, and MaxBurst * DataW / 8 <= 4096.
  parameter int unsigned MaxBurst = 16,
  /// Bursts in flight (issued, B not yet received) at most: a power of two >= 2.
  parameter int unsigned Outstanding = 4,
  /// AWID / BID width (the unit issues ID 0 only: responses come back in order).
  parameter int unsigned IdW = 4
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Command valid.
  input  logic in_valid_i,
  /// The unit takes a command this cycle.
  output logic in_ready_o,
  /// addr (AddrW, aligned to ItemW/8 bytes), len (LenW, items; 0 = nothing), LSB first.
  input  logic [AddrW+LenW-1:0] in_data_i,

  /// Item valid.
  input  logic dat_valid_i,
  /// The unit takes an item this cycle.
  output logic dat_ready_o,
  /// One item: its byte at the lowest address in bits 7:0.
  input  logic [ItemW-1:0] dat_data_i,

  /// Completion valid.
  output logic out_valid_o,
  /// Consumer takes the completion this cycle.
  input  logic out_ready_i,
  /// resp (2: first non-OKAY BRESP of the command's bursts, else OKAY), count (16: commands
  /// completed since reset, this one included, mod 2^16), LSB first.
  output logic [17:0] out_data_o,

  /// Sticky: some B response since reset was not OKAY.
  output logic err_o,

  // AXI4 write channels: ID 0 only (responses in order); bursts start aligned to the bus;
  // bytes whose strobe is 0 are unspecified; BREADY low only while a completion waits for
  // the consumer.
  `CUBE5_AXI4_WR_MGR_PORTS(m_axi_, AddrW, DataW, IdW)
);

  // ==============================================================================================
  // Derived sizes
  // ==============================================================================================

  localparam int unsigned Bytes      = DataW / 8;
  localparam int unsigned SizeW      = $clog2(Bytes);
  localparam int unsigned IBytes     = ItemW / 8;
  localparam int unsigned ISizeW     = $clog2(IBytes);
  localparam int unsigned Lanes      = DataW / ItemW;       // items per beat
  localparam int unsigned LaneBits   = $clog2(Lanes);       // 0 when an item fills the bus
  localparam int unsigned LaneW      = (LaneBits > 0) ? LaneBits : 1;
  localparam int unsigned BeatsPer4k = 4096 / Bytes;
  localparam int unsigned Depth      = 2 * MaxBurst;        // W buffer beats
  localparam int unsigned PtrW       = $clog2(Depth);
  localparam int unsigned CntW       = $clog2(Depth) + 1;
  localparam int unsigned OPtrW      = $clog2(Outstanding);
  localparam int unsigned OCntW      = $clog2(Outstanding) + 1;
  localparam int unsigned BurstW     = $clog2(MaxBurst) + 1; // 1 .. MaxBurst
  // A command's beats (<= 2^LenW), at least one bit wider than a burst length.
  localparam int unsigned NbW        = (LenW > BurstW) ? LenW + 1 : BurstW + 1;
  localparam int unsigned WordW      = DataW + Bytes;       // {strb, data}
  localparam int unsigned SpanW      = LenW + LaneBits + 1; // lane + items + Lanes - 1
  localparam int unsigned PkW        = 1 + LaneW + LenW;    // packer command {one, items, lane}

  if (DataW < 8 || DataW > 1024 || (1 << $clog2(DataW)) != DataW) begin : gen_bad_data_w
    $fatal(1, "cube5_axi_wr: DataW must be a power of two in 8..1024");
  end
  if (ItemW < 8 || ItemW > DataW || (1 << $clog2(ItemW)) != ItemW) begin : gen_bad_item_w
    $fatal(1, "cube5_axi_wr: ItemW must be a power of two in 8..DataW");
  end
  if (MaxBurst < 2 || MaxBurst > 256 || (1 << $clog2(MaxBurst)) != MaxBurst
      || MaxBurst > BeatsPer4k) begin : gen_bad_max_burst
    $fatal(1, "cube5_axi_wr: MaxBurst must be a power of two in 2..256 with MaxBurst * DataW/8 <= 4096");
  end
  if (Outstanding < 2 || (1 << $clog2(Outstanding)) != Outstanding) begin : gen_bad_outstanding
    $fatal(1, "cube5_axi_wr: Outstanding must be a power of two >= 2");
  end
  if (AddrW < 13 || AddrW > 64) begin : gen_bad_addr_w
    $fatal(1, "cube5_axi_wr: AddrW must be in 13..64");
  end
  if (LenW < 1 || LenW > 32) begin : gen_bad_len_w
    $fatal(1, "cube5_axi_wr: LenW must be in 1..32");
  end
  if (IdW < 1 || IdW > 32) begin : gen_bad_id_w
    $fatal(1, "cube5_axi_wr: IdW must be in 1..32");
  end

  // ==============================================================================================
  // Command intake: beats of the command, its first lane
  // ==============================================================================================

  logic             in_fire;
  logic [AddrW-1:0] in_addr, in_beat_addr;
  logic [LenW-1:0]  in_len;
  logic [LaneW-1:0] in_lane;
  logic [NbW-1:0]   in_beats;
  assign in_addr = in_data_i[AddrW-1:0];
  assign in_len  = in_data_i[AddrW+LenW-1:AddrW];
  // The address rounded down to the bus. (A concatenation: Yosys 0.23 reads `~N'(v)` as
  // `(~N)'(v)`, docs/architecture.md "RTL conventions", and dropped the mask in the netlist.)
  if (SizeW > 0) begin : gen_beat_addr
    assign in_beat_addr = {in_addr[AddrW-1:SizeW], {SizeW{1'b0}}};
  end else begin : gen_byte_bus
    assign in_beat_addr = in_addr;
  end
  if (LaneBits > 0) begin : gen_lane
    assign in_lane = in_addr[SizeW-1:ISizeW];
    if (ISizeW > 0) begin : gen_item_low
      logic unused_in_low;  // item-aligned: the bits below an item are ignored
      assign unused_in_low = ^in_addr[ISizeW-1:0];
    end
  end else begin : gen_one_lane
    assign in_lane = 1'b0;
    if (SizeW > 0) begin : gen_item_low
      logic unused_in_low;  // an item fills the beat: the bits below it are ignored
      assign unused_in_low = ^in_addr[SizeW-1:0];
    end
  end
  // Beats = ceil((lane + items) / Lanes).
  logic [SpanW-1:0] in_span, in_span_beats;
  assign in_span       = SpanW'(in_lane) + SpanW'(in_len) + (SpanW'(Lanes) - SpanW'(1));
  assign in_span_beats = in_span >> LaneBits;
  assign in_beats      = NbW'(in_span_beats);
  logic unused_span_hi;  // the shift's top bits are zero: a command has at most 2^LenW beats
  assign unused_span_hi = ^in_span_beats;

  // ==============================================================================================
  // Burst splitter, plan register and AW register (cube5_axi_split)
  // ==============================================================================================

  logic [CntW-1:0]  avail_q, avail_d;    // W-buffer beats not yet claimed by an issued burst
  logic [CntW-1:0]  claimed_add;         // the burst issued this cycle's beats, or 0
  logic [OCntW-1:0] bursts_q, bursts_d;  // bursts issued whose B has not been taken

  logic              in_any, split_take, may_issue, issue, plan_last;
  logic [BurstW-1:0] plan_len;
  assign in_any    = (in_len != '0);
  assign may_issue = (avail_q >= CntW'(plan_len)) && (bursts_q < OCntW'(Outstanding));

  cube5_axi_split #(
    .AddrW   (AddrW),
    .SizeW   (SizeW),
    .BeatsW  (NbW),
    .MaxBurst(MaxBurst)
  ) u_split (
    .clk_i      (clk_i),
    .rst_ni     (rst_ni),
    .take_o     (split_take),
    .cmd_fire_i (in_fire),
    .cmd_addr_i (in_beat_addr),
    .cmd_beats_i(in_beats),
    .cmd_any_i  (in_any),
    .may_issue_i(may_issue),
    .issue_o    (issue),
    .plan_len_o (plan_len),
    .plan_last_o(plan_last),
    .a_addr_o   (m_axi_awaddr_o),
    .a_len_o    (m_axi_awlen_o),
    .a_valid_o  (m_axi_awvalid_o),
    .a_ready_i  (m_axi_awready_i)
  );

  assign m_axi_awsize_o  = 3'(SizeW);
  assign m_axi_awburst_o = 2'b01;
  assign m_axi_awid_o    = '0;

  // Packer command FIFO (two entries, flops): room decides whether a command is taken.
  logic [PkW-1:0] pk_mem_q [2];
  logic [1:0]     pk_cnt_q, pk_cnt_d;
  logic           pk_wr_q, pk_wr_d, pk_rd_q, pk_rd_d;
  logic           pk_push, pk_pop;

  assign in_ready_o = split_take && (pk_cnt_q != 2'd2);
  assign in_fire    = in_valid_i && in_ready_o;
  assign pk_push    = in_fire && in_any;

  // ==============================================================================================
  // Packer: items to beats at their lanes, into the W buffer
  // ==============================================================================================

  logic             pk_busy_q, pk_busy_d;  // lane/left hold the head command's progress
  logic [LaneW-1:0] lane_q, lane_d, cur_lane;
  logic [LenW-1:0]  left_q, left_d, cur_left;
  logic             one_q, one_d, cur_one;   // one item left (kept as a flag for clock rate)
  logic [DataW-1:0] pk_data_q, pk_data_d, merged;
  logic [Bytes-1:0] pk_strb_q, pk_strb_d, merged_strb;
  logic             beat_done, dat_fire, ram_full;
  logic [CntW-1:0]  count_q, count_d;      // beats in the W buffer

  assign cur_lane  = pk_busy_q ? lane_q : pk_mem_q[pk_rd_q][LaneW-1:0];
  assign cur_left  = pk_busy_q ? left_q : pk_mem_q[pk_rd_q][LaneW+LenW-1:LaneW];
  assign cur_one   = pk_busy_q ? one_q : pk_mem_q[pk_rd_q][PkW-1];
  assign ram_full  = (count_q == CntW'(Depth));
  assign beat_done = (cur_lane == LaneW'(Lanes - 1)) || cur_one;
  assign dat_ready_o = (pk_cnt_q != 2'd0) && !(beat_done && ram_full);
  assign dat_fire  = dat_valid_i && dat_ready_o;
  assign pk_pop    = dat_fire && cur_one;

  always_comb begin
    merged      = pk_data_q;
    merged_strb = pk_strb_q;
    for (int unsigned l = 0; l < Lanes; l++) begin
      if (cur_lane == LaneW'(l)) begin
        merged[l*ItemW +: ItemW]       = dat_data_i;
        merged_strb[l*IBytes +: IBytes] = '1;
      end
    end
  end

  always_comb begin
    pk_busy_d = pk_busy_q;
    lane_d    = lane_q;
    left_d    = left_q;
    one_d     = one_q;
    pk_data_d = pk_data_q;
    pk_strb_d = pk_strb_q;
    if (dat_fire) begin
      pk_busy_d = !pk_pop;
      lane_d    = (cur_lane == LaneW'(Lanes - 1)) ? '0 : cur_lane + LaneW'(1);
      left_d    = cur_left - LenW'(1);
      one_d     = (cur_left == LenW'(2));
      pk_data_d = merged;
      pk_strb_d = beat_done ? '0 : merged_strb;
    end
  end

  always_comb begin
    pk_cnt_d = pk_cnt_q + 2'(pk_push) - 2'(pk_pop);
    pk_wr_d  = pk_push ? !pk_wr_q : pk_wr_q;
    pk_rd_d  = pk_pop ? !pk_rd_q : pk_rd_q;
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      pk_busy_q <= 1'b0;
      pk_cnt_q  <= '0;
      pk_wr_q   <= 1'b0;
      pk_rd_q   <= 1'b0;
      pk_strb_q <= '0;
    end else begin
      pk_busy_q <= pk_busy_d;
      pk_cnt_q  <= pk_cnt_d;
      pk_wr_q   <= pk_wr_d;
      pk_rd_q   <= pk_rd_d;
      pk_strb_q <= pk_strb_d;
    end
  end

  always_ff @(posedge clk_i) begin
    lane_q    <= lane_d;
    left_q    <= left_d;
    one_q     <= one_d;
    pk_data_q <= pk_data_d;
    if (pk_push) pk_mem_q[pk_wr_q] <= {in_len == LenW'(1), in_len, in_lane};
  end

  // ==============================================================================================
  // W buffer (RAM), WLAST count and the W register
  // ==============================================================================================

  logic [WordW-1:0]  mem_q [Depth];
  logic [WordW-1:0]  rd_q;
  logic [PtrW-1:0]   wr_q, wr_d, rd_ptr_q, rd_ptr_d;
  logic              ram_we, ren;
  logic [CntW-1:0]   claimed_q, claimed_d;  // W-buffer beats of issued bursts, not yet read
  logic              claimed_nz_q, claimed_nz_d;  // claimed_q != 0, kept as a flag for ren
  logic              wvalid_q, wvalid_d, wlast_q, wlast_d;
  logic [BurstW-1:0] blq_q [Outstanding];   // beats of each issued burst, for WLAST
  logic [OPtrW-1:0]  blq_wr_q, blq_wr_d, blq_rd_q, blq_rd_d;
  logic [BurstW-1:0] wbeat_q, wbeat_d;      // beats of the head burst already read
  logic              rd_last;

  assign ram_we  = dat_fire && beat_done;
  assign ren     = claimed_nz_q && (!wvalid_q || m_axi_wready_i);
  assign rd_last = (wbeat_q + BurstW'(1) == blq_q[blq_rd_q]);

  always_comb begin
    claimed_add = issue ? CntW'(plan_len) : CntW'(0);
    wr_d      = ram_we ? wr_q + PtrW'(1) : wr_q;
    rd_ptr_d  = ren ? rd_ptr_q + PtrW'(1) : rd_ptr_q;
    count_d   = count_q + CntW'(ram_we) - CntW'(ren);
    // ram_we (behind the packer's lane decode) selects last, between sums that do not wait for it.
    avail_d   = avail_q - claimed_add;
    if (ram_we) avail_d = avail_q - claimed_add + CntW'(1);
    // ren selects last, between sums that do not wait for it; plan_len >= 1 and ren implies
    // claimed_q >= 1, so the count is nonzero after an issue, and after a read unless it was 1.
    claimed_d    = ren ? claimed_q + claimed_add - CntW'(1) : claimed_q + claimed_add;
    claimed_nz_d = issue || (ren ? (claimed_q != CntW'(1)) : claimed_nz_q);
    wvalid_d  = ren || (wvalid_q && !m_axi_wready_i);
    wlast_d   = ren ? rd_last : wlast_q;
    wbeat_d   = wbeat_q;
    blq_rd_d  = blq_rd_q;
    if (ren) begin
      wbeat_d = rd_last ? '0 : wbeat_q + BurstW'(1);
      if (rd_last) blq_rd_d = blq_rd_q + OPtrW'(1);
    end
    blq_wr_d = issue ? blq_wr_q + OPtrW'(1) : blq_wr_q;
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      wr_q      <= '0;
      rd_ptr_q  <= '0;
      count_q   <= '0;
      avail_q   <= '0;
      claimed_q <= '0;
      claimed_nz_q <= 1'b0;
      wvalid_q  <= 1'b0;
      wbeat_q   <= '0;
      blq_wr_q  <= '0;
      blq_rd_q  <= '0;
    end else begin
      wr_q      <= wr_d;
      rd_ptr_q  <= rd_ptr_d;
      count_q   <= count_d;
      avail_q   <= avail_d;
      claimed_q <= claimed_d;
      claimed_nz_q <= claimed_nz_d;
      wvalid_q  <= wvalid_d;
      wbeat_q   <= wbeat_d;
      blq_wr_q  <= blq_wr_d;
      blq_rd_q  <= blq_rd_d;
    end
  end

  always_ff @(posedge clk_i) begin
    wlast_q <= wlast_d;
    if (issue) blq_q[blq_wr_q] <= plan_len;
  end

  // The RAM: one write port, one registered read port with enable, no reset.
  always_ff @(posedge clk_i) begin
    if (ram_we) mem_q[wr_q] <= {merged_strb, merged};
  end
  always_ff @(posedge clk_i) begin
    if (ren) rd_q <= mem_q[rd_ptr_q];
  end

  assign m_axi_wdata_o  = rd_q[DataW-1:0];
  assign m_axi_wstrb_o  = rd_q[WordW-1:DataW];
  assign m_axi_wlast_o  = wlast_q;
  assign m_axi_wvalid_o = wvalid_q;

  // ==============================================================================================
  // B responses: per-burst last-of-command flags, completions
  // ==============================================================================================

  logic [Outstanding-1:0] info_q, info_d;
  logic [OPtrW-1:0]       info_wr_q, info_wr_d, info_rd_q, info_rd_d;
  logic                   b_fire, b_ends_cmd;
  logic [1:0]             acc_resp, cmd_resp_q, cmd_resp_d;
  logic                   out_valid_q, out_valid_d;
  logic [1:0]             out_resp_q, out_resp_d;
  logic [15:0]            done_q, done_d;
  logic                   err_q, err_d;

  assign b_ends_cmd     = info_q[info_rd_q];
  assign m_axi_bready_o = !(out_valid_q && b_ends_cmd);
  assign b_fire         = m_axi_bvalid_i && m_axi_bready_o;
  assign acc_resp       = (cmd_resp_q != 2'b00) ? cmd_resp_q : m_axi_bresp_i;

  always_comb begin
    info_d      = info_q;
    info_wr_d   = info_wr_q;
    info_rd_d   = info_rd_q;
    cmd_resp_d  = cmd_resp_q;
    out_valid_d = out_valid_q && !out_ready_i;
    out_resp_d  = out_resp_q;
    done_d      = done_q;
    // A decoded write (an indexed one became a 32-bit compare chain in synth_ecp5).
    for (int unsigned i = 0; i < Outstanding; i++) begin
      if (issue && info_wr_q == OPtrW'(i)) info_d[i] = plan_last;
    end
    if (issue) info_wr_d = info_wr_q + OPtrW'(1);
    if (b_fire) begin
      info_rd_d  = info_rd_q + OPtrW'(1);
      cmd_resp_d = acc_resp;
      if (b_ends_cmd) begin
        cmd_resp_d  = 2'b00;
        out_valid_d = 1'b1;
        out_resp_d  = acc_resp;
        done_d      = done_q + 16'd1;
      end
    end
    bursts_d = bursts_q + OCntW'(issue) - OCntW'(b_fire);
    err_d    = err_q || (b_fire && m_axi_bresp_i != 2'b00);
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      info_wr_q   <= '0;
      info_rd_q   <= '0;
      cmd_resp_q  <= 2'b00;
      out_valid_q <= 1'b0;
      done_q      <= '0;
      bursts_q    <= '0;
      err_q       <= 1'b0;
    end else begin
      info_wr_q   <= info_wr_d;
      info_rd_q   <= info_rd_d;
      cmd_resp_q  <= cmd_resp_d;
      out_valid_q <= out_valid_d;
      done_q      <= done_d;
      bursts_q    <= bursts_d;
      err_q       <= err_d;
    end
  end

  always_ff @(posedge clk_i) begin
    info_q     <= info_d;
    out_resp_q <= out_resp_d;
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = {done_q, out_resp_q};
  assign err_o       = err_q;

  logic unused_bid;
  assign unused_bid = ^m_axi_bid_i;

`ifndef SYNTHESIS
  // A stalled completion holds (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_axi_wr: completion changed while stalled");
  // AW and W hold their payload until taken (AXI4 A3.2.1).
  AwHoldsUntilReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      m_axi_awvalid_o && !m_axi_awready_i |=> m_axi_awvalid_o
      && $stable(m_axi_awaddr_o) && $stable(m_axi_awlen_o))
    else $error("cube5_axi_wr: AW changed while stalled");
  WHoldsUntilReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      m_axi_wvalid_o && !m_axi_wready_i |=> m_axi_wvalid_o && $stable(m_axi_wdata_o)
      && $stable(m_axi_wstrb_o) && $stable(m_axi_wlast_o))
    else $error("cube5_axi_wr: W changed while stalled");
  // The W buffer never overflows: a beat is written only with room.
  WBufferNeverOverflows: assert property (@(posedge clk_i) disable iff (!rst_ni)
      ram_we |-> count_q < CntW'(Depth))
    else $error("cube5_axi_wr: a beat written into a full W buffer");
  // The read enable's flag is the count's.
  ClaimedFlagIsCount: assert property (@(posedge clk_i) disable iff (!rst_ni)
      claimed_nz_q == (claimed_q != '0))
    else $error("cube5_axi_wr: claimed_nz_q disagrees with claimed_q");
  // Every B belongs to a burst in flight.
  NoResponseWithoutBurst: assert property (@(posedge clk_i) disable iff (!rst_ni)
      b_fire |-> bursts_q != '0)
    else $error("cube5_axi_wr: a B response with no burst outstanding");
`endif

endmodule
