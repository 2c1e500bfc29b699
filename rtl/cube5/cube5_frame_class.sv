// cube5_frame_class: per pipeline, the classification of one sample without gradient and shader
// (docs/numerics/frame.md, "A frame without gradient and shader"): the frame's `Shade = 0` form of
// steps 2 to 4, for the unlit modes (MIP, MinIP, X-ray). Each pipeline keeps the shader's 1-D
// classification table (patent [45]: density to RGBA), written at the shader's own configuration
// addresses (region 0 of docs/numerics/shader.md; texel and zero-entry writes are ignored, there
// is no reflectance map),
// and reads entry `C >> (SampleW - ClassIdxW)` of the neighbourhood's centre sample C. That is
// exactly what cube5_shader returns in mode `unlit` with `tf2d = 0` (`rgb' = rgb`, `a' = a`), so
// the frame's image does not change; the gradient, its neighbours (x-, x+, y-, y+, B, A) and the
// reflectance map are not needed. Latency 1 (the table's registered read); never stalled.
module cube5_frame_class #(
  parameter int unsigned P          = 4,
  parameter int unsigned VoxelW     = 12,
  parameter int unsigned FracW      = 4,
  parameter int unsigned ClassIdxW  = 12,
  parameter int unsigned ColorW     = 8,
  parameter int unsigned AlphaW     = 12,
  /// Shader configuration port widths (cube5_shader_pkg), the addresses the table listens at.
  parameter int unsigned ShCfgAddrW = 14,
  parameter int unsigned ShCfgDataW = 36
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Neighbourhoods of one anchor beat, lane l at [l*7*SampleW +: 7*SampleW]: C, x-, x+, y-, y+, B, A
  /// (only C is read).
  input  logic nb_valid_i,
  input  logic [7*P*cube5_pkg::sample_w(VoxelW, FracW)-1:0] nb_i,

  /// Shader table writes (classification entries reach every pipeline's table).
  input  logic                  cfg_valid_i,
  input  logic [ShCfgAddrW-1:0] cfg_addr_i,
  input  logic [ShCfgDataW-1:0] cfg_data_i,

  /// Classified samples of one anchor beat, lane l at [l*RgbaW +: RgbaW]: r, g, b, a (LSB first).
  output logic rgba_valid_o,
  output logic [P*(3*ColorW+AlphaW)-1:0] rgba_o
);

  localparam int unsigned SampleW = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned RgbaW   = 3 * ColorW + AlphaW;
  localparam int unsigned OffW    = ShCfgAddrW - 2;

  if (ClassIdxW > SampleW || ClassIdxW > OffW) begin : gen_bad_class
    $fatal(1, "cube5_frame_class: ClassIdxW must fit the sample and the shader's address offset");
  end
  if (RgbaW > ShCfgDataW) begin : gen_bad_data
    $fatal(1, "cube5_frame_class: an entry must fit the shader's configuration data");
  end

  // ---------------------------------------------------------------------------
  // Configuration: classification entries only (shader region 0, offset below 2^ClassIdxW)
  // ---------------------------------------------------------------------------
  logic [1:0]      cfg_region;
  logic [OffW-1:0] cfg_off;
  logic            class_we;
  assign cfg_region = cfg_addr_i[ShCfgAddrW-1 -: 2];
  assign cfg_off    = cfg_addr_i[OffW-1:0];
  assign class_we   = cfg_valid_i && cfg_region == cube5_shader_pkg::RegionClass
                      && (cfg_off >> ClassIdxW) == '0;

  // ---------------------------------------------------------------------------
  // The tables, one per pipeline, read at the centre sample's class index
  // ---------------------------------------------------------------------------
  for (genvar l = 0; l < P; l++) begin : gen_class
    // The top ClassIdxW bits of C (docs/numerics/shader.md, "Classification", 1-D).
    logic [ClassIdxW-1:0] idx;
    assign idx = nb_i[l*7*SampleW + SampleW - ClassIdxW +: ClassIdxW];

    cube5_shader_ram #(
      .Depth (1 << ClassIdxW),
      .Width (RgbaW),
      .AddrW (ClassIdxW)
    ) u_table (
      .clk_i   (clk_i),
      .we_i    (class_we),
      .waddr_i (cfg_off[ClassIdxW-1:0]),
      .wdata_i (cfg_data_i[RgbaW-1:0]),
      .re_i    (nb_valid_i),
      .raddr_i (idx),
      .rdata_o (rgba_o[l*RgbaW +: RgbaW])
    );
  end

  logic valid_q;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      valid_q <= 1'b0;
    end else begin
      valid_q <= nb_valid_i;
    end
  end
  assign rgba_valid_o = valid_q;

  // The neighbours of the centre (the gradient's inputs) and the other configuration bits.
  logic unused_class;
  assign unused_class = ^{nb_i, cfg_data_i, cfg_off};

endmodule
