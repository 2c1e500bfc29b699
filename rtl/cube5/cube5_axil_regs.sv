// cube5_axil_regs: AXI4-Lite subordinate register block, one generic module for every register map.
//
// The map is a set of tables that `cube5-gen regs` writes into the block's package from its
// `<block>.regs.toml` (`axil = true`): one entry per word offset (`AxilStored`,
// `AxilReadable`, `AxilRo`, `AxilW1c`, `AxilHasReset`, `AxilMask`, `AxilReset`, the interrupt's
// two offsets). Contract: docs/accel-regs.md, "The register block".
//
// - Write: AW and W are taken independently into one holding register each; the write is done in
//   the cycle both are held and the B slot is free, and BVALID rises in the next cycle, the first
//   cycle `reg_q_o` shows the new value. A new AW and W are taken in the cycle the held ones are
//   written, so with BREADY high the block takes one write per cycle (B two cycles after the
//   later of the AW and W handshakes).
// - Read: the value is sampled in the cycle of the AR handshake; RVALID rises in the next cycle;
//   ARREADY = !RVALID | RREADY, so with RREADY high one read per cycle.
// - Access: RW stores and reads back; RO reads `ro_i`; WO stores, a read answers SLVERR; W1C reads
//   back, writing 1 clears a bit, `w1c_set_i` sets it (a set and a clear of one bit in one cycle:
//   the set wins). WSTRB selects the bytes written (or cleared). Bits outside a register's fields
//   (`AxilMask`) read 0 and ignore writes. A write to an RO offset or any access to an unmapped
//   offset answers SLVERR and changes nothing; a SLVERR read returns 0.
// - Reset (synchronous, active low): registers with a reset value take it, the others keep theirs
//   (their flops have no reset); responses in flight are dropped.
`include "cube5_axi_ports.svh"

module cube5_axil_regs #(
  /// Word offsets 0 .. Words - 1 (the table length).
  parameter int unsigned Words = 1,
  /// Byte address bits decoded: the word offset is addr[AddrW-1:2].
  parameter int unsigned AddrW = 12,
  /// Per offset: the block keeps its value (RW, WO, W1C).
  parameter logic [Words-1:0] Stored = {Words{1'b0}},
  /// Per offset: a read answers OKAY (RW, RO, W1C).
  parameter logic [Words-1:0] Readable = {Words{1'b0}},
  /// Per offset: a read returns `ro_i` (RO).
  parameter logic [Words-1:0] Ro = {Words{1'b0}},
  /// Per offset: write-1-to-clear, set by `w1c_set_i`.
  parameter logic [Words-1:0] W1c = {Words{1'b0}},
  /// Per offset: reset loads the `Reset` word; else reset keeps the value.
  parameter logic [Words-1:0] HasReset = {Words{1'b0}},
  /// Per offset: the bits the register has (its fields).
  parameter logic [Words*32-1:0] Mask = {Words{32'h0}},
  /// Per offset: the reset value.
  parameter logic [Words*32-1:0] Reset = {Words{32'h0}},
  /// 1: `irq_o` = |(word IrqStatus & word IrqEnable); 0: `irq_o` = 0.
  parameter int unsigned HasIrq = 0,
  parameter int unsigned IrqStatus = 0,
  parameter int unsigned IrqEnable = 0
) (
  input  logic                  clk_i,
  input  logic                  rst_ni,
  // ---- AXI4-Lite subordinate (BRESP and RRESP: 0 OKAY, 2 SLVERR) ----
  `CUBE5_AXIL_SUB_PORTS(s_axil_, AddrW),
  // AxPROT: ignored.
  input  logic [2:0]            s_axil_awprot_i,
  input  logic [2:0]            s_axil_arprot_i,
  // ---- hardware side ----
  /// Every register's value, word i at [i*32 +: 32] (0 where nothing is kept).
  output logic [Words*32-1:0]   reg_q_o,
  /// Values of the RO registers (other words unused).
  input  logic [Words*32-1:0]   ro_i,
  /// Set bits of the W1C registers (other words unused).
  input  logic [Words*32-1:0]   w1c_set_i,
  /// Bit i high for one cycle, the first cycle `reg_q_o` shows a bus write to offset i (OKAY).
  output logic [Words-1:0]      wr_stb_o,
  /// Bit i high for one cycle, the first cycle of RVALID of a read of offset i (OKAY).
  output logic [Words-1:0]      rd_stb_o,
  /// Level interrupt: |(status & enable).
  output logic                  irq_o
);

  localparam int unsigned IdxW = AddrW - 2;
  localparam logic [1:0] RespOkay = 2'b00;
  localparam logic [1:0] RespSlvErr = 2'b10;

