// cube5_section_buf_eram: an edge memory bank of cube5_section_buf with two P-groups per item
// (docs/numerics/section_buf.md, "Storage and the skew"): the two group banks of one lk mod P,
// side by side in one word, each half with its own write enable (an item that writes both writes
// them at one word). Each half is padded to PartW bits (18: two 9-bit bytes) so that the ECP5 flow
// maps the enables to DP16KD's byte enables (one block RAM where two banks took two). One write
// port, one registered read port with a read enable, `no_rw_check` as cube5_section_buf_ram. No
// reset.
module cube5_section_buf_eram #(
  /// Entries.
  parameter int unsigned Depth = 16,
  /// Bits per half.
  parameter int unsigned Width = 8,
  /// Bits per half as stored (Width <= PartW).
  parameter int unsigned PartW = 18,
  /// Address bits, at least $clog2(Depth).
  parameter int unsigned AddrW = 4
) (
  input  logic               clk_i,
  /// Write enable of each half (never with a read of the same address).
  input  logic [1:0]         we_i,
  /// Write address, < Depth.
  input  logic [AddrW-1:0]   waddr_i,
  /// Write data, half h at h Width.
  input  logic [2*Width-1:0] wdata_i,
  /// Read enable: the output register loads the entry at raddr_i.
  input  logic               re_i,
  /// Read address, < Depth.
  input  logic [AddrW-1:0]   raddr_i,
  /// Registered read data, half h at h Width.
  output logic [2*Width-1:0] rdata_o
);

  if (Depth < 2 || AddrW < $clog2(Depth) || Width > PartW) begin : gen_bad_params
    $fatal(1, "cube5_section_buf_eram: need Depth >= 2, AddrW >= $clog2(Depth), Width <= PartW");
  end

  (* no_rw_check *)
  logic [2*PartW-1:0] mem_q [Depth];
  logic [2*PartW-1:0] rdata_q;

  always_ff @(posedge clk_i) begin
    if (we_i[0]) mem_q[waddr_i][0 +: PartW]     <= PartW'(wdata_i[0 +: Width]);
    if (we_i[1]) mem_q[waddr_i][PartW +: PartW] <= PartW'(wdata_i[Width +: Width]);
  end
  always_ff @(posedge clk_i) begin
    if (re_i) rdata_q <= mem_q[raddr_i];
  end
  assign rdata_o = {rdata_q[PartW +: Width], rdata_q[0 +: Width]};

  // The padding bits are written as zeros and never read.
  logic unused_pad;
  assign unused_pad = ^{rdata_q[Width +: PartW - Width], rdata_q[PartW + Width +: PartW - Width]};

endmodule
