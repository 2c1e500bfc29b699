// cube5_vol_fetch_pkg: port widths of the volume fetch unit (cube5_vol_fetch).
//
// The SystemVerilog reading of docs/numerics/vol_fetch.md; the Rust model
// (model/src/units/cube5_vol_fetch.rs) reads the same page independently. Functions assign their
// name (no `return`) for Yosys 0.23, which also needs port widths from functions rather than from
// localparams declared after the ports.
package cube5_vol_fetch_pkg;

  /// NbW: bits of a block coordinate, log2(MaxDim / B).
  function automatic int unsigned nb_w(int unsigned max_dim, int unsigned b);
    nb_w = $clog2(max_dim / b);
  endfunction

  /// WordW: bits of a P-group index inside a block, max(1, log2(B^3 / P)).
  function automatic int unsigned word_w(int unsigned p, int unsigned b);
    word_w = (b * b * b / p > 2) ? $clog2(b * b * b / p) : 1;
  endfunction

  /// Bits of one command: op, then the longer of a LUT write (2 BlkW + 2) and a sweep.
  function automatic int unsigned cmd_w(int unsigned addr_w, int unsigned max_dim,
                                        int unsigned b);
    int unsigned nbw, lut, sweep;
    nbw   = nb_w(max_dim, b);
    lut   = 6 * nbw + 2;
    sweep = addr_w + 3 * (nbw + 1) + 3 + nbw + nbw + 1;
    cmd_w = 1 + ((lut > sweep) ? lut : sweep);
  endfunction

  /// Bits of one output item: P lanes, the block, the word, four flags.
  function automatic int unsigned out_w(int unsigned p, int unsigned voxel_w, int unsigned max_dim,
                                        int unsigned b);
    out_w = p * voxel_w + 3 * nb_w(max_dim, b) + word_w(p, b) + 4;
  endfunction

endpackage