`ifndef SYNTHESIS
  initial begin
    if (Words < 1 || Words > (1 << IdxW)) $fatal(1, "cube5_axil_regs: Words = %0d does not fit AddrW = %0d", Words, AddrW);
    if (AddrW < 3 || AddrW > 32) $fatal(1, "cube5_axil_regs: AddrW = %0d outside 3..32", AddrW);
    if (HasIrq != 0 && (IrqStatus >= Words || IrqEnable >= Words)) $fatal(1, "cube5_axil_regs: interrupt offsets outside the map");
  end
`endif

  logic unused_prot;
  assign unused_prot = ^{s_axil_awprot_i, s_axil_arprot_i, s_axil_awaddr_i[1:0], s_axil_araddr_i[1:0]};

  // ---------------------------------------------------------------------------------------------
  // Write channels: AW and W holding registers, B response register
  // ---------------------------------------------------------------------------------------------

  logic            aw_valid_q, aw_valid_d, w_valid_q, w_valid_d, b_valid_q, b_valid_d;
  logic [IdxW-1:0] aw_idx_q, aw_idx_d;
  logic [31:0]     w_data_q, w_data_d;
  logic [3:0]      w_strb_q, w_strb_d;
  logic [1:0]      b_resp_q, b_resp_d;
  logic            wr_go, aw_fire, w_fire;
  logic [Words-1:0] wr_sel;     // one-hot: the word written this cycle
  logic [Words-1:0] wr_stb_d, wr_stb_q;
  logic [31:0]     byte_mask;

  assign wr_go = aw_valid_q & w_valid_q & (~b_valid_q | s_axil_bready_i);
  assign s_axil_awready_o = ~aw_valid_q | wr_go;
  assign s_axil_wready_o  = ~w_valid_q | wr_go;
  assign aw_fire = s_axil_awvalid_i & s_axil_awready_o;
  assign w_fire  = s_axil_wvalid_i & s_axil_wready_o;
  assign byte_mask = {{8{w_strb_q[3]}}, {8{w_strb_q[2]}}, {8{w_strb_q[1]}}, {8{w_strb_q[0]}}};

  always_comb begin
    aw_valid_d = aw_fire | (aw_valid_q & ~wr_go);
    aw_idx_d   = aw_fire ? s_axil_awaddr_i[AddrW-1:2] : aw_idx_q;
    w_valid_d  = w_fire | (w_valid_q & ~wr_go);
    w_data_d   = w_fire ? s_axil_wdata_i : w_data_q;
    w_strb_d   = w_fire ? s_axil_wstrb_i : w_strb_q;
    wr_sel     = '0;
    for (int unsigned i = 0; i < Words; i++) begin
      wr_sel[i] = wr_go & (aw_idx_q == IdxW'(i)) & Stored[i];
    end
    b_valid_d = wr_go | (b_valid_q & ~s_axil_bready_i);
    b_resp_d  = wr_go ? ((|wr_sel) ? RespOkay : RespSlvErr) : b_resp_q;
    wr_stb_d  = wr_sel;
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      aw_valid_q <= 1'b0;
      w_valid_q  <= 1'b0;
      b_valid_q  <= 1'b0;
      wr_stb_q   <= '0;
    end else begin
      aw_valid_q <= aw_valid_d;
      w_valid_q  <= w_valid_d;
      b_valid_q  <= b_valid_d;
      wr_stb_q   <= wr_stb_d;
    end
  end

  always_ff @(posedge clk_i) begin
    aw_idx_q <= aw_idx_d;
    w_data_q <= w_data_d;
    w_strb_q <= w_strb_d;
    b_resp_q <= b_resp_d;
  end

  assign s_axil_bvalid_o = b_valid_q;
  assign s_axil_bresp_o  = b_resp_q;
  assign wr_stb_o        = wr_stb_q;

  // ---------------------------------------------------------------------------------------------
  // Registers: one word per offset; only the Mask bits of Stored words become flops
  // ---------------------------------------------------------------------------------------------

  logic [Words*32-1:0] word_q;   // every offset, Mask applied (0 where nothing is kept)

  for (genvar i = 0; i < Words; i++) begin : g_word
    localparam logic [31:0] M = Mask[i*32 +: 32];
    if (!W1c[i]) begin : g_no_set
      logic unused_set;
      assign unused_set = ^w1c_set_i[i*32 +: 32];
    end
    if (Stored[i]) begin : g_stored
      logic [31:0] q, d;
      always_comb begin
        d = q;
        if (W1c[i]) begin
          if (wr_sel[i]) d = d & ~(w_data_q & byte_mask);
          d = d | w1c_set_i[i*32 +: 32];
        end else if (wr_sel[i]) begin
          d = (d & ~byte_mask) | (w_data_q & byte_mask);
        end
      end
      if (HasReset[i]) begin : g_reset
        always_ff @(posedge clk_i) begin
          if (!rst_ni) q <= Reset[i*32 +: 32] & M;
          else q <= d & M;
        end
      end else begin : g_kept
        always_ff @(posedge clk_i) begin
          if (rst_ni) q <= d & M;
        end
      end
      assign word_q[i*32 +: 32] = q & M;
    end else begin : g_none
      assign word_q[i*32 +: 32] = 32'h0;
    end
  end

  assign reg_q_o = word_q;

  // ---------------------------------------------------------------------------------------------
  // Read channel: the value of the offset in the cycle of the AR handshake, one cycle later on R
  // ---------------------------------------------------------------------------------------------

  logic            r_valid_q, r_valid_d, ar_fire;
  logic [31:0]     r_data_q, r_data_d, rd_word;
  logic [1:0]      r_resp_q, r_resp_d;
  logic [Words-1:0] rd_sel, rd_stb_q;
  logic [IdxW-1:0] ar_idx;

  assign s_axil_arready_o = ~r_valid_q | s_axil_rready_i;
  assign ar_fire = s_axil_arvalid_i & s_axil_arready_o;
  assign ar_idx = s_axil_araddr_i[AddrW-1:2];

  always_comb begin
    rd_word = 32'h0;
    rd_sel  = '0;
    for (int unsigned i = 0; i < Words; i++) begin
      if (ar_idx == IdxW'(i) && Readable[i]) begin
        rd_sel[i] = ar_fire;
        rd_word   = Ro[i] ? (ro_i[i*32 +: 32] & Mask[i*32 +: 32]) : word_q[i*32 +: 32];
      end
    end
    r_valid_d = ar_fire | (r_valid_q & ~s_axil_rready_i);
    r_data_d  = ar_fire ? rd_word : r_data_q;
    r_resp_d  = ar_fire ? ((|rd_sel) ? RespOkay : RespSlvErr) : r_resp_q;
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      r_valid_q <= 1'b0;
      rd_stb_q  <= '0;
    end else begin
      r_valid_q <= r_valid_d;
      rd_stb_q  <= rd_sel;
    end
  end

  always_ff @(posedge clk_i) begin
    r_data_q <= r_data_d;
    r_resp_q <= r_resp_d;
  end

  assign s_axil_rvalid_o = r_valid_q;
  assign s_axil_rdata_o  = r_data_q;
  assign s_axil_rresp_o  = r_resp_q;
  assign rd_stb_o        = rd_stb_q;

  // ---------------------------------------------------------------------------------------------
  // Interrupt
  // ---------------------------------------------------------------------------------------------

  if (HasIrq != 0) begin : g_irq
    assign irq_o = |(word_q[IrqStatus*32 +: 32] & word_q[IrqEnable*32 +: 32]);
  end else begin : g_no_irq
    assign irq_o = 1'b0;
  end

`ifndef SYNTHESIS
  // A response held while stalled keeps its payload (AXI4-Lite).
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      s_axil_bvalid_o && !s_axil_bready_i |=> s_axil_bvalid_o && $stable(s_axil_bresp_o))
    else $error("cube5_axil_regs: B changed while stalled");
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      s_axil_rvalid_o && !s_axil_rready_i |=> s_axil_rvalid_o && $stable(s_axil_rdata_o) && $stable(s_axil_rresp_o))
    else $error("cube5_axil_regs: R changed while stalled");
`endif

endmodule
