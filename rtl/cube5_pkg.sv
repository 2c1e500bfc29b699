// cube5_pkg: widths and encodings shared by the Cube-5 pipeline units.
//
// The numbers here are the SystemVerilog reading of docs/numerics.md; the Rust model reads the same
// page independently. Functions assign their name (no `return`) so Yosys 0.23 accepts them.
package cube5_pkg;

  // ---------------------------------------------------------------------------
  // Tri-linear interpolation (docs/numerics.md, cube5_trilin)
  // ---------------------------------------------------------------------------

  /// Weight modes of the 2-bit `mode` field.
  localparam logic [1:0] TrilinModeLerp   = 2'd0;
  localparam logic [1:0] TrilinModeHalf   = 2'd1;
  localparam logic [1:0] TrilinModeSelect = 2'd2;

  /// Bits of one trilin input item: 8 voxels, 3 weights, the mode.
  function automatic int unsigned trilin_in_w(int unsigned voxel_w, int unsigned weight_w);
    trilin_in_w = 8 * voxel_w + 3 * weight_w + 2;
  endfunction

  /// Bits of one sample, U(VoxelW.FracW).
  function automatic int unsigned sample_w(int unsigned voxel_w, int unsigned frac_w);
    sample_w = voxel_w + frac_w;
  endfunction

endpackage
