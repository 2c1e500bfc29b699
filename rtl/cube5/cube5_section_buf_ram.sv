// cube5_section_buf_ram: a simple dual-port RAM of the section buffer (one bank): one write port,
// one read port with a registered read (a read issued in cycle t returns its word in cycle t + 1,
// held until the next read). Written so that Yosys maps it to ECP5 block RAM (DP16KD) or LUT RAM.
// A write takes effect at the clock edge that ends its cycle. Contents are datapath state: not
// reset.
module cube5_section_buf_ram #(
  /// Word width.
  parameter int unsigned Width = 12,
  /// Address bits: 2^AddrW words.
  parameter int unsigned AddrW = 10
) (
  input  logic             clk_i,
  /// Write this cycle.
  input  logic             we_i,
  /// Write address.
  input  logic [AddrW-1:0] waddr_i,
  /// Word to write.
  input  logic [Width-1:0] wdata_i,
  /// Read this cycle.
  input  logic             re_i,
  /// Read address.
  input  logic [AddrW-1:0] raddr_i,
  /// Word read in the previous read cycle.
  output logic [Width-1:0] rdata_o
);

  logic [Width-1:0] mem_q [2**AddrW];
  logic [Width-1:0] rdata_q;

  always_ff @(posedge clk_i) begin
    if (we_i) begin
      mem_q[waddr_i] <= wdata_i;
    end
  end

  always_ff @(posedge clk_i) begin
    if (re_i) begin
      rdata_q <= mem_q[raddr_i];
    end
  end

  assign rdata_o = rdata_q;

endmodule
