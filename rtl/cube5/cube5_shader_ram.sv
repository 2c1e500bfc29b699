// cube5_shader_ram: a table of cube5_shader (docs/numerics/shader.md): one write port (the
// configuration port), one read port with a registered output and a read enable (the pipeline's
// stage enable), so FPGA flows map it to block RAM with the output register inside. Read-first:
// a read and a write of one address in one cycle return the old contents. No reset: tables are
// datapath state.
module cube5_shader_ram #(
  /// Entries.
  parameter int unsigned Depth = 16,
  /// Bits per entry.
  parameter int unsigned Width = 8,
  /// Address bits, at least $clog2(Depth).
  parameter int unsigned AddrW = 4
) (
  input  logic             clk_i,

  /// Write enable.
  input  logic             we_i,
  /// Write address, < Depth.
  input  logic [AddrW-1:0] waddr_i,
  /// Write data.
  input  logic [Width-1:0] wdata_i,

  /// Read enable: the output register loads the entry at raddr_i.
  input  logic             re_i,
  /// Read address, < Depth.
  input  logic [AddrW-1:0] raddr_i,
  /// Registered read data.
  output logic [Width-1:0] rdata_o
);

  if (Depth < 2 || AddrW < $clog2(Depth)) begin : gen_bad_addr_w
    $fatal(1, "cube5_shader_ram: need Depth >= 2 and AddrW >= $clog2(Depth)");
  end

  logic [Width-1:0] mem_q [Depth];
  logic [Width-1:0] rdata_q;

  // The memory array is the one place where an always_ff holds an indexed write (the form that
  // block-RAM inference expects) rather than `x_q <= x_d`.
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
