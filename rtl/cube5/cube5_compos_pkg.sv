// cube5_compos_pkg: widths, mode codes and configuration addresses of cube5_compos.
//
// The SystemVerilog reading of docs/numerics/compos.md; the Rust model (model/src/units/cube5_compos.rs) reads
// the same page independently. Functions assign their name (no `return`) so Yosys 0.23 accepts them.
package cube5_compos_pkg;

  // ---------------------------------------------------------------------------
  // The 3-bit `mode` field of a sample
  // ---------------------------------------------------------------------------
  localparam logic [2:0] ModeFrontToBack = 3'd0;
  localparam logic [2:0] ModeBackToFront = 3'd1;
  localparam logic [2:0] ModeMax         = 3'd2;
  localparam logic [2:0] ModeMin         = 3'd3;
  localparam logic [2:0] ModeXraySum     = 3'd4;
  localparam logic [2:0] ModeFirstOpaque = 3'd5;
  localparam logic [2:0] ModeFlush       = 3'd6;
  localparam logic [2:0] ModeReserved    = 3'd7;

  // ---------------------------------------------------------------------------
  // Configuration registers: address 2^AlphaW + offset (table entries below that)
  // ---------------------------------------------------------------------------
  localparam int unsigned RegCtrl        = 0;  // bit 0 LutBypass, bits 4:1 XrayShift
  localparam int unsigned RegEtThreshold = 1;
  localparam int unsigned RegFoThreshold = 2;

  /// Bits of one coxel: R, G, B, A (AccW+1 each), Z, geometry R, G, B, terminated.
  function automatic int unsigned coxel_w(int unsigned color_w, int unsigned acc_w,
                                          int unsigned z_w);
    coxel_w = 4 * (acc_w + 1) + z_w + 3 * color_w + 1;
  endfunction

  /// Bits of one sample: r, g, b, alpha, depth, mode.
  function automatic int unsigned sample_w(int unsigned color_w, int unsigned alpha_w,
                                           int unsigned z_w);
    sample_w = 3 * color_w + alpha_w + z_w + 3;
  endfunction

  /// Bits of one input item: the coxel, then the sample.
  function automatic int unsigned in_w(int unsigned color_w, int unsigned alpha_w,
                                       int unsigned acc_w, int unsigned z_w);
    in_w = coxel_w(color_w, acc_w, z_w) + sample_w(color_w, alpha_w, z_w);
  endfunction

  /// Fraction bits of the colour stage's multiplier operand: max(Q, min(2 ColorW, AccW)). Colours
  /// read at 2 ColorW bits and the corrected alpha at Q bits have no lower bits to multiply.
  function automatic int unsigned mul_scale(int unsigned color_w, int unsigned q,
                                            int unsigned acc_w);
    int unsigned c;
    c = (2 * color_w < acc_w) ? 2 * color_w : acc_w;
    mul_scale = (c > q) ? c : q;
  endfunction

endpackage
