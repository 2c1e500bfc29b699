// gicube_scatter_hash: the random pool of the scattering unit from a ray's mangling bits
// (docs/numerics/gicube_scatter.md, Random numbers; patent [380], [385]). Three lanes of Robert
// Jenkins' 32-bit integer hash, steps 1-3 in the first register stage and 4-6 in the second.
//
// Each step is a continuous assignment of its own: Yosys 0.23 mis-synthesized the same steps
// written as a package function called three times from one always_comb block (the gate-level
// co-simulation caught it), so no function is used here.
module gicube_scatter_hash (
  /// Clock.
  input  logic        clk_i,
  /// Pipeline advance.
  input  logic        en_i,
  /// The ray's mangling source.
  input  logic [31:0] ray_bits_i,
  /// Pool w0 + 2^32 w1 + 2^64 w2, gicube_scatter_pkg::HashLatency stages after ray_bits_i.
  output logic [95:0] pool_o
);

  logic [95:0] lane_key;
  assign lane_key = {ray_bits_i ^ gicube_scatter_pkg::HashLane2,
                     ray_bits_i ^ gicube_scatter_pkg::HashLane1,
                     ray_bits_i};

  logic [95:0] half_d, half_q, pool_d, pool_q;

  for (genvar l = 0; l < 3; l++) begin : gen_lane
    logic [31:0] a0, a1, a2, a3, b0, b1, b2, b3;
    // Steps 1-3.
    assign a0 = lane_key[l*32 +: 32];
    assign a1 = (a0 + 32'h7ed5_5d16) + (a0 << 12);
    assign a2 = (a1 ^ 32'hc761_c23c) ^ (a1 >> 19);
    assign a3 = (a2 + 32'h1656_67b1) + (a2 << 5);
    assign half_d[l*32 +: 32] = a3;
    // Steps 4-6.
    assign b0 = half_q[l*32 +: 32];
    assign b1 = (b0 + 32'hd3a2_646c) ^ (b0 << 9);
    assign b2 = (b1 + 32'hfd70_46c5) + (b1 << 3);
    assign b3 = (b2 ^ 32'hb55a_4f09) ^ (b2 >> 16);
    assign pool_d[l*32 +: 32] = b3;
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      half_q <= half_d;
      pool_q <= pool_d;
    end
  end

  assign pool_o = pool_q;

endmodule
