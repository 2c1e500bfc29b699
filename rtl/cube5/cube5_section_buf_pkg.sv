// cube5_section_buf_pkg: port widths of the section buffer (cube5_section_buf).
//
// The SystemVerilog reading of docs/numerics/section_buf.md; the Rust model
// (model/src/units/cube5_section_buf.rs) reads the same page independently. The item fields are
// cube5_vol_fetch's (its package). Functions assign their name (no `return`) for Yosys 0.23.
package cube5_section_buf_pkg;

  /// Bits of one input: op, then the longer of a fetch item (cube5_vol_fetch's output item) and a
  /// section command.
  function automatic int unsigned in_w(int unsigned p, int unsigned voxel_w, int unsigned max_dim,
                                       int unsigned b);
    int unsigned m, item, cmd;
    m    = $clog2(max_dim);
    item = cube5_vol_fetch_pkg::out_w(p, voxel_w, max_dim, b);
    cmd  = 3 + 3 * (m + 1) + m;
    in_w = 1 + ((item > cmd) ? item : cmd);
  endfunction

  /// Bits of one beam: P lanes and three edge voxels, five flags.
  function automatic int unsigned out_w(int unsigned p, int unsigned voxel_w);
    out_w = (p + 3) * voxel_w + 5;
  endfunction

endpackage
