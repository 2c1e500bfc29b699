// cube5_trilin: tri-linear interpolation of one sample from eight voxels (patent [44], [48], [202];
// cube3-paper §3), as seven rounded linear interpolations: four along x, two along y, one along z.
//
// Modes (docs/numerics.md): Lerp uses the weights, Half forces 0.5 (level-of-detail filtering),
// Select forces 0 or 1 from each weight's MSB (nearest voxel). Three register stages, one per axis
// (Pipe = 0), or nine (Pipe = 1: per axis the difference, the product and the rounded sum, so that
// every multiplier sits between registers; the same bits); each stage holds its item while the next
// is full, so the unit accepts one item per cycle when the output is never stalled and never drops
// or duplicates an item.
module cube5_trilin #(
  /// Voxel width, U(VoxelW.0).
  parameter int unsigned VoxelW  = 12,
  /// Weight fraction bits, U(0.WeightW).
  parameter int unsigned WeightW = 8,
  /// Fraction bits kept in intermediates and in the sample.
  parameter int unsigned FracW   = 4,
  /// 0: one register stage per axis, latency 3. 1: three per axis (cube5_lerp_pipe), latency 9:
  /// the clock rate of the frame's interpolators (docs/numerics/trilin.md, "Timing").
  parameter int unsigned Pipe    = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// v[0..7] (VoxelW each, corner x + 2y + 4z), wx, wy, wz (WeightW each), mode (2), LSB first.
  input  logic [cube5_pkg::trilin_in_w(VoxelW, WeightW)-1:0] in_data_i,

  /// Output sample valid.
  output logic out_valid_o,
  /// Consumer takes the sample this cycle.
  input  logic out_ready_i,
  /// Sample, U(VoxelW.FracW).
  output logic [cube5_pkg::sample_w(VoxelW, FracW)-1:0] out_data_o
);

  localparam int unsigned SampleW = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned EffW    = WeightW + 1;  // effective weight, 2^WeightW = 1.0

  // Elaboration checks mirror TrilinConfig::validate in the model.
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_trilin: VoxelW must be 4..16");
  end
  if (WeightW < 1 || WeightW > 12) begin : gen_bad_weight_w
    $fatal(1, "cube5_trilin: WeightW must be 1..12");
  end
  if (FracW > 8) begin : gen_bad_frac_w
    $fatal(1, "cube5_trilin: FracW must be 0..8");
  end
  if (Pipe > 1) begin : gen_bad_pipe
    $fatal(1, "cube5_trilin: Pipe must be 0 or 1");
  end

  // ---------------------------------------------------------------------------
  // Input decode: voxels widened to U(VoxelW.FracW), effective weights per mode
  // ---------------------------------------------------------------------------
  localparam int unsigned WeightsLsb = 8 * VoxelW;
  localparam int unsigned ModeLsb    = WeightsLsb + 3 * WeightW;

  logic [1:0]          mode;
  logic [8*SampleW-1:0] corners;   // corner c at [c*SampleW +: SampleW]
  logic [3*EffW-1:0]    eff;       // axis a at [a*EffW +: EffW]

  always_comb begin
    mode = in_data_i[ModeLsb +: 2];
    for (int unsigned c = 0; c < 8; c++) begin
      corners[c*SampleW +: SampleW] = {in_data_i[c*VoxelW +: VoxelW], {FracW{1'b0}}};
    end
    for (int unsigned a = 0; a < 3; a++) begin
      logic [WeightW-1:0] w;
      w = in_data_i[WeightsLsb + a*WeightW +: WeightW];
      unique case (mode)
        cube5_pkg::TrilinModeHalf:   eff[a*EffW +: EffW] = EffW'(1) << (WeightW - 1);
        cube5_pkg::TrilinModeSelect: eff[a*EffW +: EffW] = w[WeightW-1] ? (EffW'(1) << WeightW)
                                                                         : '0;
        default:                     eff[a*EffW +: EffW] = {1'b0, w};
      endcase
    end
  end

  // ---------------------------------------------------------------------------
  // Stage handshakes: a stage takes a new item when it is empty or its item moves on
  // ---------------------------------------------------------------------------
  localparam int unsigned AxisStages = (Pipe != 0) ? 3 : 1;
  logic [3*AxisStages-1:0] ready;
  logic [SampleW-1:0]      sample_q;

  cube5_valid_chain #(
    .Stages (3 * AxisStages)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     (ready),
    .out_valid_o (out_valid_o)
  );
  assign in_ready_o = ready[0];

  if (Pipe == 0) begin : gen_comb
    logic ready_x, ready_y, ready_z;
    assign {ready_z, ready_y, ready_x} = ready;

    // -------------------------------------------------------------------------
    // Stage x: four interpolations along x (pairs of corners differing in x)
    // -------------------------------------------------------------------------
    logic [4*SampleW-1:0] along_x_d, along_x_q;
    logic [2*EffW-1:0]    eff_yz_q;

    for (genvar i = 0; i < 4; i++) begin : gen_lerp_x
      cube5_lerp #(
        .ValW    (SampleW),
        .WeightW (WeightW)
      ) u_lerp (
        .a_i (corners[(2*i)*SampleW +: SampleW]),
        .b_i (corners[(2*i+1)*SampleW +: SampleW]),
        .e_i (eff[0 +: EffW]),
        .y_o (along_x_d[i*SampleW +: SampleW])
      );
    end

    // -------------------------------------------------------------------------
    // Stage y: two interpolations along y
    // -------------------------------------------------------------------------
    logic [2*SampleW-1:0] along_y_d, along_y_q;
    logic [EffW-1:0]      eff_z_q;

    for (genvar i = 0; i < 2; i++) begin : gen_lerp_y
      cube5_lerp #(
        .ValW    (SampleW),
        .WeightW (WeightW)
      ) u_lerp (
        .a_i (along_x_q[(2*i)*SampleW +: SampleW]),
        .b_i (along_x_q[(2*i+1)*SampleW +: SampleW]),
        .e_i (eff_yz_q[0 +: EffW]),
        .y_o (along_y_d[i*SampleW +: SampleW])
      );
    end

    // -------------------------------------------------------------------------
    // Stage z: the sample
    // -------------------------------------------------------------------------
    logic [SampleW-1:0] sample_d;

    cube5_lerp #(
      .ValW    (SampleW),
      .WeightW (WeightW)
    ) u_lerp_z (
      .a_i (along_y_q[0 +: SampleW]),
      .b_i (along_y_q[SampleW +: SampleW]),
      .e_i (eff_z_q),
      .y_o (sample_d)
    );

    // Datapath registers (not reset; the valids are u_valid's)
    always_ff @(posedge clk_i) begin
      if (ready_x) begin
        along_x_q <= along_x_d;
        eff_yz_q  <= eff[EffW +: 2*EffW];
      end
      if (ready_y) begin
        along_y_q <= along_y_d;
        eff_z_q   <= eff_yz_q[EffW +: EffW];
      end
      if (ready_z) begin
        sample_q <= sample_d;
      end
    end
  end else begin : gen_pipe
    // Per axis: the difference, the product, the rounded sum (cube5_lerp_pipe); the later axes'
    // weights travel beside the items.
    logic [4*SampleW-1:0] along_x;
    logic [2*SampleW-1:0] along_y;
    logic [2*EffW-1:0]    eff_yz;
    logic [EffW-1:0]      eff_z;
    logic                 unused_side;

    cube5_lerp_pipe #(
      .N (4), .ValW (SampleW), .WeightW (WeightW), .SideW (2 * EffW)
    ) u_lerp_x (
      .clk_i,
      .en_i   (ready[2:0]),
      .a_i    ({corners[6*SampleW +: SampleW], corners[4*SampleW +: SampleW],
                corners[2*SampleW +: SampleW], corners[0 +: SampleW]}),
      .b_i    ({corners[7*SampleW +: SampleW], corners[5*SampleW +: SampleW],
                corners[3*SampleW +: SampleW], corners[1*SampleW +: SampleW]}),
      .e_i    (eff[0 +: EffW]),
      .side_i (eff[EffW +: 2*EffW]),
      .y_o    (along_x),
      .side_o (eff_yz)
    );

    cube5_lerp_pipe #(
      .N (2), .ValW (SampleW), .WeightW (WeightW), .SideW (EffW)
    ) u_lerp_y (
      .clk_i,
      .en_i   (ready[5:3]),
      .a_i    ({along_x[2*SampleW +: SampleW], along_x[0 +: SampleW]}),
      .b_i    ({along_x[3*SampleW +: SampleW], along_x[1*SampleW +: SampleW]}),
      .e_i    (eff_yz[0 +: EffW]),
      .side_i (eff_yz[EffW +: EffW]),
      .y_o    (along_y),
      .side_o (eff_z)
    );

    cube5_lerp_pipe #(
      .N (1), .ValW (SampleW), .WeightW (WeightW), .SideW (1)
    ) u_lerp_z (
      .clk_i,
      .en_i   (ready[8:6]),
      .a_i    (along_y[0 +: SampleW]),
      .b_i    (along_y[SampleW +: SampleW]),
      .e_i    (eff_z),
      .side_i (1'b0),
      .y_o    (sample_q),
      .side_o (unused_side)
    );
  end

  assign out_data_o  = sample_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_trilin: output changed while stalled");
`endif

endmodule
