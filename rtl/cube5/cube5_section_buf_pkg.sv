// cube5_section_buf_pkg: port widths of the section buffer (cube5_section_buf).
//
// The SystemVerilog reading of docs/numerics/section_buf.md; the Rust model
// (model/src/units/cube5_section_buf.rs) reads the same page independently. Functions assign their
// name (no `return`) for Yosys 0.23.
package cube5_section_buf_pkg;

  /// NbW: bits of a block coordinate, log2(MaxDim / B).
  function automatic int unsigned nb_w(int unsigned max_dim, int unsigned b);
    nb_w = $clog2(max_dim / b);
  endfunction

  /// WordW: bits of a P-group index inside a block, max(1, log2(B^3 / P)).
  function automatic int unsigned word_w(int unsigned p, int unsigned b);
    word_w = (b * b * b / p > 2) ? $clog2(b * b * b / p) : 1;
  endfunction

  /// Bits of one input: op, then the longer of a fetch item and a section command.
  function automatic int unsigned in_w(int unsigned p, int unsigned voxel_w, int unsigned max_dim,
                                       int unsigned b);
    int unsigned m, item, cmd;
    m    = $clog2(max_dim);
    item = p * voxel_w + 3 * nb_w(max_dim, b) + word_w(p, b) + 4;
    cmd  = 3 + 3 * (m + 1) + m;
    in_w = 1 + ((item > cmd) ? item : cmd);
  endfunction

  /// Bits of one beam: P lanes and three edge voxels, five flags.
  function automatic int unsigned out_w(int unsigned p, int unsigned voxel_w);
    out_w = (p + 3) * voxel_w + 5;
  endfunction

endpackage
