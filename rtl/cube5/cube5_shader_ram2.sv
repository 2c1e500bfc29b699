// cube5_shader_ram2: two tables of cube5_shader (docs/numerics/shader.md) in one memory with two
// ports, which FPGA flows map to one dual-port block RAM where two cube5_shader_ram take two
// (the reflectance map's banks: 150 x 17 bits each at the frame's widths, a block RAM holds 1,024
// x 18). Port A reads table 0 and does every write (a table is written only at table load), port
// B reads table 1; each has a registered output with the read enable (the pipeline's stage
// enable). In a cycle with a write both reads return other entries (port A the old contents of the
// entry written, port B an entry of table 0): write while no read is wanted
// (docs/numerics/shader.md, "Configuration port"). No reset: tables are datapath state.
module cube5_shader_ram2 #(
  /// Entries per table.
  parameter int unsigned Depth = 16,
  /// Bits per entry.
  parameter int unsigned Width = 8,
  /// Address bits, at least $clog2(Depth).
  parameter int unsigned AddrW = 4
) (
  input  logic               clk_i,

  /// Write enable of table k at [k] (at most one on).
  input  logic [1:0]         we_i,
  /// Write address, < Depth (the table of the write enable that is on).
  input  logic [AddrW-1:0]   waddr_i,
  /// Write data.
  input  logic [Width-1:0]   wdata_i,

  /// Read enable: both output registers load.
  input  logic               re_i,
  /// Read address of table k at [k*AddrW +: AddrW], < Depth.
  input  logic [2*AddrW-1:0] raddr_i,
  /// Registered read data of table k at [k*Width +: Width].
  output logic [2*Width-1:0] rdata_o
);

  if (Depth < 2 || AddrW < $clog2(Depth)) begin : gen_bad_addr_w
    $fatal(1, "cube5_shader_ram2: need Depth >= 2 and AddrW >= $clog2(Depth)");
  end

  // Table k at addresses {k, entry}.
  logic [Width-1:0] mem_q [2 << AddrW];
  logic [AddrW:0]   addr_a, addr_b;
  logic [Width-1:0] rdata_a_q, rdata_b_q;

  // Every write goes through port A; port B only reads, and while table 1 is written it reads
  // table 0, so that it never reads the address written: Yosys 0.23 maps a memory to one
  // dual-port block RAM only if each read port either shares the write port's address or
  // provably never collides with it (docs/toolchain.md).
  assign addr_a = |we_i ? {we_i[1], waddr_i} : {1'b0, raddr_i[0 +: AddrW]};
  assign addr_b = {!we_i[1], raddr_i[AddrW +: AddrW]};

  // The memory array is the one place where an always_ff holds an indexed write (the form that
  // block-RAM inference expects) rather than `x_q <= x_d`.
  always_ff @(posedge clk_i) begin
    if (|we_i) begin
      mem_q[addr_a] <= wdata_i;
    end
    if (re_i) begin
      rdata_a_q <= mem_q[addr_a];
      rdata_b_q <= mem_q[addr_b];
    end
  end

  assign rdata_o = {rdata_b_q, rdata_a_q};

endmodule
