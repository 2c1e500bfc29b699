// gicube_sample_pkg: widths and the configuration address map of gicube_sample
// (docs/numerics/gicube_sample.md, "The RTL"). Functions assign their name (no `return`) for
// Yosys 0.23.
package gicube_sample_pkg;

  /// Weight bits per axis, U(0.8): the fraction of the packet's start position.
  localparam int unsigned WeightW = 8;
  /// Fraction bits of the density sample, U(VoxelW.4).
  localparam int unsigned SampleFracW = 4;
  /// Irradiance bits, U(2.14), per corner and for the interpolated value.
  localparam int unsigned IrrW = 16;
  localparam int unsigned IrrFracW = 14;
  /// Bits of one packet channel (red, green, blue, opacity), U(0.12).
  localparam int unsigned ChanW = 12;
  /// Classified colour and alpha widths (cube5_shader's ColorW, AlphaW).
  localparam int unsigned ColorW = 8;
  localparam int unsigned AlphaW = 12;

  /// Configuration address bits: the region bit over cube5_compos's AlphaW + 1 word address.
  localparam int unsigned CfgAddrW = AlphaW + 2;
  /// Configuration data bits: one classification entry r, g, b, a.
  localparam int unsigned CfgDataW = 3 * ColorW + AlphaW;
  /// Region bit values: the classification table, or cube5_compos's words (table, registers).
  localparam logic RegionClass  = 1'b0;
  localparam logic RegionCompos = 1'b1;

  /// Bits of one input item: voxels, weights, irr_en, irr corners, colour, opacity, lighting.
  function automatic int unsigned in_w(int unsigned voxel_w);
    in_w = 8 * voxel_w + 3 * WeightW + 1 + 8 * IrrW + 3 * ChanW + ChanW + 1;
  endfunction

  /// Jitter (Jitter = 1; contract "Jitter and the power LUT"): random LUT index and entry bits
  /// (r = (2^7 + J) / 2^8), log LUT entry bits (U(4.12)), power LUT index and difference bits.
  localparam int unsigned JitIdxW  = 8;
  localparam int unsigned JitW     = 7;
  localparam int unsigned LogW     = 16;
  localparam int unsigned ExpIdxW  = 10;
  localparam int unsigned ExpDiffW = 7;

  /// Shading (Shade = 1; contract "Gradient, tag and reflectance map"): the decoded gradient
  /// component bits ([378]: 3 x 10), and the input bits the corners' gradient indices and tags
  /// add after `lighting`.
  localparam int unsigned GradCompW = 10;
  function automatic int unsigned shade_in_w(int unsigned shade, int unsigned grad_idx_w,
                                             int unsigned tag_w);
    shade_in_w = shade * 8 * (grad_idx_w + tag_w);
  endfunction

  /// Shading's tables sit above the other regions: configuration address bit 14 (one more bit).
  function automatic int unsigned cfg_addr_w(int unsigned shade);
    cfg_addr_w = CfgAddrW + shade;
  endfunction

  /// Bits of one output item: colour, opacity, terminated.
  localparam int unsigned OutW = 3 * ChanW + ChanW + 1;

  /// cube5_shader's classification index bits: min(12, VoxelW + 4).
  function automatic int unsigned class_idx_w(int unsigned voxel_w);
    class_idx_w = (voxel_w + SampleFracW < 12) ? voxel_w + SampleFracW : 12;
  endfunction

endpackage
