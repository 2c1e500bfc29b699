// cube5_shader_ram: a table of cube5_shader (docs/numerics/shader.md): one write port (the
// configuration port), one read port with a registered output and a read enable (the pipeline's
// stage enable), so FPGA flows map it to block RAM with the output register inside. Read-first:
// a read and a write of one address in one cycle return the old contents. No reset: tables are
// datapath state. NoRwCheck = 1 declares that its user never reads and writes one address in one
// cycle (Yosys's `no_rw_check`): the ECP5 flow then maps it to a bare DP16KD, where a read-first
// memory gets a write delayed by a cycle and a bypass multiplexer behind the block RAM's output.
module cube5_shader_ram #(
  /// Entries.
  parameter int unsigned Depth = 16,
  /// Bits per entry.
  parameter int unsigned Width = 8,
  /// Address bits, at least $clog2(Depth).
  parameter int unsigned AddrW = 4,
  /// 1: the user never reads and writes one address in one cycle (the result would be undefined).
  parameter bit NoRwCheck = 1'b0
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

  logic [Width-1:0] rdata_q;

  // The memory array is the one place where an always_ff holds an indexed write (the form that
  // block-RAM inference expects) rather than `x_q <= x_d`. The two branches differ only in the
  // attribute (Yosys 0.23 takes no parameter in an attribute's value).
  if (NoRwCheck) begin : gen_no_rw_check
    (* no_rw_check *)
    logic [Width-1:0] mem_q [Depth];
    always_ff @(posedge clk_i) begin
      if (we_i) mem_q[waddr_i] <= wdata_i;
    end
    always_ff @(posedge clk_i) begin
      if (re_i) rdata_q <= mem_q[raddr_i];
    end
  end else begin : gen_read_first
    logic [Width-1:0] mem_q [Depth];
    always_ff @(posedge clk_i) begin
      if (we_i) mem_q[waddr_i] <= wdata_i;
    end
    always_ff @(posedge clk_i) begin
      if (re_i) rdata_q <= mem_q[raddr_i];
    end
  end

  assign rdata_o = rdata_q;

endmodule
