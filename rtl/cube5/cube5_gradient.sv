// cube5_gradient: central-difference gradient of interpolated samples on the previous, current and
// next slice (patent [45], [204]-[205]; cube3-paper §4 "ABC gradient estimation"), with a magnitude
// estimate for the shader's classification.
//
// One item is the 3x3x3 block of samples around the sample point. Its 2-bit mode picks the scheme
// (docs/numerics/gradient.md). N6: one difference per axis. N10: z from the next and previous
// planes resampled at the point orthogonal to the sample. N26: the power-of-two inverse-Manhattan
// weights of the whole block, i.e. the 3x3x3 Sobel operator, computed as [1 2 1] x [1 2 1] on the
// face differences.
//
// N10's A - B is linear in the samples, so it is computed as one bilinear interpolation of the four
// next-minus-previous differences (two lerps along x, one along y, all exact, the rounding half
// folded into the last sum): three multipliers instead of six. Magnitude: (30 max + 13 mid +
// 9 min) / 32 as 13 sum + 17 max - 4 min, which needs only the largest and smallest component and
// no multiplier.
//
// Five register stages, each about one lerp deep: (1) differences, steps, N26 row sums; (2) x-lerps,
// N26 sums, the x/y select; (3) y-lerp, rounding, the z select; (4) |g|, their sum, max, min;
// (5) the magnitude. Each holds its item while the next is full, so the unit accepts one item per
// cycle when the output is never stalled and never drops or duplicates an item.
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
  localparam int unsigned StepW    = WeightW + 2;            // dx, dy: S(2.WeightW)
  localparam int unsigned EffW     = WeightW + 1;            // clamped |step|, 2^WeightW = 1.0
  localparam int unsigned DiffW    = SampleW + 1;            // difference of two samples, signed
  localparam int unsigned HW       = DiffW + 1;              // difference of two differences
  localparam int unsigned HhW      = HW + 1;                 // the bilinear cross term
  localparam int unsigned XW       = DiffW + WeightW;        // t0: x-lerp of row 0, signed
  localparam int unsigned XdW      = HW + WeightW;           // t1 - t0: x-lerp of row differences
  localparam int unsigned YW       = XW + WeightW;           // A - B (+ half), signed
  localparam int unsigned RndShift = 2 * WeightW - 4;        // (A - B) / 2^(2W+1) * 2^5
  localparam int unsigned RndHalf  = (RndShift == 0) ? 0 : (1 << (RndShift - 1));
  localparam int unsigned SumAbsW  = GradW + 1;              // |gx| + |gy| + |gz|
  localparam int unsigned MagSumW  = GradW + 6;              // 13 sum + 17 max - 4 min + 16

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

  // Sample at block coordinates (i, j, k), widened to a signed difference operand.
  function automatic logic [DiffW-1:0] smp(logic [27*SampleW-1:0] b, int unsigned i,
                                           int unsigned j, int unsigned k);
    smp = DiffW'(b[cube5_gradient_pkg::blk(i, j, k)*SampleW +: SampleW]);
  endfunction

  // ---------------------------------------------------------------------------
  // Stage handshakes: a stage takes a new item when it is empty or its item moves on
  // ---------------------------------------------------------------------------
  logic ready_1, ready_2, ready_3, ready_4, ready_5;

  cube5_valid_chain #(
    .Stages (5)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     ({ready_5, ready_4, ready_3, ready_2, ready_1}),
    .out_valid_o (out_valid_o)
  );
  assign in_ready_o = ready_1;

  // ---------------------------------------------------------------------------
  // Stage 1a: face differences; N6 components and the N26 rows
  // ---------------------------------------------------------------------------
  // d of axis a at cross offset (p, q) over the two other axes in ascending order
  // (x: (y, z); y: (x, z); z: (x, y)) is s(+1 along a) - s(-1 along a). N6 is the centre
  // difference times 16. N26 is [1 2 1] along q here, then [1 2 1] along p in stage 2. Every
  // partial sum of N26 is at most 16 differences, so GradW = DiffW + 4 bits hold it exactly.
  logic [3*GradW-1:0] g6_d;    // axis a at [a*GradW +: GradW]
  logic [9*GradW-1:0] rows_d;  // axis a, row p at [(a*3 + p)*GradW +: GradW]

  for (genvar a = 0; a < 3; a++) begin : gen_axis_diff
    logic [9*GradW-1:0] dd;  // d at (p, q) at [(p*3 + q)*GradW +: GradW], sign-extended

    always_comb begin
      for (int unsigned p = 0; p < 3; p++) begin
        for (int unsigned q = 0; q < 3; q++) begin
          logic [DiffW-1:0] hi, lo;
          if (a == 0) begin
            hi = smp(blk, 2, p, q);
            lo = smp(blk, 0, p, q);
          end else if (a == 1) begin
            hi = smp(blk, p, 2, q);
            lo = smp(blk, p, 0, q);
          end else begin
            hi = smp(blk, p, q, 2);
            lo = smp(blk, p, q, 0);
          end
          dd[(p*3 + q)*GradW +: GradW] = GradW'($signed(hi - lo));
        end
        rows_d[(a*3 + p)*GradW +: GradW] = dd[(p*3 + 0)*GradW +: GradW]
                                         + (dd[(p*3 + 1)*GradW +: GradW] << 1)
                                         + dd[(p*3 + 2)*GradW +: GradW];
      end
    end

    assign g6_d[a*GradW +: GradW] = dd[4*GradW +: GradW] << 4;
  end

  // ---------------------------------------------------------------------------
  // Stage 1b: N10, the clamped steps and the four next-minus-previous differences
  // ---------------------------------------------------------------------------
  // The orthogonal point lies at ray offset (-dx, -dy) in the next plane (k = 2) and (+dx, +dy) in
  // the previous one (k = 0). The partner column in the next plane is i = 0 for dx >= 0, 2 for
  // dx < 0, mirrored in the previous plane; rows likewise from dy. e(u, v) pairs the sample at
  // partner offsets (u, v) of the next plane with its mirror in the previous plane, so that
  // A - B = bilinear interpolation of e with weights (ex, ey).
  logic             dx_neg, dy_neg;
  logic [StepW-1:0] dx_abs, dy_abs;
  logic [EffW-1:0]  ex_d, ey_d;

  assign dx_neg = dx[StepW-1];
  assign dy_neg = dy[StepW-1];
  assign dx_abs = dx_neg ? StepW'(-dx) : dx;  // -(-2^(W+1)) = 2^(W+1) still fits unsigned
  assign dy_abs = dy_neg ? StepW'(-dy) : dy;
  assign ex_d   = (dx_abs > StepW'(1 << WeightW)) ? EffW'(1 << WeightW) : dx_abs[EffW-1:0];
  assign ey_d   = (dy_abs > StepW'(1 << WeightW)) ? EffW'(1 << WeightW) : dy_abs[EffW-1:0];

  logic [4*DiffW-1:0] e_d;  // e(u, v) at [(v*2 + u)*DiffW +: DiffW]

  // Constant block indices and 2:1 muxes on the step signs (a variable index would make a shifter
  // over the whole block).
  always_comb begin
    e_d[0*DiffW +: DiffW] = smp(blk, 1, 1, 2) - smp(blk, 1, 1, 0);
    e_d[1*DiffW +: DiffW] = dx_neg ? smp(blk, 2, 1, 2) - smp(blk, 0, 1, 0)
                                   : smp(blk, 0, 1, 2) - smp(blk, 2, 1, 0);
    e_d[2*DiffW +: DiffW] = dy_neg ? smp(blk, 1, 2, 2) - smp(blk, 1, 0, 0)
                                   : smp(blk, 1, 0, 2) - smp(blk, 1, 2, 0);
    unique case ({dy_neg, dx_neg})
      2'b00:   e_d[3*DiffW +: DiffW] = smp(blk, 0, 0, 2) - smp(blk, 2, 2, 0);
      2'b01:   e_d[3*DiffW +: DiffW] = smp(blk, 2, 0, 2) - smp(blk, 0, 2, 0);
      2'b10:   e_d[3*DiffW +: DiffW] = smp(blk, 0, 2, 2) - smp(blk, 2, 0, 0);
      default: e_d[3*DiffW +: DiffW] = smp(blk, 2, 2, 2) - smp(blk, 0, 0, 0);
    endcase
  end

  // The y-lerp needs t0 and t1 - t0, where t_v is the x-lerp of row v; by linearity t1 - t0 is the
  // x-lerp of the row differences. Each lerp takes its endpoint difference ready-made, so stage 2 is
  // one multiply and one sum per lerp:
  //   t0      = e00 * 2^W + ex * df,  df = e10 - e00
  //   t1 - t0 = h0  * 2^W + ex * dh,  h0 = e01 - e00,  dh = (e11 - e01) - (e10 - e00)
  logic signed [DiffW-1:0] e00, e10, e01, e11;
  logic signed [HW-1:0]    df_d, h0_d;
  logic signed [HhW-1:0]   dh_d;

  always_comb begin
    e00  = $signed(e_d[0*DiffW +: DiffW]);
    e10  = $signed(e_d[1*DiffW +: DiffW]);
    e01  = $signed(e_d[2*DiffW +: DiffW]);
    e11  = $signed(e_d[3*DiffW +: DiffW]);
    df_d = HW'(e10) - HW'(e00);
    h0_d = HW'(e01) - HW'(e00);
    dh_d = HhW'(HW'(e11) - HW'(e01)) - HhW'(df_d);
  end

  // ---------------------------------------------------------------------------
  // Stage 1 registers
  // ---------------------------------------------------------------------------
  logic [3*GradW-1:0] g6_q;
  logic [9*GradW-1:0] rows_q;
  logic [DiffW-1:0]   e00_q;
  logic [HW-1:0]      df_q, h0_q;
  logic [HhW-1:0]     dh_q;
  logic [EffW-1:0]    ex_q, ey_q;
  logic               is_n10_q, is_n26_q;

  // ---------------------------------------------------------------------------
  // Stage 2: N26 sums along p and the x/y select; N10 lerps along x
  // ---------------------------------------------------------------------------
  logic [3*GradW-1:0] g26;
  logic [3*GradW-1:0] g12_d, g12_q;  // x, y final; z final unless N10

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      g26[a*GradW +: GradW] = rows_q[(a*3 + 0)*GradW +: GradW]
                            + (rows_q[(a*3 + 1)*GradW +: GradW] << 1)
                            + rows_q[(a*3 + 2)*GradW +: GradW];
    end
    g12_d = is_n26_q ? g26 : g6_q;
  end

  logic [XW-1:0]  t0_d, t0_q;
  logic [XdW-1:0] dt_d, dt_q;

  cube5_gradient_lerp #(
    .ValW    (DiffW),
    .DiffW   (HW),
    .WeightW (WeightW),
    .OutW    (XW)
  ) u_lerp_x_row (
    .a_i (e00_q),
    .d_i (df_q),
    .e_i (ex_q),
    .y_o (t0_d)
  );

  cube5_gradient_lerp #(
    .ValW    (HW),
    .DiffW   (HhW),
    .WeightW (WeightW),
    .OutW    (XdW)
  ) u_lerp_x_rowdiff (
    .a_i (h0_q),
    .d_i (dh_q),
    .e_i (ex_q),
    .y_o (dt_d)
  );

  logic [EffW-1:0] ey_q2;
  logic            is_n10_q2;

  // ---------------------------------------------------------------------------
  // Stage 3: N10 lerp along y with the rounding half, the shift, the z select
  // ---------------------------------------------------------------------------
  // A - B + half = t0 * 2^W + ey * (t1 - t0) + half: one multiply, one three-input sum.
  logic [YW-1:0] diff_rnd;  // A - B + 2^(RndShift-1), signed; |A - B| + half < 2^(YW-1)

  cube5_gradient_lerp #(
    .ValW    (XW),
    .DiffW   (XdW),
    .WeightW (WeightW),
    .OutW    (YW),
    .Bias    (RndHalf)
  ) u_lerp_y (
    .a_i (t0_q),
    .d_i (dt_q),
    .e_i (ey_q2),
    .y_o (diff_rnd)
  );

  // |A - B| <= 2^(2W) (2^SampleW - 1): after the shift by 2W - 4 the value is within the component
  // bound and the low GradW bits are exact.
  logic signed [YW-1:0] diff_shifted;
  logic [GradW-1:0]     gz10;

  assign diff_shifted = $signed(diff_rnd) >>> RndShift;
  assign gz10         = diff_shifted[GradW-1:0];

  if (YW > GradW) begin : gen_unused_diff_shifted  // YW - GradW = RndShift sign copies
    logic unused_diff_shifted;
    assign unused_diff_shifted = ^diff_shifted[YW-1:GradW];
  end

  logic [3*GradW-1:0] g3_d, g3_q;
  assign g3_d = {is_n10_q2 ? gz10 : g12_q[2*GradW +: GradW], g12_q[0 +: 2*GradW]};

  // ---------------------------------------------------------------------------
  // Stage 4: |g|, their sum, max and min (30 M + 13 m + 9 n = 13 (M + m + n) + 17 M - 4 n)
  // ---------------------------------------------------------------------------
  logic [3*GradW-1:0] mag_abs;  // |g| of axis a at [a*GradW +: GradW]
  logic [GradW-1:0]   abs_max_d, abs_min_d, abs_max_q, abs_min_q;
  logic               ge01, ge02, ge12;
  logic [SumAbsW-1:0] abs_sum_d, abs_sum_q;
  logic [3*GradW-1:0] g4_q;

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      logic [GradW-1:0] g;
      g = g3_q[a*GradW +: GradW];
      mag_abs[a*GradW +: GradW] = g[GradW-1] ? GradW'(-g) : g;  // never the most negative code
    end
    // Three comparisons side by side, then two levels of muxes (on a tie either pick is the same
    // value).
    ge01 = mag_abs[0 +: GradW] >= mag_abs[GradW +: GradW];
    ge02 = mag_abs[0 +: GradW] >= mag_abs[2*GradW +: GradW];
    ge12 = mag_abs[GradW +: GradW] >= mag_abs[2*GradW +: GradW];
    abs_max_d = (ge01 && ge02) ? mag_abs[0 +: GradW]
              : ge12           ? mag_abs[GradW +: GradW] : mag_abs[2*GradW +: GradW];
    abs_min_d = (!ge01 && !ge02) ? mag_abs[0 +: GradW]
              : !ge12            ? mag_abs[GradW +: GradW] : mag_abs[2*GradW +: GradW];
    abs_sum_d = SumAbsW'(mag_abs[0 +: GradW]) + SumAbsW'(mag_abs[GradW +: GradW])
              + SumAbsW'(mag_abs[2*GradW +: GradW]);
  end

  // ---------------------------------------------------------------------------
  // Stage 5: mag = rnd(13 S + 17 M - 4 n, 5), shifts and adds only
  // ---------------------------------------------------------------------------
  logic [MagSumW-1:0] mag_sum, mag_rnd;
  logic [GradW-1:0]   mag;

  always_comb begin
    mag_sum = (MagSumW'(abs_sum_q) << 3) + (MagSumW'(abs_sum_q) << 2) + MagSumW'(abs_sum_q)
            + (MagSumW'(abs_max_q) << 4) + MagSumW'(abs_max_q)
            - (MagSumW'(abs_min_q) << 2) + MagSumW'(16);
    mag_rnd = mag_sum >> 5;
    mag     = mag_rnd[GradW-1:0];  // at most 26 (2^SampleW - 1) < 2^GradW
  end

  logic unused_mag_rnd;
  assign unused_mag_rnd = ^mag_rnd[MagSumW-1:GradW];

  logic [4*GradW-1:0] out_q;

  // ---------------------------------------------------------------------------
  // Datapath registers (not reset; the valids are u_valid's)
  // ---------------------------------------------------------------------------
  always_ff @(posedge clk_i) begin
    if (ready_1) begin
      g6_q     <= g6_d;
      rows_q   <= rows_d;
      e00_q    <= e00;
      df_q     <= df_d;
      h0_q     <= h0_d;
      dh_q     <= dh_d;
      ex_q     <= ex_d;
      ey_q     <= ey_d;
      is_n10_q <= is_n10;
      is_n26_q <= is_n26;
    end
    if (ready_2) begin
      g12_q     <= g12_d;
      t0_q      <= t0_d;
      dt_q      <= dt_d;
      ey_q2     <= ey_q;
      is_n10_q2 <= is_n10_q;
    end
    if (ready_3) begin
      g3_q <= g3_d;
    end
    if (ready_4) begin
      g4_q      <= g3_q;
      abs_max_q <= abs_max_d;
      abs_min_q <= abs_min_d;
      abs_sum_q <= abs_sum_d;
    end
    if (ready_5) begin
      out_q <= {mag, g4_q};
    end
  end

  assign out_data_o  = out_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_gradient: output changed while stalled");
`endif

endmodule
