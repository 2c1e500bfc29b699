// cube5_axil: the co-simulation and synthesis top of the AXI4-Lite register block cube5_axil_regs,
// holding one generated register map (`Map`: cube5_axil_regs_pkg's `Map` encodings). Contract:
// docs/accel-regs.md, "The register block".
//
// The block's hardware side is Words x 32 bits in and out, more pins than an FPGA package has, so
// this top narrows it to what a test needs and what place and route can fit:
// - `hw_i` feeds every RO word and every W1C set input, rotated by a per-offset amount
//   (RO word i: `hw_i` rotated left by 5i mod 32; W1C word i: rotated left by 7i mod 32, and
//   only while `hw_set_i` is high), so each offset sees a different value;
// - `wsel_i` selects the word shown on `hw_q_o` and the write strobe on `hw_wr_stb_o`, `rsel_i`
//   the read strobe on `hw_rd_stb_o` (0 for an offset outside the map).
`include "cube5_axi_ports.svh"

module cube5_axil #(
  /// Which generated map: 0 cube5_accel.regs.toml, 1 the exercise map (cube5_axil_regs.regs.toml).
  parameter int unsigned Map = 0,
  /// Byte address bits on the bus (the maps have at most 256 words).
  parameter int unsigned AddrW = 10
) (
  input  logic             clk_i,
  input  logic             rst_ni,
  `CUBE5_AXIL_SUB_PORTS(s_axil_, AddrW),
  /// RO values and W1C set bits, rotated per offset (see the header).
  input  logic [31:0]      hw_i,
  /// W1C set inputs follow `hw_i` in this cycle.
  input  logic             hw_set_i,
  /// Offset shown on `hw_q_o` and `hw_wr_stb_o`.
  input  logic [7:0]       wsel_i,
  /// Offset shown on `hw_rd_stb_o`.
  input  logic [7:0]       rsel_i,
  output logic [31:0]      hw_q_o,
  output logic             hw_wr_stb_o,
  output logic             hw_rd_stb_o,
  output logic             irq_o
);

  localparam bit IsAccel = Map == 32'(cube5_axil_regs_pkg::MapAccel);
  localparam int unsigned Words =
      IsAccel ? cube5_accel_regs_pkg::AxilWords : cube5_axil_regs_pkg::AxilWords;

`ifndef SYNTHESIS
  initial begin
    if (Map != 32'(cube5_axil_regs_pkg::MapAccel) && Map != 32'(cube5_axil_regs_pkg::MapExercise))
      $fatal(1, "cube5_axil: Map = %0d is not a map (0 accel, 1 exercise)", Map);
    if (Words > 256 || (Words << 2) > (1 << AddrW))
      $fatal(1, "cube5_axil: %0d words do not fit AddrW = %0d", Words, AddrW);
  end
`endif

  function automatic logic [31:0] rotl(logic [31:0] v, int unsigned s);
    rotl = (s % 32 == 0) ? v : ((v << (s % 32)) | (v >> (32 - s % 32)));
  endfunction

  logic [Words*32-1:0] reg_q, ro, set;
  logic [Words-1:0]    wr_stb, rd_stb;

  for (genvar i = 0; i < Words; i++) begin : g_hw
    assign ro[i*32 +: 32]  = rotl(hw_i, 5 * i);
    assign set[i*32 +: 32] = hw_set_i ? rotl(hw_i, 7 * i) : 32'h0;
  end

  cube5_axil_regs #(
    .Words    (Words),
    .AddrW    (AddrW),
    .Stored   (IsAccel ? Words'(cube5_accel_regs_pkg::AxilStored)   : Words'(cube5_axil_regs_pkg::AxilStored)),
    .Readable (IsAccel ? Words'(cube5_accel_regs_pkg::AxilReadable) : Words'(cube5_axil_regs_pkg::AxilReadable)),
    .Ro       (IsAccel ? Words'(cube5_accel_regs_pkg::AxilRo)       : Words'(cube5_axil_regs_pkg::AxilRo)),
    .W1c      (IsAccel ? Words'(cube5_accel_regs_pkg::AxilW1c)      : Words'(cube5_axil_regs_pkg::AxilW1c)),
    .HasReset (IsAccel ? Words'(cube5_accel_regs_pkg::AxilHasReset) : Words'(cube5_axil_regs_pkg::AxilHasReset)),
    .Mask     (IsAccel ? (Words*32)'(cube5_accel_regs_pkg::AxilMask)  : (Words*32)'(cube5_axil_regs_pkg::AxilMask)),
    .Reset    (IsAccel ? (Words*32)'(cube5_accel_regs_pkg::AxilReset) : (Words*32)'(cube5_axil_regs_pkg::AxilReset)),
    .HasIrq   (IsAccel ? cube5_accel_regs_pkg::AxilHasIrq    : cube5_axil_regs_pkg::AxilHasIrq),
    .IrqStatus(IsAccel ? cube5_accel_regs_pkg::AxilIrqStatus : cube5_axil_regs_pkg::AxilIrqStatus),
    .IrqEnable(IsAccel ? cube5_accel_regs_pkg::AxilIrqEnable : cube5_axil_regs_pkg::AxilIrqEnable)
  ) u_regs (
    .clk_i,
    .rst_ni,
    .s_axil_awvalid_i,
    .s_axil_awready_o,
    .s_axil_awaddr_i,
    .s_axil_awprot_i (3'b000),
    .s_axil_wvalid_i,
    .s_axil_wready_o,
    .s_axil_wdata_i,
    .s_axil_wstrb_i,
    .s_axil_bvalid_o,
    .s_axil_bready_i,
    .s_axil_bresp_o,
    .s_axil_arvalid_i,
    .s_axil_arready_o,
    .s_axil_araddr_i,
    .s_axil_arprot_i (3'b000),
    .s_axil_rvalid_o,
    .s_axil_rready_i,
    .s_axil_rdata_o,
    .s_axil_rresp_o,
    .reg_q_o  (reg_q),
    .ro_i     (ro),
    .w1c_set_i(set),
    .wr_stb_o (wr_stb),
    .rd_stb_o (rd_stb),
    .irq_o
  );

  always_comb begin
    hw_q_o      = 32'h0;
    hw_wr_stb_o = 1'b0;
    hw_rd_stb_o = 1'b0;
    for (int unsigned i = 0; i < Words; i++) begin
      if (wsel_i == 8'(i)) begin
        hw_q_o      = reg_q[i*32 +: 32];
        hw_wr_stb_o = wr_stb[i];
      end
      if (rsel_i == 8'(i)) hw_rd_stb_o = rd_stb[i];
    end
  end

endmodule
