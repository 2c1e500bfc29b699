// cube5_skewmem_bank: one memory module of the skewed memory (patent [37]): a single-port RAM of
// 2^AddrW words with a registered read and Latency-1 further read-data registers, so a read issued
// in cycle t returns its word in cycle t + Latency (1 = SRAM; more models a pipelined DRAM-like
// module). It never stalls: the controller only issues what it can take back. A write takes effect
// at the clock edge that ends its cycle. Contents are datapath state: not reset.
module cube5_skewmem_bank #(
  /// Word width (one voxel).
  parameter int unsigned Width   = 12,
  /// Address bits: 2^AddrW words.
  parameter int unsigned AddrW   = 10,
  /// Cycles from a read request to its data, 1..8.
  parameter int unsigned Latency = 1
) (
  input  logic             clk_i,
  /// Access this cycle (read, or write with we_i).
  input  logic             req_i,
  /// The access is a write.
  input  logic             we_i,
  /// Word address.
  input  logic [AddrW-1:0] addr_i,
  /// Word to write.
  input  logic [Width-1:0] wdata_i,
  /// Word read Latency cycles ago (held otherwise; undefined before the first read).
  output logic [Width-1:0] rdata_o
);

  if (Latency < 1 || Latency > 8) begin : gen_bad_latency
    $fatal(1, "cube5_skewmem_bank: Latency must be 1..8");
  end

  logic [Width-1:0] mem_q [2**AddrW];
  logic [Width-1:0] rdata_q [Latency];

  always_ff @(posedge clk_i) begin
    if (req_i && we_i) begin
      mem_q[addr_i] <= wdata_i;
    end
  end

  always_ff @(posedge clk_i) begin
    if (req_i && !we_i) begin
      rdata_q[0] <= mem_q[addr_i];
    end
  end

  // Further read-data stages (the DRAM-like part of the latency); they shift every cycle.
  for (genvar i = 1; i < Latency; i++) begin : gen_read_pipe
    always_ff @(posedge clk_i) begin
      rdata_q[i] <= rdata_q[i-1];
    end
  end

  assign rdata_o = rdata_q[Latency-1];

endmodule
