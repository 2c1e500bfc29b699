// cube5_skewmem_pkg: widths and encodings of the skewed memory controller (cube5_skewmem).
//
// The SystemVerilog reading of docs/numerics/skewmem.md; the Rust model (model/src/units/cube5_skewmem.rs)
// reads the same page independently. Functions assign their name (no `return`) for Yosys 0.23.
package cube5_skewmem_pkg;

  /// Command kinds (the `op` bit).
  localparam logic OpWrite = 1'b0;
  localparam logic OpRead  = 1'b1;

  /// Beam axes (the 2-bit `axis` field; 3 is reserved and behaves as x).
  localparam logic [1:0] AxisX = 2'd0;
  localparam logic [1:0] AxisY = 2'd1;
  localparam logic [1:0] AxisZ = 2'd2;

  /// Bits that name one of P modules (at least 1, so P = 1 needs no zero-width vectors).
  function automatic int unsigned mod_w(int unsigned p);
    mod_w = (p > 1) ? $clog2(p) : 1;
  endfunction

  /// Bits of a block index or block pointer, 3 (MaxDimLog2 - log2 B).
  function automatic int unsigned blk_w(int unsigned max_dim_log2, int unsigned b);
    blk_w = 3 * (max_dim_log2 - $clog2(b));
  endfunction

  /// Bits of one command: op, axis, x, y, z, data, probe.
  function automatic int unsigned in_w(int unsigned p, int unsigned voxel_w,
                                       int unsigned max_dim_log2);
    in_w = 3 + 3 * max_dim_log2 + voxel_w + mod_w(p);
  endfunction

  /// Bits of one response: P lanes, five flags, two counters.
  function automatic int unsigned out_w(int unsigned p, int unsigned voxel_w, int unsigned cnt_w);
    out_w = p * voxel_w + 5 + 2 * cnt_w;
  endfunction

  /// Bits of cfg_addr_i: the register / LUT select bit and a block index.
  function automatic int unsigned cfg_addr_w(int unsigned max_dim_log2, int unsigned b);
    cfg_addr_w = 1 + blk_w(max_dim_log2, b);
  endfunction

  /// Bits of cfg_data_i: the wider of the dimensions register and a LUT entry.
  function automatic int unsigned cfg_data_w(int unsigned max_dim_log2, int unsigned b);
    if (3 * (max_dim_log2 + 1) > blk_w(max_dim_log2, b) + 2) begin
      cfg_data_w = 3 * (max_dim_log2 + 1);
    end else begin
      cfg_data_w = blk_w(max_dim_log2, b) + 2;
    end
  endfunction

endpackage
