// cube5_gradient_pkg: widths and encodings of the gradient stage, cube5_gradient and cube5_sepconv.
//
// The SystemVerilog reading of docs/numerics/gradient.md and docs/numerics/sepconv.md; the Rust
// model reads the same pages independently. Functions assign their name (no `return`) for Yosys.
package cube5_gradient_pkg;

  // ---------------------------------------------------------------------------
  // cube5_gradient (docs/numerics/gradient.md)
  // ---------------------------------------------------------------------------

  /// Neighbourhood schemes of the 2-bit `mode` field (3 is reserved and behaves as N6).
  localparam logic [1:0] GradModeN6  = 2'd0;
  localparam logic [1:0] GradModeN10 = 2'd1;
  localparam logic [1:0] GradModeN26 = 2'd2;

  /// Fraction bits the output adds to the samples' (N26's division by 32 is exact).
  localparam int unsigned GradGuardW = 5;

  /// Bits of one input item: 27 samples, dx and dy (S(2.WeightW)), the mode.
  function automatic int unsigned gradient_in_w(int unsigned sample_w, int unsigned weight_w);
    gradient_in_w = 27 * sample_w + 2 * (weight_w + 2) + 2;
  endfunction

  /// Bits of each output field, S(VoxelW.(FracW+5)) and U(VoxelW.(FracW+5)).
  function automatic int unsigned grad_w(int unsigned sample_w);
    grad_w = sample_w + GradGuardW;
  endfunction

  /// Block index of the sample at offset (i-1, j-1, k-1), with i, j, k in 0..2.
  function automatic int unsigned blk(int unsigned i, int unsigned j, int unsigned k);
    blk = i + 3 * j + 9 * k;
  endfunction

  // ---------------------------------------------------------------------------
  // cube5_sepconv (docs/numerics/sepconv.md)
  // ---------------------------------------------------------------------------

  /// The 1-bit `kernel` field.
  localparam logic SepKernelSmooth = 1'b0;  // {1 w 1}
  localparam logic SepKernelDiff   = 1'b1;  // {-1 0 1}

  /// Configuration port: address width and the address of the centre weight.
  localparam int unsigned SepCfgAddrW = 4;
  localparam logic [SepCfgAddrW-1:0] SepCfgAddrW0 = '0;

  /// Integer bits of the centre weight w, U(4.WeightFracW).
  localparam int unsigned SepWeightIntW = 4;

  /// Bits of the exact result a + w b + c: never overflows.
  function automatic int unsigned sepconv_exact_w(int unsigned tap_w, int unsigned weight_frac_w);
    sepconv_exact_w = tap_w + weight_frac_w + 5;
  endfunction

endpackage
