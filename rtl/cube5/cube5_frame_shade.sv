// cube5_frame_shade: per pipeline, the gradient and the shading of one sample (docs/numerics/frame.md,
// "The pipeline of one sample", steps 2 to 4): cube5_gradient in mode N6 on the frame's orthogonal
// neighbourhood, the adapter (components and magnitude shifted right by 4, arithmetic), and
// cube5_shader, whose tables every pipeline receives from the configuration port. The centre sample
// C waits for the gradient in a FIFO (pushed when a block enters the gradient units, popped when
// their result leaves), so nothing here depends on the units' latencies. Never stalled: the units'
// outputs are always taken.
module cube5_frame_shade #(
  parameter int unsigned P         = 4,
  parameter int unsigned VoxelW    = 12,
  parameter int unsigned FracW     = 4,
  parameter int unsigned WeightW   = 8,
  parameter int unsigned ClassIdxW = 12,
  parameter int unsigned MagIdxW   = 4,
  parameter int unsigned MagShift  = 10,
  parameter int unsigned ColorW    = 8,
  parameter int unsigned AlphaW    = 12,
  parameter int unsigned RmLog2    = 3,
  parameter int unsigned RmFracW   = 4,
  parameter int unsigned DiffW     = 9,
  parameter int unsigned SpecW     = 8,
  /// Shader configuration port widths (cube5_shader_pkg).
  parameter int unsigned ShCfgAddrW = 14,
  parameter int unsigned ShCfgDataW = 36,
  /// The shaders' `Pipe` (cube5_shader): cube5_frame's ShaderPipe; 0 in cube5_er.
  parameter int unsigned ShaderPipe = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// New frame (empties the side FIFO).
  input  logic start_i,
  /// Shader mode of every sample this frame: bit 0 tf2d, bit 1 unlit.
  input  logic [1:0] shader_mode_i,

  /// Neighbourhoods of one anchor beat, lane l at [l*7*SampleW +: 7*SampleW]: C, x-, x+, y-, y+, B, A.
  input  logic nb_valid_i,
  input  logic [7*P*cube5_pkg::sample_w(VoxelW, FracW)-1:0] nb_i,

  /// Shader table writes (forwarded to every pipeline).
  input  logic                  cfg_valid_i,
  input  logic [ShCfgAddrW-1:0] cfg_addr_i,
  input  logic [ShCfgDataW-1:0] cfg_data_i,

  /// Shaded samples of one anchor beat, lane l at [l*RgbaW +: RgbaW]: r, g, b, a (LSB first).
  output logic rgba_valid_o,
  output logic [P*(3*ColorW+AlphaW)-1:0] rgba_o
);

  localparam int unsigned SampleW  = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned GInW     = cube5_gradient_pkg::gradient_in_w(SampleW, WeightW);
  localparam int unsigned GGradW   = cube5_gradient_pkg::grad_w(SampleW);
  localparam int unsigned SGradW   = cube5_shader_pkg::grad_w(VoxelW, FracW);
  localparam int unsigned SInW     = cube5_shader_pkg::in_w(VoxelW, FracW);
  localparam int unsigned RgbaW    = 3 * ColorW + AlphaW;
  localparam int unsigned AdaptW   = GGradW - 4;   // gradient >> 4

  if (AdaptW > SGradW) begin : gen_bad_adapter
    $fatal(1, "cube5_frame_shade: the shifted gradient does not fit the shader's format");
  end

  // ---------------------------------------------------------------------------
  // Gradient blocks: the 7 values in the 27-sample block, every other entry 0, dx = dy = 0, N6
  // ---------------------------------------------------------------------------
  logic [P*GInW-1:0]     g_in;
  logic [P*SampleW-1:0]  centre;

  always_comb begin
    for (int unsigned l = 0; l < P; l++) begin
      logic [7*SampleW-1:0] nb;
      logic [27*SampleW-1:0] blk;
      nb  = nb_i[l*7*SampleW +: 7*SampleW];
      blk = '0;
      blk[cube5_gradient_pkg::blk(1, 1, 1)*SampleW +: SampleW] = nb[0*SampleW +: SampleW];  // C
      blk[cube5_gradient_pkg::blk(0, 1, 1)*SampleW +: SampleW] = nb[1*SampleW +: SampleW];  // x-
      blk[cube5_gradient_pkg::blk(2, 1, 1)*SampleW +: SampleW] = nb[2*SampleW +: SampleW];  // x+
      blk[cube5_gradient_pkg::blk(1, 0, 1)*SampleW +: SampleW] = nb[3*SampleW +: SampleW];  // y-
      blk[cube5_gradient_pkg::blk(1, 2, 1)*SampleW +: SampleW] = nb[4*SampleW +: SampleW];  // y+
      blk[cube5_gradient_pkg::blk(1, 1, 0)*SampleW +: SampleW] = nb[5*SampleW +: SampleW];  // B
      blk[cube5_gradient_pkg::blk(1, 1, 2)*SampleW +: SampleW] = nb[6*SampleW +: SampleW];  // A
      g_in[l*GInW +: GInW] = {cube5_gradient_pkg::GradModeN6, (2*(WeightW+2))'(0), blk};
      centre[l*SampleW +: SampleW] = nb[0 +: SampleW];
    end
  end

  // ---------------------------------------------------------------------------
  // Gradient units and the centre-sample FIFO
  // ---------------------------------------------------------------------------
  logic [P-1:0]          g_ready, g_valid;
  logic [P*4*GGradW-1:0] g_out;

  for (genvar l = 0; l < P; l++) begin : gen_gradient
    cube5_gradient #(
      .VoxelW  (VoxelW),
      .FracW   (FracW),
      .WeightW (WeightW)
    ) u_gradient (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (nb_valid_i),
      .in_ready_o  (g_ready[l]),
      .in_data_i   (g_in[l*GInW +: GInW]),
      .out_valid_o (g_valid[l]),
      .out_ready_i (1'b1),
      .out_data_o  (g_out[l*4*GGradW +: 4*GGradW])
    );
  end

  logic [P*SampleW-1:0] centre_q;
  logic                 unused_side_empty, unused_side_full;

  cube5_frame_fifo #(
    .Width (P * SampleW),
    .Depth (8)
  ) u_centre (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (start_i),
    .push_i  (nb_valid_i),
    .d_i     (centre),
    .pop_i   (g_valid[0]),
    .q_o     (centre_q),
    .empty_o (unused_side_empty),
    .full_o  (unused_side_full)
  );

  // ---------------------------------------------------------------------------
  // Adapter (gradient to shader: >> 4, arithmetic) and the shaders
  // ---------------------------------------------------------------------------
  logic [P*SInW-1:0]  s_in;
  logic [P-1:0]       s_ready, s_valid;

  always_comb begin
    for (int unsigned l = 0; l < P; l++) begin
      logic [4*GGradW-1:0] g;
      logic [4*SGradW-1:0] sg;
      g = g_out[l*4*GGradW +: 4*GGradW];
      for (int unsigned c = 0; c < 3; c++) begin
        logic signed [GGradW-1:0] comp;
        comp = $signed(g[c*GGradW +: GGradW]);
        sg[c*SGradW +: SGradW] = SGradW'(comp >>> 4);
      end
      sg[3*SGradW +: SGradW] = SGradW'(g[3*GGradW + 4 +: AdaptW]);
      s_in[l*SInW +: SInW] = {shader_mode_i, sg, centre_q[l*SampleW +: SampleW]};
    end
  end

  for (genvar l = 0; l < P; l++) begin : gen_shader
    cube5_shader #(
      .VoxelW    (VoxelW),
      .FracW     (FracW),
      .ClassIdxW (ClassIdxW),
      .MagIdxW   (MagIdxW),
      .MagShift  (MagShift),
      .ColorW    (ColorW),
      .AlphaW    (AlphaW),
      .RmLog2    (RmLog2),
      .RmFracW   (RmFracW),
      .DiffW     (DiffW),
      .SpecW     (SpecW),
      .Pipe      (ShaderPipe)
    ) u_shader (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (g_valid[0]),
      .in_ready_o  (s_ready[l]),
      .in_data_i   (s_in[l*SInW +: SInW]),
      .out_valid_o (s_valid[l]),
      .out_ready_i (1'b1),
      .out_data_o  (rgba_o[l*RgbaW +: RgbaW]),
      .cfg_valid_i (cfg_valid_i),
      .cfg_addr_i  (cfg_addr_i),
      .cfg_data_i  (cfg_data_i)
    );
  end

  assign rgba_valid_o = s_valid[0];

  logic unused_shade;
  assign unused_shade = ^{unused_side_empty, unused_side_full, g_valid, s_valid};

`ifndef SYNTHESIS
  ShadeGradientReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      nb_valid_i |-> &g_ready)
    else $error("cube5_frame_shade: a gradient unit was not ready");
  ShadeShaderReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      g_valid[0] |-> &s_ready)
    else $error("cube5_frame_shade: a shader was not ready");
  ShadeLanesInStep: assert property (@(posedge clk_i) disable iff (!rst_ni)
      (g_valid == '0 || &g_valid) && (s_valid == '0 || &s_valid))
    else $error("cube5_frame_shade: pipelines out of step");
`endif

endmodule
