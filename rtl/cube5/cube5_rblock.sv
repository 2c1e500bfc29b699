// cube5_rblock: recursive-blocking (bit-interleaved) addressing unit (patent [24], [447]-[450];
// docs/numerics/rblock.md). Converts a linear raster index x + 2^XBits (y + 2^YBits z) into the
// recursive-blocked array offset (..., z1 y1 x1, z0 y0 x0) and back, one conversion per clock.
//
// Bit form (the contract's choice for hardware): every offset bit is one coordinate bit, so both
// directions are wiring, chosen at elaboration by walking the interleave order; one output register.
module cube5_rblock #(
  /// Bits of x: the volume is 2^XBits voxels along x.
  parameter int unsigned XBits = 8,
  /// Bits of y.
  parameter int unsigned YBits = 8,
  /// Bits of z.
  parameter int unsigned ZBits = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// value (XBits+YBits+ZBits), dir (1: 0 = linear to blocked, 1 = blocked to linear), LSB first.
  input  logic [XBits+YBits+ZBits:0] in_data_i,

  /// Output valid.
  output logic out_valid_o,
  /// Consumer takes the output this cycle.
  input  logic out_ready_i,
  /// The converted index.
  output logic [XBits+YBits+ZBits-1:0] out_data_o
);

  localparam int unsigned TotalW = XBits + YBits + ZBits;

  if (XBits < 1 || XBits > 16 || YBits < 1 || YBits > 16 || ZBits < 1 || ZBits > 16)
  begin : gen_bad_bits
    $fatal(1, "cube5_rblock: XBits, YBits and ZBits must be 1..16");
  end

  // The linear-index bit that blocked-offset bit `j` holds: walk the interleave order (levels from
  // the least significant, axes x, y, z within a level, an axis only while it has bits left).
  function automatic int unsigned lin_bit_of(int unsigned j);
    int unsigned placed;
    lin_bit_of = 0;
    placed = 0;
    for (int unsigned l = 0; l < 16; l++) begin
      if (l < XBits) begin
        if (placed == j) lin_bit_of = l;
        placed = placed + 1;
      end
      if (l < YBits) begin
        if (placed == j) lin_bit_of = XBits + l;
        placed = placed + 1;
      end
      if (l < ZBits) begin
        if (placed == j) lin_bit_of = XBits + YBits + l;
        placed = placed + 1;
      end
    end
  endfunction

  // ---------------------------------------------------------------------------
  // Both directions as wiring
  // ---------------------------------------------------------------------------
  logic [TotalW-1:0] value, blocked, linear;
  logic              dir;

  assign value = in_data_i[TotalW-1:0];
  assign dir   = in_data_i[TotalW];

  for (genvar j = 0; j < TotalW; j++) begin : gen_bit
    localparam int unsigned LinBit = lin_bit_of(j);
    assign blocked[j]      = value[LinBit];
    assign linear[LinBit]  = value[j];
  end

  // ---------------------------------------------------------------------------
  // One register stage
  // ---------------------------------------------------------------------------
  cube5_pipe_reg #(
    .Width (TotalW)
  ) u_out (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .in_ready_o  (in_ready_o),
    .in_data_i   (dir ? linear : blocked),
    .out_valid_o (out_valid_o),
    .out_ready_i (out_ready_i),
    .out_data_o  (out_data_o)
  );

  // A stalled output holds its item: asserted in cube5_pipe_reg.

endmodule
