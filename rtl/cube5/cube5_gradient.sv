// cube5_gradient: central-difference gradient of interpolated samples on the previous, current and
// next slice (patent [45], [204]-[205]; cube3-paper §4 "ABC gradient estimation"), with a magnitude
// estimate for the shader's classification.
//
// One item is the 3x3x3 block of samples around the sample point. Its 2-bit mode picks the scheme
// (docs/numerics/gradient.md): N6, one difference per axis; N10, z from the next and previous planes
// resampled at the point orthogonal to the sample (bilinear, exact, one rounding); N26, the
// power-of-two inverse-Manhattan weights of the whole block (the 3x3x3 Sobel operator, computed here
// as [1 2 1] x [1 2 1] on the face differences). Magnitude: (30 max + 13 mid + 9 min) / 32, computed
// as 13 sum + 17 max - 4 min, which needs no sorting network, only max and min.
//
// Three register stages: differences and the x-lerps; y-lerps, rounding and the mode select; the
// magnitude. Each holds its item while the next is full, so the unit accepts one item per cycle
// when the output is never stalled and never drops or duplicates an item.
module cube5_gradient #(
  /// Voxel width; samples are U(VoxelW.FracW).
  parameter int unsigned VoxelW  = 12,
  /// Fraction bits of the samples.
  parameter int unsigned FracW   = 4,
  /// Fraction bits of the ray steps dx, dy, S(2.WeightW) (N10 only).
  parameter int unsigned WeightW = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// s[0..26] (sample at offset (i-1, j-1, k-1) at index i + 3j + 9k), dx, dy, mode; LSB first.
  input  logic [cube5_gradient_pkg::gradient_in_w(cube5_pkg::sample_w(VoxelW, FracW),
                                                  WeightW)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// gx, gy, gz (S(VoxelW.(FracW+5)) each), mag (U(VoxelW.(FracW+5))); LSB first.
  output logic [4*cube5_gradient_pkg::grad_w(cube5_pkg::sample_w(VoxelW, FracW))-1:0] out_data_o
);

  localparam int unsigned SampleW  = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned GradW    = cube5_gradient_pkg::grad_w(SampleW);
  localparam int unsigned StepW    = WeightW + 2;       // dx, dy: S(2.WeightW)
  localparam int unsigned EffW     = WeightW + 1;       // clamped |step|, 2^WeightW = 1.0
  localparam int unsigned DiffW    = SampleW + 1;       // difference of two samples, signed
  localparam int unsigned XW       = SampleW + WeightW;     // x-lerp, scale 2^WeightW
  localparam int unsigned YW       = SampleW + 2 * WeightW; // y-lerp, scale 2^(2 WeightW)
  localparam int unsigned RndShift = 2 * WeightW - 4;   // N10: (A - B) / 2^(2W+1) * 2^5
  localparam int unsigned MagSumW  = GradW + 6;         // 13 sum + 17 max - 4 min

  // Elaboration checks mirror GradientConfig::validate in the model.
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_gradient: VoxelW must be 4..16");
  end
  if (FracW > 8) begin : gen_bad_frac_w
    $fatal(1, "cube5_gradient: FracW must be 0..8");
  end
  if (WeightW < 2 || WeightW > 12) begin : gen_bad_weight_w
    $fatal(1, "cube5_gradient: WeightW must be 2..12");
  end

  // ---------------------------------------------------------------------------
  // Input decode
  // ---------------------------------------------------------------------------
  localparam int unsigned DxLsb   = 27 * SampleW;
  localparam int unsigned DyLsb   = DxLsb + StepW;
  localparam int unsigned ModeLsb = DyLsb + StepW;

  logic [27*SampleW-1:0] blk;  // sample at offset (i-1, j-1, k-1) at [blk(i,j,k)*SampleW +: SampleW]
  logic [StepW-1:0]      dx, dy;
  logic [1:0]            mode;
  logic                  is_n10, is_n26;

  assign blk    = in_data_i[0 +: 27*SampleW];
  assign dx     = in_data_i[DxLsb +: StepW];
  assign dy     = in_data_i[DyLsb +: StepW];
  assign mode   = in_data_i[ModeLsb +: 2];
  assign is_n10 = (mode == cube5_gradient_pkg::GradModeN10);
  assign is_n26 = (mode == cube5_gradient_pkg::GradModeN26);

  // The centre sample is carried for a regular block but no scheme reads it.
  logic unused_centre;
  assign unused_centre = ^blk[cube5_gradient_pkg::blk(1, 1, 1)*SampleW +: SampleW];

  // ---------------------------------------------------------------------------
  // Stage handshakes: a stage takes a new item when it is empty or its item moves on
  // ---------------------------------------------------------------------------
  logic valid_1_q, valid_2_q, valid_3_q;
  logic ready_1, ready_2, ready_3;

  assign ready_3    = !valid_3_q || out_ready_i;
  assign ready_2    = !valid_2_q || ready_3;
  assign ready_1    = !valid_1_q || ready_2;
  assign in_ready_o = ready_1;

  // ---------------------------------------------------------------------------
  // Stage 1a: face differences and the N6 / N26 components
  // ---------------------------------------------------------------------------
  // d[(a*9 + p*3 + q)*DiffW +: DiffW] = s(+1 along axis a) - s(-1 along a) at the cross offsets
  // (p-1, q-1) over the two other axes in ascending order (x: (y, z); y: (x, z); z: (x, y)).
  logic [27*DiffW-1:0] d;
  logic [3*GradW-1:0]  g6, g26;  // axis a at [a*GradW +: GradW]

  always_comb begin
    for (int unsigned p = 0; p < 3; p++) begin
      for (int unsigned q = 0; q < 3; q++) begin
        d[(0*9 + p*3 + q)*DiffW +: DiffW] =
            DiffW'(blk[cube5_gradient_pkg::blk(2, p, q)*SampleW +: SampleW])
          - DiffW'(blk[cube5_gradient_pkg::blk(0, p, q)*SampleW +: SampleW]);
        d[(1*9 + p*3 + q)*DiffW +: DiffW] =
            DiffW'(blk[cube5_gradient_pkg::blk(p, 2, q)*SampleW +: SampleW])
          - DiffW'(blk[cube5_gradient_pkg::blk(p, 0, q)*SampleW +: SampleW]);
        d[(2*9 + p*3 + q)*DiffW +: DiffW] =
            DiffW'(blk[cube5_gradient_pkg::blk(p, q, 2)*SampleW +: SampleW])
          - DiffW'(blk[cube5_gradient_pkg::blk(p, q, 0)*SampleW +: SampleW]);
      end
    end
  end

  // N6 is the centre difference times 16; N26 is [1 2 1] along q, then [1 2 1] along p. Every
  // partial sum of N26 is at most 16 differences, so GradW = DiffW + 4 bits hold it exactly.
  for (genvar a = 0; a < 3; a++) begin : gen_axis
    logic [9*GradW-1:0] dd;   // d at cross offset (p, q) at [(p*3 + q)*GradW +: GradW], widened
    logic [3*GradW-1:0] row;  // [1 2 1] along q, at [p*GradW +: GradW]

    always_comb begin
      for (int unsigned p = 0; p < 3; p++) begin
        for (int unsigned q = 0; q < 3; q++) begin
          dd[(p*3 + q)*GradW +: GradW] = GradW'($signed(d[(a*9 + p*3 + q)*DiffW +: DiffW]));
        end
        row[p*GradW +: GradW] = dd[(p*3 + 0)*GradW +: GradW]
                              + (dd[(p*3 + 1)*GradW +: GradW] << 1)
                              + dd[(p*3 + 2)*GradW +: GradW];
      end
    end

    assign g6[a*GradW +: GradW]  = dd[4*GradW +: GradW] << 4;
    assign g26[a*GradW +: GradW] = row[0 +: GradW] + (row[GradW +: GradW] << 1)
                                 + row[2*GradW +: GradW];
  end

  // ---------------------------------------------------------------------------
  // Stage 1b: N10, the lerps along x in the next (k = 2) and previous (k = 0) planes
  // ---------------------------------------------------------------------------
  // The orthogonal point lies at ray offset (-dx, -dy) in the next plane, (+dx, +dy) in the
  // previous one. Its partner rays: next plane i = 0 for dx >= 0 and 2 for dx < 0 (row j the same
  // way from dy); previous plane the mirror image.
  logic              dx_neg, dy_neg;
  logic [StepW-1:0]  dx_abs, dy_abs;
  logic [EffW-1:0]   ex, ey;

  assign dx_neg = dx[StepW-1];
  assign dy_neg = dy[StepW-1];
  assign dx_abs = dx_neg ? StepW'(-dx) : dx;  // -(-2^(W+1)) = 2^(W+1) still fits unsigned
  assign dy_abs = dy_neg ? StepW'(-dy) : dy;
  assign ex     = (dx_abs > StepW'(1 << WeightW)) ? EffW'(1 << WeightW) : dx_abs[EffW-1:0];
  assign ey     = (dy_abs > StepW'(1 << WeightW)) ? EffW'(1 << WeightW) : dy_abs[EffW-1:0];

  // Sample at block coordinates (i, j, k).
  function automatic logic [SampleW-1:0] smp(logic [27*SampleW-1:0] b, int unsigned i,
                                             int unsigned j, int unsigned k);
    smp = b[cube5_gradient_pkg::blk(i, j, k)*SampleW +: SampleW];
  endfunction

  // The four x-lerps, l = 0, 1: next plane (k = 2) rows j = 1 and the partner row; l = 2, 3:
  // previous plane (k = 0) likewise. a is the sample on the ray's own column (i = 1), b the partner.
  logic [4*SampleW-1:0] lx_a, lx_b;
  logic [4*XW-1:0]      lx_y;

  always_comb begin
    lx_a[0*SampleW +: SampleW] = smp(blk, 1, 1, 2);
    lx_b[0*SampleW +: SampleW] = dx_neg ? smp(blk, 2, 1, 2) : smp(blk, 0, 1, 2);
    lx_a[1*SampleW +: SampleW] = dy_neg ? smp(blk, 1, 2, 2) : smp(blk, 1, 0, 2);
    lx_b[1*SampleW +: SampleW] = dy_neg ? (dx_neg ? smp(blk, 2, 2, 2) : smp(blk, 0, 2, 2))
                                        : (dx_neg ? smp(blk, 2, 0, 2) : smp(blk, 0, 0, 2));
    lx_a[2*SampleW +: SampleW] = smp(blk, 1, 1, 0);
    lx_b[2*SampleW +: SampleW] = dx_neg ? smp(blk, 0, 1, 0) : smp(blk, 2, 1, 0);
    lx_a[3*SampleW +: SampleW] = dy_neg ? smp(blk, 1, 0, 0) : smp(blk, 1, 2, 0);
    lx_b[3*SampleW +: SampleW] = dy_neg ? (dx_neg ? smp(blk, 0, 0, 0) : smp(blk, 2, 0, 0))
                                        : (dx_neg ? smp(blk, 0, 2, 0) : smp(blk, 2, 2, 0));
  end

  for (genvar l = 0; l < 4; l++) begin : gen_lerp_x
    cube5_gradient_lerp #(
      .ValW    (SampleW),
      .WeightW (WeightW)
    ) u_lerp (
      .a_i (lx_a[l*SampleW +: SampleW]),
      .b_i (lx_b[l*SampleW +: SampleW]),
      .e_i (ex),
      .y_o (lx_y[l*XW +: XW])
    );
  end

  // ---------------------------------------------------------------------------
  // Stage 1 registers
  // ---------------------------------------------------------------------------
  logic [4*XW-1:0]    lx_q;          // next row 1, next partner row, previous likewise
  logic [3*GradW-1:0] g1_d, g1_q;    // x, y final; z final unless N10
  logic [EffW-1:0]    ey_q;
  logic               is_n10_q;

  assign g1_d = is_n26 ? g26 : g6;

  // ---------------------------------------------------------------------------
  // Stage 2: N10 lerps along y, A - B, one rounding; the z select
  // ---------------------------------------------------------------------------
  logic [YW-1:0] plane_next, plane_prev;

  cube5_gradient_lerp #(
    .ValW    (XW),
    .WeightW (WeightW)
  ) u_lerp_y_next (
    .a_i (lx_q[0*XW +: XW]),
    .b_i (lx_q[1*XW +: XW]),
    .e_i (ey_q),
    .y_o (plane_next)
  );

  cube5_gradient_lerp #(
    .ValW    (XW),
    .WeightW (WeightW)
  ) u_lerp_y_prev (
    .a_i (lx_q[2*XW +: XW]),
    .b_i (lx_q[3*XW +: XW]),
    .e_i (ey_q),
    .y_o (plane_prev)
  );

  // A, B < 2^YW, so A - B and the rounding half fit YW + 2 signed bits; after the shift by
  // 2W - 4 the value is within the component bound and the low GradW bits are exact.
  localparam int unsigned DW = YW + 2;

  logic signed [DW-1:0] diff_ab, diff_rnd, diff_shifted;
  logic [GradW-1:0]     gz10;

  assign diff_ab = $signed(DW'(plane_next)) - $signed(DW'(plane_prev));
  if (RndShift == 0) begin : gen_rnd_none
    assign diff_rnd = diff_ab;
  end else begin : gen_rnd_half_up
    assign diff_rnd = diff_ab + $signed(DW'(1) << (RndShift - 1));
  end
  assign diff_shifted = diff_rnd >>> RndShift;
  assign gz10         = diff_shifted[GradW-1:0];

  logic unused_diff_shifted;
  assign unused_diff_shifted = ^diff_shifted[DW-1:GradW];

  logic [3*GradW-1:0] g2_d, g2_q;

  assign g2_d = {is_n10_q ? gz10 : g1_q[2*GradW +: GradW], g1_q[0 +: 2*GradW]};

  // ---------------------------------------------------------------------------
  // Stage 3: magnitude, 30 M + 13 m + 9 n = 13 (M + m + n) + 17 M - 4 n, rounded half up by 5
  // ---------------------------------------------------------------------------
  logic [3*GradW-1:0] mag_abs;  // |g| of axis a at [a*GradW +: GradW]
  logic [GradW-1:0]   mag_max, mag_min;
  logic [MagSumW-1:0] mag_sum, mag_rnd;
  logic [GradW-1:0]   mag;

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      logic [GradW-1:0] g;
      g = g2_q[a*GradW +: GradW];
      mag_abs[a*GradW +: GradW] = g[GradW-1] ? GradW'(-g) : g;  // never the most negative code
    end
    mag_max = mag_abs[0 +: GradW];
    mag_min = mag_abs[0 +: GradW];
    for (int unsigned a = 1; a < 3; a++) begin
      if (mag_abs[a*GradW +: GradW] > mag_max) mag_max = mag_abs[a*GradW +: GradW];
      if (mag_abs[a*GradW +: GradW] < mag_min) mag_min = mag_abs[a*GradW +: GradW];
    end
    mag_sum = MagSumW'(13) * (MagSumW'(mag_abs[0 +: GradW]) + MagSumW'(mag_abs[GradW +: GradW])
                              + MagSumW'(mag_abs[2*GradW +: GradW]))
            + MagSumW'(17) * MagSumW'(mag_max) - (MagSumW'(mag_min) << 2);
    mag_rnd = (mag_sum + MagSumW'(16)) >> 5;
    mag     = mag_rnd[GradW-1:0];  // at most 26 (2^SampleW - 1) < 2^GradW
  end

  logic unused_mag_rnd;
  assign unused_mag_rnd = ^mag_rnd[MagSumW-1:GradW];

  logic [4*GradW-1:0] out_d, out_q;
  assign out_d = {mag, g2_q};

  // ---------------------------------------------------------------------------
  // Registers: valids reset (synchronously), datapath not
  // ---------------------------------------------------------------------------
  logic valid_1_d, valid_2_d, valid_3_d;
  assign valid_1_d = ready_1 ? in_valid_i : valid_1_q;
  assign valid_2_d = ready_2 ? valid_1_q  : valid_2_q;
  assign valid_3_d = ready_3 ? valid_2_q  : valid_3_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      valid_1_q <= 1'b0;
      valid_2_q <= 1'b0;
      valid_3_q <= 1'b0;
    end else begin
      valid_1_q <= valid_1_d;
      valid_2_q <= valid_2_d;
      valid_3_q <= valid_3_d;
    end
  end

  always_ff @(posedge clk_i) begin
    if (ready_1) begin
      lx_q     <= lx_y;
      g1_q     <= g1_d;
      ey_q     <= ey;
      is_n10_q <= is_n10;
    end
    if (ready_2) begin
      g2_q <= g2_d;
    end
    if (ready_3) begin
      out_q <= out_d;
    end
  end

  assign out_valid_o = valid_3_q;
  assign out_data_o  = out_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_gradient: output changed while stalled");
`endif

endmodule
