// cube5_axi_rd: AXI4 burst read manager (issue 12; docs/numerics/axi_rd.md). Takes read commands
// (byte address aligned to the data bus, length in beats), splits each into INCR bursts of at most
// MaxBurst beats that never cross a 4 KB boundary, keeps up to Outstanding bursts in flight, and
// streams the returned beats out in command order with a last-of-command flag and the beat's RRESP.
//
// Credit rule: a burst is issued only when the return FIFO has room for all of its beats (beats in
// flight + beats held <= FifoDepth = MaxBurst * Outstanding), so RREADY is tied high and a slow
// consumer never stalls the bus. The FIFO is one write port and one registered read port with no
// reset on the array, so synth_ecp5 maps it to block RAM (DP16KD).
//
//   command ─► cube5_axi_split (splitter ─► plan register ─► AR register) ─► AR channel
//                                     last-of-command flag per burst ─► info FIFO (Outstanding) ─┐
//   R channel (RREADY = 1) ─► {resp, last, data} ─► return FIFO (RAM) ─► read register ─► out
`include "cube5_axi_ports.svh"

module cube5_axi_rd #(
  /// Byte address width of the AXI port (>= 13).
  parameter int unsigned AddrW = 32,
  /// Data bus width in bits: 8 .. 1024, a power of two.
  parameter int unsigned DataW = 64,
  /// Bits of a command's length in beats.
  parameter int unsigned LenW = 16,
  /// Longest burst in beats: a power of two, 2 .. 256, and MaxBurst * DataW / 8 <= 4096.
  parameter int unsigned MaxBurst = 16,
  /// Bursts in flight at most: a power of two >= 2.
  parameter int unsigned Outstanding = 4,
  /// ARID / RID width (the unit issues ID 0 only: responses come back in order).
  parameter int unsigned IdW = 4
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Command valid.
  input  logic in_valid_i,
  /// The unit takes a command this cycle.
  output logic in_ready_o,
  /// addr (AddrW, aligned to DataW/8 bytes), len (LenW, beats; 0 = no beats), LSB first.
  input  logic [AddrW+LenW-1:0] in_data_i,

  /// Output beat valid.
  output logic out_valid_o,
  /// Consumer takes the beat this cycle.
  input  logic out_ready_i,
  /// data (DataW), last (1: the command's final beat), resp (2: the beat's RRESP), LSB first.
  output logic [DataW+2:0] out_data_o,

  /// Sticky: some beat since reset came back with RRESP != OKAY.
  output logic err_o,

  // AXI4 read channels: ID 0 only (responses in order); RREADY always 1 out of reset (the
  // credit rule).
  `CUBE5_AXI4_RD_MGR_PORTS(m_axi_, AddrW, DataW, IdW)
);

  // ==============================================================================================
  // Derived sizes
  // ==============================================================================================

  localparam int unsigned Bytes      = DataW / 8;
  localparam int unsigned SizeW      = $clog2(Bytes);
  localparam int unsigned BeatsPer4k = 4096 / Bytes;
  localparam int unsigned Depth      = MaxBurst * Outstanding;
  localparam int unsigned PtrW       = $clog2(Depth);
  localparam int unsigned CntW       = $clog2(Depth) + 1;
  localparam int unsigned OPtrW      = $clog2(Outstanding);
  localparam int unsigned OCntW      = $clog2(Outstanding) + 1;
  localparam int unsigned WordW      = DataW + 3;

  if (DataW < 8 || DataW > 1024 || (1 << $clog2(DataW)) != DataW) begin : gen_bad_data_w
    $fatal(1, "cube5_axi_rd: DataW must be a power of two in 8..1024");
  end
  if (MaxBurst < 2 || MaxBurst > 256 || (1 << $clog2(MaxBurst)) != MaxBurst
      || MaxBurst > BeatsPer4k) begin : gen_bad_max_burst
    $fatal(1, "cube5_axi_rd: MaxBurst must be a power of two in 2..256 with MaxBurst * DataW/8 <= 4096");
  end
  if (Outstanding < 2 || (1 << $clog2(Outstanding)) != Outstanding) begin : gen_bad_outstanding
    $fatal(1, "cube5_axi_rd: Outstanding must be a power of two >= 2");
  end
  if (AddrW < 13 || AddrW > 64) begin : gen_bad_addr_w
    $fatal(1, "cube5_axi_rd: AddrW must be in 13..64");
  end
  if (LenW < 1 || LenW > 32) begin : gen_bad_len_w
    $fatal(1, "cube5_axi_rd: LenW must be in 1..32");
  end

  // ==============================================================================================
  // Command splitter, burst plan register and AR register (cube5_axi_split)
  // ==============================================================================================
  //
  // Two stages, so the burst-length arithmetic and the credit check are not one path: the
  // splitter plans the next burst of the current command into the plan register; the plan is
  // issued (loaded into the AR register) when its beats fit the credits.

  localparam int unsigned BurstW = $clog2(MaxBurst) + 1;  // 1 .. MaxBurst

  logic             in_fire;
  logic [AddrW-1:0] in_addr;
  logic [LenW-1:0]  in_len;
  assign in_addr = in_data_i[AddrW-1:0];
  assign in_len  = in_data_i[AddrW+LenW-1:AddrW];

  logic [CntW-1:0]  credit_q, credit_d;  // return-FIFO slots not reserved by a burst
  logic [OCntW-1:0] bursts_q, bursts_d;  // bursts issued whose RLAST has not arrived

  logic              in_any, split_take, may_issue, issue, plan_last;
  logic [BurstW-1:0] plan_len;
  assign in_any    = (in_len != '0);
  assign may_issue = (credit_q >= CntW'(plan_len)) && (bursts_q < OCntW'(Outstanding));

  // A new command is taken when the splitter is idle or plans its last burst this cycle.
  assign in_ready_o = split_take;
  assign in_fire    = in_valid_i && in_ready_o;

  cube5_axi_split #(
    .AddrW   (AddrW),
    .SizeW   (SizeW),
    .BeatsW  (LenW),
    .MaxBurst(MaxBurst)
  ) u_split (
    .clk_i      (clk_i),
    .rst_ni     (rst_ni),
    .take_o     (split_take),
    .cmd_fire_i (in_fire),
    .cmd_addr_i (in_addr),
    .cmd_beats_i(in_len),
    .cmd_any_i  (in_any),
    .may_issue_i(may_issue),
    .issue_o    (issue),
    .plan_len_o (plan_len),
    .plan_last_o(plan_last),
    .a_addr_o   (m_axi_araddr_o),
    .a_len_o    (m_axi_arlen_o),
    .a_valid_o  (m_axi_arvalid_o),
    .a_ready_i  (m_axi_arready_i)
  );

  assign m_axi_arsize_o  = 3'(SizeW);
  assign m_axi_arburst_o = 2'b01;
  assign m_axi_arid_o    = '0;

  // ==============================================================================================
  // Burst info FIFO: whether each burst in flight ends its command
  // ==============================================================================================

  logic [Outstanding-1:0] info_q, info_d;
  logic [OPtrW-1:0]       info_wr_q, info_wr_d, info_rd_q, info_rd_d;

  logic r_fire, r_end;
  assign m_axi_rready_o = 1'b1;
  assign r_fire = m_axi_rvalid_i;
  assign r_end  = r_fire && m_axi_rlast_i;

  always_comb begin
    info_d    = info_q;
    info_wr_d = info_wr_q;
    info_rd_d = info_rd_q;
    // Constant indices (as cube5_axi_wr's): Yosys makes a bit-select write with a variable index
    // a 32-bit offset adder in front of a decoder, the critical path here.
    for (int unsigned i = 0; i < Outstanding; i++) begin
      if (issue && info_wr_q == OPtrW'(i)) info_d[i] = plan_last;
    end
    if (issue) info_wr_d = info_wr_q + OPtrW'(1);
    if (r_end) info_rd_d = info_rd_q + OPtrW'(1);
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      info_wr_q <= '0;
      info_rd_q <= '0;
    end else begin
      info_wr_q <= info_wr_d;
      info_rd_q <= info_rd_d;
    end
  end

  always_ff @(posedge clk_i) begin
    info_q <= info_d;
  end

  // ==============================================================================================
  // Return FIFO (block RAM) and the output register
  // ==============================================================================================

  logic [WordW-1:0] mem_q [Depth];
  logic [WordW-1:0] wr_word, rd_q;
  logic [PtrW-1:0]  wr_q, wr_d, rd_ptr_q, rd_ptr_d;
  logic [CntW-1:0]  count_q, count_d;  // words in the RAM
  logic             out_valid_q, out_valid_d;
  logic             ren;
  logic             count_nz_q, count_nz_d;  // count_q != 0, kept as a flag for ren
  logic [CntW-1:0]  credit_base;             // the credits after this cycle's issue, if any
  logic             err_q, err_d;

  assign wr_word  = {m_axi_rresp_i, m_axi_rlast_i && info_q[info_rd_q], m_axi_rdata_i};
  assign ren      = count_nz_q && (!out_valid_q || out_ready_i);

  always_comb begin
    wr_d        = r_fire ? wr_q + PtrW'(1) : wr_q;
    rd_ptr_d    = ren ? rd_ptr_q + PtrW'(1) : rd_ptr_q;
    count_d     = count_q + CntW'(r_fire) - CntW'(ren);
    // ren implies count_q >= 1: the count is nonzero after a beat arrives, and after a read
    // unless it was 1.
    count_nz_d  = r_fire || (ren ? (count_q != CntW'(1)) : count_nz_q);
    out_valid_d = ren || (out_valid_q && !out_ready_i);
    // ren (behind the consumer's ready) selects last: the increment does not wait for it.
    credit_base = issue ? credit_q - CntW'(plan_len) : credit_q;
    credit_d    = ren ? credit_base + CntW'(1) : credit_base;
    bursts_d    = bursts_q + OCntW'(issue) - OCntW'(r_end);
    err_d       = err_q || (r_fire && m_axi_rresp_i != 2'b00);
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      wr_q        <= '0;
      rd_ptr_q    <= '0;
      count_q     <= '0;
      count_nz_q  <= 1'b0;
      out_valid_q <= 1'b0;
      credit_q    <= CntW'(Depth);
      bursts_q    <= '0;
      err_q       <= 1'b0;
    end else begin
      wr_q        <= wr_d;
      rd_ptr_q    <= rd_ptr_d;
      count_q     <= count_d;
      count_nz_q  <= count_nz_d;
      out_valid_q <= out_valid_d;
      credit_q    <= credit_d;
      bursts_q    <= bursts_d;
      err_q       <= err_d;
    end
  end

  // The RAM: one write port, one registered read port with enable, no reset (DP16KD).
  always_ff @(posedge clk_i) begin
    if (r_fire) mem_q[wr_q] <= wr_word;
  end
  always_ff @(posedge clk_i) begin
    if (ren) rd_q <= mem_q[rd_ptr_q];
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = rd_q;
  assign err_o       = err_q;

  logic unused_rid;
  assign unused_rid = ^m_axi_rid_i;

`ifndef SYNTHESIS
  // A stalled output holds its beat (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_axi_rd: output changed while stalled");
  // AR holds its payload until taken (AXI4 A3.2.1).
  ArHoldsUntilReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      m_axi_arvalid_o && !m_axi_arready_i |=> m_axi_arvalid_o
      && $stable(m_axi_araddr_o) && $stable(m_axi_arlen_o))
    else $error("cube5_axi_rd: AR changed while stalled");
  // The read enable's flag is the count's.
  CountFlagIsCount: assert property (@(posedge clk_i) disable iff (!rst_ni)
      count_nz_q == (count_q != '0))
    else $error("cube5_axi_rd: count_nz_q disagrees with count_q");
  // The credit rule keeps the return FIFO from overflowing, so RREADY may stay high.
  ReturnFifoNeverOverflows: assert property (@(posedge clk_i) disable iff (!rst_ni)
      r_fire |-> count_q < CntW'(Depth))
    else $error("cube5_axi_rd: a beat arrived with the return FIFO full (credit rule broken)");
  // Every R beat belongs to a burst in flight.
  NoBeatWithoutBurst: assert property (@(posedge clk_i) disable iff (!rst_ni)
      r_fire |-> bursts_q != '0)
    else $error("cube5_axi_rd: an R beat arrived with no burst outstanding");
`endif

endmodule
