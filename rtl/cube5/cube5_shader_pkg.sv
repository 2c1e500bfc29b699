// cube5_shader_pkg: widths and encodings of cube5_shader (docs/numerics/shader.md).
//
// The SystemVerilog reading of the shader's contract page; the Rust model (model/src/units/cube5_shader.rs)
// reads the same page independently. Functions assign their name (no `return`) for Yosys 0.23.
package cube5_shader_pkg;

  /// Bits of the per-item mode field.
  localparam int unsigned ModeTf2d  = 0;  // classify by density and gradient magnitude
  localparam int unsigned ModeUnlit = 1;  // skip illumination

  /// Configuration regions (the top two address bits).
  localparam logic [1:0] RegionClass = 2'd0;
  localparam logic [1:0] RegionTexel = 2'd1;
  localparam logic [1:0] RegionZero  = 2'd2;

  /// Sample width, U(VoxelW.FracW).
  function automatic int unsigned sample_w(int unsigned voxel_w, int unsigned frac_w);
    sample_w = voxel_w + frac_w;
  endfunction

  /// Gradient component width, S(VoxelW+2 . FracW); the magnitude is as wide, unsigned.
  function automatic int unsigned grad_w(int unsigned voxel_w, int unsigned frac_w);
    grad_w = voxel_w + 2 + frac_w;
  endfunction

  /// Bits of one input item: sample, gx, gy, gz, mag, mode.
  function automatic int unsigned in_w(int unsigned voxel_w, int unsigned frac_w);
    in_w = sample_w(voxel_w, frac_w) + 4 * grad_w(voxel_w, frac_w) + 2;
  endfunction

  /// Bits of one output item (and of one classification entry): r, g, b, a.
  function automatic int unsigned rgba_w(int unsigned color_w, int unsigned alpha_w);
    rgba_w = 3 * color_w + alpha_w;
  endfunction

  /// Configuration address bits: two region bits over the widest region offset.
  function automatic int unsigned cfg_addr_w(int unsigned class_idx_w, int unsigned rm_log2);
    int unsigned texel_w;
    texel_w = 3 + 2 * (rm_log2 + 1);
    cfg_addr_w = 2 + ((class_idx_w > texel_w) ? class_idx_w : texel_w);
  endfunction

  /// Configuration data bits: a classification entry or a texel, whichever is wider.
  function automatic int unsigned cfg_data_w(int unsigned color_w, int unsigned alpha_w,
                                             int unsigned diff_w, int unsigned spec_w);
    int unsigned rgba;
    rgba = rgba_w(color_w, alpha_w);
    cfg_data_w = (rgba > diff_w + spec_w) ? rgba : diff_w + spec_w;
  endfunction

  /// Quotient bits of a face coordinate, QW = RmLog2 + RmFracW + 1.
  function automatic int unsigned quotient_w(int unsigned rm_log2, int unsigned rm_frac_w);
    quotient_w = rm_log2 + rm_frac_w + 1;
  endfunction

  /// Quotient bits per divider pipeline stage (one compare-and-subtract each). The contract's
  /// latency assumes 1; 2 halves the divider's stages at about 3/4 of the clock rate.
  localparam int unsigned DivBitsPerStage = 1;

  /// Divider pipeline stages.
  function automatic int unsigned div_stages(int unsigned rm_log2, int unsigned rm_frac_w);
    div_stages = (quotient_w(rm_log2, rm_frac_w) + DivBitsPerStage - 1) / DivBitsPerStage;
  endfunction

  /// Texel-bank side M = 2^(RmLog2-1) + 1: half-indices i >> 1 of one parity run 0 .. M-1.
  function automatic int unsigned bank_side(int unsigned rm_log2);
    bank_side = (1 << (rm_log2 - 1)) + 1;
  endfunction

endpackage
