// cube5_section_buf_ram: a bank of cube5_section_buf (docs/numerics/section_buf.md, "Storage"):
// one write port, one read port with a registered output and a read enable, like
// cube5_shader_ram, but with Yosys's `no_rw_check` on the memory: the section buffer never reads
// and writes one address in one cycle (its writes go to the half that is not being read), so the
// ECP5 flow maps it to a bare DP16KD, where a read-first memory gets its writes delayed a cycle and
// a bypass multiplexer behind the block RAM's output (docs/measurements.md, cube5_section_buf).
// A module of its own rather than a parameter of cube5_shader_ram: wrapping that memory in a
// generate block changed its other users' netlists (Yosys/ABC LUT counts). No reset.
module cube5_section_buf_ram #(
  /// Entries.
  parameter int unsigned Depth = 16,
  /// Bits per entry.
  parameter int unsigned Width = 8,
  /// Address bits, at least $clog2(Depth).
  parameter int unsigned AddrW = 4
) (
  input  logic             clk_i,
  /// Write enable (never with a read of the same address).
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
    $fatal(1, "cube5_section_buf_ram: need Depth >= 2 and AddrW >= $clog2(Depth)");
  end

  (* no_rw_check *)
  logic [Width-1:0] mem_q [Depth];
  logic [Width-1:0] rdata_q;

  // The indexed write is the form block-RAM inference expects (not `x_q <= x_d`).
  always_ff @(posedge clk_i) begin
    if (we_i) mem_q[waddr_i] <= wdata_i;
  end
  always_ff @(posedge clk_i) begin
    if (re_i) rdata_q <= mem_q[raddr_i];
  end
  assign rdata_o = rdata_q;

endmodule
