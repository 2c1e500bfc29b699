// gicube_sample: the GI-Cube block processor's sample datapath (patent [353], [379]-[380], [383];
// parts I, J, K and L of docs/gicube-rtl.md; contract docs/numerics/gicube_sample.md). Per item,
// one sample of one ray: the tri-linear density of the cell's eight voxels (cube5_trilin), its
// classification (cube5_shader, 1-D, unlit), the sample colour (0 for a lighting ray; for a lit
// rendering ray the classified colour times the tri-linear irradiance of the corners, a second
// cube5_trilin and three 8 x 16-bit products), and one front-to-back compositing step onto the
// packet's colour and opacity (cube5_compos with its opacity LUT and termination threshold).
//
//   in ─┬─► cube5_trilin (density, 3) ─► cube5_shader (class, 12) ─► shade (1) ─► cube5_compos (6) ─► out
//       ├─► cube5_trilin (irradiance, 3, never stalls) ──► irr FIFO ──────────┤
//       └─► side FIFO (colour, opacity, lighting, irr_en) ────────────────────┘
//
// The packet fields and the irradiance wait in two small FIFOs, read when the classified sample
// reaches the shade stage; they hold at most the items inside the density trilin and the shader
// (one a stage), so they never fill and need no credit. A lighting ray composites a black sample,
// which leaves its colour unchanged (C + rnd(w 0) = C), so no bypass carries the colour around the
// compositor. Latency 22, one item per clock when the output is never stalled.
module gicube_sample #(
  /// Bits per voxel, 4..16.
  parameter int unsigned VoxelW = 8,
  /// 1: the jitter stage (random, log and power LUTs, [353], [380]) before the compositor, whose
  /// LUT is then bypassed; 0: the compositor's opacity table corrects for the fixed step.
  parameter int unsigned Jitter = 0,
  /// 1: shading ([352], [378], [379], [383]): the corners' gradient indices decoded by eight
  /// gradient LUTs and interpolated tri-linearly, the nearest corner's tag in the classification
  /// index, and the reflectance map lighting rendering rays without irradiance; 0: unlit.
  parameter int unsigned Shade = 0,
  /// Gradient index bits per voxel (Shade = 1), 2..11.
  parameter int unsigned GradIdxW = 11,
  /// Tag bits per voxel (Shade = 1), 0..4 and below ClassIdxW; 0 with Shade = 0.
  parameter int unsigned TagW = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// voxels[8] (VoxelW), weights x, y, z (U(0.8)), irr_en, irr[8] (U(2.14)), red, green, blue,
  /// opacity (U(0.12)), lighting, with Shade = 1 grad_idx[8] (GradIdxW), tag[8] (TagW); LSB first.
  input  logic [gicube_sample_pkg::in_w(VoxelW)
                + gicube_sample_pkg::shade_in_w(Shade, GradIdxW, TagW)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// red, green, blue, opacity (U(0.12)), terminated; LSB first.
  output logic [gicube_sample_pkg::OutW-1:0] out_data_o,

  /// Configuration write this cycle (tables and registers; they survive reset).
  input  logic cfg_valid_i,
  /// Bit 13 clear: classification entry (the index below); set: cube5_compos word (bits 12:0);
  /// with Shade = 1, bit 14 set: the gradient LUTs, texels and zero-gradient entry.
  input  logic [gicube_sample_pkg::cfg_addr_w(Shade)-1:0] cfg_addr_i,
  /// r, g, b (8 each), a (12) for a classification entry; the cube5_compos word in bits 12:0.
  input  logic [gicube_sample_pkg::CfgDataW-1:0] cfg_data_i
);

  // ---------------------------------------------------------------------------
  // Widths
  // ---------------------------------------------------------------------------
  localparam int unsigned WeightW   = gicube_sample_pkg::WeightW;
  localparam int unsigned FracW     = gicube_sample_pkg::SampleFracW;
  localparam int unsigned IrrW      = gicube_sample_pkg::IrrW;
  localparam int unsigned IrrFracW  = gicube_sample_pkg::IrrFracW;
  localparam int unsigned ChanW     = gicube_sample_pkg::ChanW;
  localparam int unsigned ColorW    = gicube_sample_pkg::ColorW;
  localparam int unsigned AlphaW    = gicube_sample_pkg::AlphaW;
  localparam int unsigned CfgAW     = gicube_sample_pkg::CfgAddrW;
  localparam int unsigned InW       = gicube_sample_pkg::in_w(VoxelW)
                                      + gicube_sample_pkg::shade_in_w(Shade, GradIdxW, TagW);
  localparam int unsigned CfgPortAW = gicube_sample_pkg::cfg_addr_w(Shade);
  localparam int unsigned SampleW   = VoxelW + FracW;
  localparam int unsigned ClassIdxW = gicube_sample_pkg::class_idx_w(VoxelW);

  // cube5_shader: unlit (Shade = 0), only its classification table is used and the reflectance
  // map is the smallest the unit allows (its divider sets the latency: div_stages(1, 1) + 9 = 12
  // stages); with Shade = 1 the map of its v12 widths, 8 x 8 cells a face (17 stages).
  localparam int unsigned RmLog2    = Shade != 0 ? 3 : 1;
  localparam int unsigned RmFracW   = Shade != 0 ? 4 : 1;
  localparam int unsigned DiffW     = Shade != 0 ? 9 : 2;
  localparam int unsigned SpecW     = Shade != 0 ? 8 : 1;
  // The tag rides on the shader's magnitude input: the 2-D index of density bits over TagW.
  localparam int unsigned MagIdxW   = TagW > 0 ? TagW : 1;
  localparam int unsigned ShGradW   = cube5_shader_pkg::grad_w(VoxelW, FracW);
  localparam int unsigned ShInW     = cube5_shader_pkg::in_w(VoxelW, FracW);
  localparam int unsigned ShCfgAW   = cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2);
  localparam int unsigned ShCfgDW   = cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW);
  localparam int unsigned ShStages  = cube5_shader_pkg::div_stages(RmLog2, RmFracW) + 9;

  // cube5_compos: ColorW 8, AlphaW 12, ExtraW 0, AccW 12, ZW 1.
  localparam int unsigned AccW      = 12;
  localparam int unsigned CxChanW   = AccW + 1;  // U(1.12)
  localparam int unsigned ZW        = 1;
  localparam int unsigned CoxelW    = cube5_compos_pkg::coxel_w(ColorW, AccW, ZW);
  localparam int unsigned CxInW     = cube5_compos_pkg::in_w(ColorW, AlphaW, AccW, ZW);

  // The FIFOs hold at most the items in the gradient LUT stage (Shade), the density trilin (3)
  // and the shader.
  localparam int unsigned FifoAW    = $clog2(Shade + 3 + ShStages);
  localparam int unsigned FifoDepth = 1 << FifoAW;

  // Input fields, LSB first.
  localparam int unsigned WeightsLsb  = 8 * VoxelW;
  localparam int unsigned IrrEnBit    = WeightsLsb + 3 * WeightW;
  localparam int unsigned IrrLsb      = IrrEnBit + 1;
  localparam int unsigned ColorLsb    = IrrLsb + 8 * IrrW;
  localparam int unsigned OpacityLsb  = ColorLsb + 3 * ChanW;
  localparam int unsigned LightingBit = OpacityLsb + ChanW;

  // Side FIFO entry: colour, opacity, lighting, irr_en (LSB first).
  localparam int unsigned SideW = 4 * ChanW + 2;

  // Elaboration checks mirror SampleConfig::validate in the model.
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "gicube_sample: VoxelW must be 4..16");
  end
  if (Jitter > 1) begin : gen_bad_jitter
    $fatal(1, "gicube_sample: Jitter must be 0 or 1");
  end
  // The jitter's position mangling rotates 8-bit weights (contract, "Jitter and the power LUT").
  if (Jitter != 0 && WeightW != 8) begin : gen_bad_jitter_weight_w
    $fatal(1, "gicube_sample: Jitter = 1 needs gicube_sample_pkg::WeightW = 8");
  end
  if (Shade > 1 || (Shade == 0 && TagW != 0)) begin : gen_bad_shade
    $fatal(1, "gicube_sample: Shade must be 0 or 1, TagW 0 without it");
  end
  if (Shade != 0 && (GradIdxW < 2 || GradIdxW > 11 || TagW > 4 || TagW >= ClassIdxW))
  begin : gen_bad_shade_w
    $fatal(1, "gicube_sample: GradIdxW must be 2..11, TagW 0..4 and below ClassIdxW");
  end
  if (LightingBit + 1 + gicube_sample_pkg::shade_in_w(Shade, GradIdxW, TagW) != InW)
  begin : gen_bad_packing
    $fatal(1, "gicube_sample: input packing and gicube_sample_pkg::in_w disagree");
  end

  logic in_fire;

  // ---------------------------------------------------------------------------
  // Configuration: the region bit routes a write to the shader's classification region or to
  // cube5_compos's word address
  // ---------------------------------------------------------------------------
  logic                cfg_low, cfg_class, cfg_compos, cfg_grad, cfg_texel, cfg_zero;
  logic                sh_cfg_valid;
  logic [ShCfgAW-1:0]  sh_cfg_addr;
  logic [ShCfgDW-1:0]  sh_cfg_data;

  always_comb begin
    // With Shade = 1 the top address bit selects the shading tables.
    cfg_low     = cfg_valid_i && !(Shade != 0 && cfg_addr_i[CfgPortAW-1]);
    cfg_class   = cfg_low && cfg_addr_i[CfgAW-1] == gicube_sample_pkg::RegionClass
                  && cfg_addr_i[CfgAW-2:ClassIdxW] == '0;
    // The jitter tables' addresses above the compositor's registers are not its words.
    cfg_compos  = cfg_low && cfg_addr_i[CfgAW-1] == gicube_sample_pkg::RegionCompos
                  && !(Jitter != 0 && cfg_addr_i[CfgAW-2] && cfg_addr_i[CfgAW-3]);
    // Shading: bits 13:12 pick the gradient LUTs (0), a texel (1, offset below 2^11) or the
    // zero-gradient entry (2, offset 0).
    cfg_grad    = 1'b0;
    cfg_texel   = 1'b0;
    cfg_zero    = 1'b0;
    if (Shade != 0 && cfg_valid_i && cfg_addr_i[CfgPortAW-1]) begin
      cfg_grad  = cfg_addr_i[13:12] == 2'd0 && cfg_addr_i[11:0] < 12'(1 << GradIdxW);
      cfg_texel = cfg_addr_i[13:12] == 2'd1 && !cfg_addr_i[11];
      cfg_zero  = cfg_addr_i[13:12] == 2'd2 && cfg_addr_i[11:0] == '0;
    end
    sh_cfg_valid = cfg_class || cfg_texel || cfg_zero;
    // Region 0 (classification) of the shader's map at the entry's index; region 1 (texel) at
    // its offset; region 2 (the zero-gradient entry).
    if (cfg_texel) begin
      sh_cfg_addr = {cube5_shader_pkg::RegionTexel, (ShCfgAW-2)'(cfg_addr_i[10:0])};
    end else if (cfg_zero) begin
      sh_cfg_addr = {cube5_shader_pkg::RegionZero, (ShCfgAW-2)'(0)};
    end else begin
      sh_cfg_addr = {cube5_shader_pkg::RegionClass, (ShCfgAW-2)'(cfg_addr_i[ClassIdxW-1:0])};
    end
    sh_cfg_data = ShCfgDW'(cfg_data_i);
  end

  // ---------------------------------------------------------------------------
  // I: the density sample, U(VoxelW.4)
  // ---------------------------------------------------------------------------
  logic               tri_in_ready, tri_out_valid, tri_out_ready;
  logic [SampleW-1:0] tri_sample;

  // The density trilin's input: the item itself, or with Shade = 1 the gradient LUT stage.
  logic                             tri_in_valid;
  logic [8*VoxelW+3*WeightW-1:0]    tri_in;

  cube5_trilin #(
    .VoxelW  (VoxelW),
    .WeightW (WeightW),
    .FracW   (FracW)
  ) u_trilin (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (tri_in_valid),
    .in_ready_o  (tri_in_ready),
    .in_data_i   ({cube5_pkg::TrilinModeLerp, tri_in}),
    .out_valid_o (tri_out_valid),
    .out_ready_i (tri_out_ready),
    .out_data_o  (tri_sample)
  );

  assign in_fire = in_valid_i && in_ready_o;

  // ---------------------------------------------------------------------------
  // Shade = 1, I (the gradient) and J (the tag): a stage that registers the item while the
  // eight gradient LUTs decode the corners' indices ([378]); three trilins (S(10) components
  // offset to unsigned: the sign bit flipped, and back) beside the density trilin, in lockstep
  // with it (the same handshake); the nearest corner's tag and the shader's mode (unlit for a
  // lighting ray or one with irradiance) in a FIFO read as the sample enters the shader.
  // ---------------------------------------------------------------------------
  localparam int unsigned GradCompW = gicube_sample_pkg::GradCompW;
  localparam int unsigned GFracW    = VoxelW - 4 < FracW ? VoxelW - 4 : FracW;
  localparam int unsigned GSampleW  = GradCompW + GFracW;

  logic [3*ShGradW-1:0] sh_grad;
  logic [ShGradW-1:0]   sh_mag;
  logic                 sh_unlit, sh_tf2d;

  if (Shade != 0) begin : gen_shade
    localparam int unsigned GidxLsb = LightingBit + 1;
    localparam int unsigned TagLsb  = GidxLsb + 8 * GradIdxW;
    localparam int unsigned TagSW   = TagW > 0 ? TagW : 1;
    localparam int unsigned MfAW    = 3;  // the tag FIFO: at most the stage and the trilin's 3

    logic                          s0_en, s0_valid_q;
    logic [8*VoxelW+3*WeightW-1:0] s0_q;
    logic [8*3*GradCompW-1:0]      lut_q;

    assign s0_en      = !s0_valid_q || tri_in_ready;
    assign in_ready_o = s0_en;

    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        s0_valid_q <= 1'b0;
      end else if (s0_en) begin
        s0_valid_q <= in_valid_i;
      end
    end

    always_ff @(posedge clk_i) begin
      if (s0_en) begin
        s0_q <= in_data_i[0 +: 8*VoxelW + 3*WeightW];
      end
    end

    assign tri_in_valid = s0_valid_q;
    assign tri_in       = s0_q;

    // Eight identical gradient LUTs, one per corner, written together.
    for (genvar c = 0; c < 8; c++) begin : gen_grad_lut
      cube5_shader_ram #(
        .Depth (2**GradIdxW),
        .Width (3*GradCompW),
        .AddrW (GradIdxW)
      ) u_grad_lut (
        .clk_i   (clk_i),
        .we_i    (cfg_grad),
        .waddr_i (cfg_addr_i[GradIdxW-1:0]),
        .wdata_i (cfg_data_i[3*GradCompW-1:0]),
        .re_i    (s0_en),
        .raddr_i (in_data_i[GidxLsb + c*GradIdxW +: GradIdxW]),
        .rdata_o (lut_q[c*3*GradCompW +: 3*GradCompW])
      );
    end

    for (genvar a = 0; a < 3; a++) begin : gen_grad_trilin
      logic [8*GradCompW-1:0] corners;
      logic [GSampleW-1:0]    g;
      logic                   g_in_ready, g_out_valid;

      // Offset binary: component + 2^9 is the two's complement with its sign bit flipped.
      always_comb begin
        for (int c = 0; c < 8; c++) begin
          corners[c*GradCompW +: GradCompW] = lut_q[(3*c + a)*GradCompW +: GradCompW]
                                              ^ (GradCompW'(1) << (GradCompW - 1));
        end
      end

      cube5_trilin #(
        .VoxelW  (GradCompW),
        .WeightW (WeightW),
        .FracW   (GFracW)
      ) u_grad_trilin (
        .clk_i       (clk_i),
        .rst_ni      (rst_ni),
        .in_valid_i  (s0_valid_q),
        .in_ready_o  (g_in_ready),
        .in_data_i   ({cube5_pkg::TrilinModeLerp, s0_q[8*VoxelW +: 3*WeightW], corners}),
        .out_valid_o (g_out_valid),
        .out_ready_i (tri_out_ready),
        .out_data_o  (g)
      );

      // Back to two's complement (the offset 2^(9 + Fg) off: the top bit flipped), widened.
      assign sh_grad[a*ShGradW +: ShGradW] =
          ShGradW'($signed({~g[GSampleW-1], g[GSampleW-2:0]}));

`ifndef SYNTHESIS
      GradTrilinInStep: assert property (@(posedge clk_i) disable iff (!rst_ni)
          g_in_ready == tri_in_ready && g_out_valid == tri_out_valid)
        else $error("gicube_sample: a gradient trilin left the density trilin's step");
`endif
      logic unused_g;
      assign unused_g = ^{g_in_ready, g_out_valid};
    end

    // The tag of the nearest corner (the weights' top bits) and the mode, written as the item
    // enters, read as its sample enters the shader.
    logic [WeightW-1:0] wx, wy, wz;
    logic [2:0]         near;
    logic [TagSW:0]     mf_wr, mf_rd;
    logic [TagSW:0]     mf_mem [2**MfAW];
    logic [MfAW-1:0]    mf_wp_q, mf_rp_q;
    logic               sh_fire;

    assign wx   = in_data_i[WeightsLsb +: WeightW];
    assign wy   = in_data_i[WeightsLsb + WeightW +: WeightW];
    assign wz   = in_data_i[WeightsLsb + 2*WeightW +: WeightW];
    assign near = {wz[WeightW-1], wy[WeightW-1], wx[WeightW-1]};

    if (TagW > 0) begin : gen_tag
      assign mf_wr[TagSW-1:0] = in_data_i[TagLsb + 32'(near)*TagW +: TagSW];
    end else begin : gen_no_tag
      assign mf_wr[TagSW-1:0] = '0;
      logic unused_near;
      assign unused_near = ^near;
    end
    assign mf_wr[TagSW] = in_data_i[LightingBit] || in_data_i[IrrEnBit];
    assign sh_fire      = tri_out_valid && tri_out_ready;

    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        mf_wp_q <= '0;
        mf_rp_q <= '0;
      end else begin
        if (in_fire) begin
          mf_wp_q <= mf_wp_q + MfAW'(1);
        end
        if (sh_fire) begin
          mf_rp_q <= mf_rp_q + MfAW'(1);
        end
      end
    end

    always_ff @(posedge clk_i) begin
      if (in_fire) begin
        mf_mem[mf_wp_q] <= mf_wr;
      end
    end

    assign mf_rd    = mf_mem[mf_rp_q];
    assign sh_mag   = ShGradW'(mf_rd[TagSW-1:0]);
    assign sh_unlit = mf_rd[TagSW];
    assign sh_tf2d  = TagW > 0;

`ifndef SYNTHESIS
    // The tag FIFO holds the items in the stage and the trilin, at most 4 of its 8.
    TagFifoNeverOverflows: assert property (@(posedge clk_i) disable iff (!rst_ni)
        in_fire && !sh_fire |-> mf_wp_q + MfAW'(1) != mf_rp_q)
      else $error("gicube_sample: tag FIFO overflow");
`endif
  end else begin : gen_no_shade
    assign in_ready_o   = tri_in_ready;
    assign tri_in_valid = in_valid_i;
    assign tri_in       = in_data_i[0 +: 8*VoxelW + 3*WeightW];
    assign sh_grad      = '0;
    assign sh_mag       = '0;
    assign sh_unlit     = 1'b1;
    assign sh_tf2d      = 1'b0;
    logic unused_grad;
    assign unused_grad = cfg_grad;
  end

  // ---------------------------------------------------------------------------
  // L (first half): the irradiance, U(2.14). Never stalled (its output goes to a FIFO that never
  // fills), so it takes an item exactly when the density trilin does.
  // ---------------------------------------------------------------------------
  logic            irr_in_ready, irr_valid;
  logic [IrrW-1:0] irr_sample;
  logic [8*IrrW+3*WeightW+1:0] irr_in;

  assign irr_in = {cube5_pkg::TrilinModeLerp, in_data_i[WeightsLsb +: 3*WeightW],
                   in_data_i[IrrLsb +: 8*IrrW]};

  cube5_trilin #(
    .VoxelW  (IrrW),
    .WeightW (WeightW),
    .FracW   (0)
  ) u_irr_trilin (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_fire),
    .in_ready_o  (irr_in_ready),
    .in_data_i   (irr_in),
    .out_valid_o (irr_valid),
    .out_ready_i (1'b1),
    .out_data_o  (irr_sample)
  );

  // ---------------------------------------------------------------------------
  // J: classification (unlit, 1-D: the index is the sample's top ClassIdxW bits)
  // ---------------------------------------------------------------------------
  logic                              sh_in_ready, sh_out_valid, sh_out_ready;
  logic [ShInW-1:0]                  sh_in;
  logic [3*ColorW+AlphaW-1:0]        sh_rgba;

  always_comb begin
    sh_in = '0;
    sh_in[0 +: SampleW]                                      = tri_sample;
    sh_in[SampleW +: 3*ShGradW]                              = sh_grad;
    sh_in[SampleW + 3*ShGradW +: ShGradW]                    = sh_mag;
    sh_in[SampleW + 4*ShGradW + cube5_shader_pkg::ModeTf2d]  = sh_tf2d;
    sh_in[SampleW + 4*ShGradW + cube5_shader_pkg::ModeUnlit] = sh_unlit;
  end

  cube5_shader #(
    .VoxelW    (VoxelW),
    .FracW     (FracW),
    .ClassIdxW (ClassIdxW),
    .MagIdxW   (MagIdxW),
    .MagShift  (0),
    .ColorW    (ColorW),
    .AlphaW    (AlphaW),
    .RmLog2    (RmLog2),
    .RmFracW   (RmFracW),
    .DiffW     (DiffW),
    .SpecW     (SpecW)
  ) u_shader (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (tri_out_valid),
    .in_ready_o  (sh_in_ready),
    .in_data_i   (sh_in),
    .out_valid_o (sh_out_valid),
    .out_ready_i (sh_out_ready),
    .out_data_o  (sh_rgba),
    .cfg_valid_i (sh_cfg_valid),
    .cfg_addr_i  (sh_cfg_addr),
    .cfg_data_i  (sh_cfg_data)
  );

  assign tri_out_ready = sh_in_ready;

  // ---------------------------------------------------------------------------
  // The FIFOs: packet fields written as the item enters, the irradiance as it leaves its trilin,
  // both read as the classified sample enters the shade stage (pop)
  // ---------------------------------------------------------------------------
  logic              pop;
  logic [FifoAW-1:0] side_wp_d, side_wp_q, irr_wp_d, irr_wp_q, rp_d, rp_q;
  logic [SideW-1:0]  side_mem [FifoDepth];
  logic [IrrW-1:0]   irr_mem [FifoDepth];
  logic [SideW-1:0]  side_rd;
  logic [IrrW-1:0]   irr_rd;

  always_comb begin
    side_wp_d = in_fire   ? side_wp_q + FifoAW'(1) : side_wp_q;
    irr_wp_d  = irr_valid ? irr_wp_q + FifoAW'(1) : irr_wp_q;
    rp_d      = pop       ? rp_q + FifoAW'(1) : rp_q;
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      side_wp_q <= '0;
      irr_wp_q  <= '0;
      rp_q      <= '0;
    end else begin
      side_wp_q <= side_wp_d;
      irr_wp_q  <= irr_wp_d;
      rp_q      <= rp_d;
    end
  end

  // Memories: one write port, one asynchronous read port (distributed RAM on ECP5).
  always_ff @(posedge clk_i) begin
    if (in_fire) begin
      side_mem[side_wp_q] <= {in_data_i[IrrEnBit], in_data_i[LightingBit],
                              in_data_i[ColorLsb +: 4*ChanW]};
    end
    if (irr_valid) begin
      irr_mem[irr_wp_q] <= irr_sample;
    end
  end

  assign side_rd = side_mem[rp_q];
  assign irr_rd  = irr_mem[rp_q];

  // ---------------------------------------------------------------------------
  // L (second half), the shade stage: rgb = 0 (lighting), e * I (lit), or e; products registered
  // ---------------------------------------------------------------------------
  localparam int unsigned ProdW = ColorW + IrrW;

  // The shade stage, and with jitter the power-LUT stage after it.
  localparam int unsigned ShdStages = 1 + Jitter;

  logic [ShdStages-1:0]      shd_ready;
  logic                      shd_en, shd_valid, cx_in_ready;
  logic                      rd_lighting, rd_irr_en;
  logic [3*ProdW-1:0]        prod_d, prod_q;
  logic [4*ChanW-1:0]        pkt_q;      // red, green, blue, opacity
  logic [AlphaW-1:0]         alpha_q;

  cube5_valid_chain #(
    .Stages (ShdStages)
  ) u_shd_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (sh_out_valid),
    .out_ready_i (cx_in_ready),
    .ready_o     (shd_ready),
    .out_valid_o (shd_valid)
  );

  assign shd_en = shd_ready[0];

  assign sh_out_ready = shd_en;
  assign pop          = sh_out_valid && shd_en;
  assign rd_lighting  = side_rd[4*ChanW];
  assign rd_irr_en    = side_rd[4*ChanW+1];

  localparam logic [IrrW-1:0] IrrOne = IrrW'(1) << IrrFracW;

  logic [IrrW-1:0] irr_f;

  always_comb begin
    // An unlit sample's colour passes as e * 1.0, rounded back to e below.
    irr_f = rd_irr_en ? irr_rd : IrrOne;
    for (int c = 0; c < 3; c++) begin
      logic [ColorW-1:0] e;
      // A lighting ray's sample is black.
      e = rd_lighting ? '0 : sh_rgba[c*ColorW +: ColorW];
      prod_d[c*ProdW +: ProdW] = ProdW'(e) * ProdW'(irr_f);
    end
  end

  always_ff @(posedge clk_i) begin
    if (shd_en) begin
      prod_q  <= prod_d;
      pkt_q   <= side_rd[0 +: 4*ChanW];
      alpha_q <= sh_rgba[3*ColorW +: AlphaW];
    end
  end

  // rgb_c = min(255, rnd(e_c I, 14)); with I = 1.0 the product is e_c << 14 and rounds to e_c.
  logic [3*ColorW-1:0] shd_rgb;

  always_comb begin
    for (int c = 0; c < 3; c++) begin
      logic [ProdW-IrrFracW:0] r;
      r = (ProdW-IrrFracW+1)'((prod_q[c*ProdW +: ProdW] + (ProdW'(1) << (IrrFracW - 1)))
                              >> IrrFracW);
      shd_rgb[c*ColorW +: ColorW] = (r >> ColorW) != '0 ? {ColorW{1'b1}} : r[ColorW-1:0];
    end
  end

  // ---------------------------------------------------------------------------
  // K (first half), with Jitter = 1: the jittered alpha code (contract, "Jitter and the power
  // LUT"). The random LUT's index is the mangled position bits (the weights) of the item, kept
  // in a FIFO beside the side FIFO; the random and log LUTs are read with the shade stage, the
  // power LUT with the next, and its two entries interpolated into the compositor's input.
  // ---------------------------------------------------------------------------
  logic [4*ChanW-1:0]  cx_pkt;
  logic [3*ColorW-1:0] cx_rgb;
  logic [AlphaW-1:0]   cx_alpha;

  if (Jitter != 0) begin : gen_jitter
    localparam int unsigned JitIdxW  = gicube_sample_pkg::JitIdxW;
    localparam int unsigned JitW     = gicube_sample_pkg::JitW;
    localparam int unsigned LogW     = gicube_sample_pkg::LogW;
    localparam int unsigned ExpIdxW  = gicube_sample_pkg::ExpIdxW;
    localparam int unsigned ExpShift = LogW - ExpIdxW;
    localparam int unsigned ExpDiffW = gicube_sample_pkg::ExpDiffW;
    localparam int unsigned ExpW     = AlphaW + ExpDiffW;

    // The mangled position bits: wx ^ rotl8(wy, 3) ^ rotl8(wz, 5).
    logic [WeightW-1:0] wx, wy, wz, idx_wr;
    assign wx     = in_data_i[WeightsLsb +: WeightW];
    assign wy     = in_data_i[WeightsLsb + WeightW +: WeightW];
    assign wz     = in_data_i[WeightsLsb + 2*WeightW +: WeightW];
    assign idx_wr = wx ^ {wy[4:0], wy[7:5]} ^ {wz[2:0], wz[7:3]};

    logic [JitIdxW-1:0] idx_mem [FifoDepth];
    logic [JitIdxW-1:0] idx_rd;

    always_ff @(posedge clk_i) begin
      if (in_fire) begin
        idx_mem[side_wp_q] <= idx_wr;
      end
    end

    assign idx_rd = idx_mem[rp_q];

    // The tables: one write port (configuration), one synchronous read port each (block RAM).
    // The random and log LUTs are read with the shade stage: J[idx], L[alpha].
    logic            cfg_log, cfg_exp, cfg_jit;
    logic [LogW-1:0] log_q;
    logic [JitW-1:0] jit_q;

    assign cfg_log = cfg_low && cfg_addr_i[CfgAW-1:AlphaW] == 2'b01;
    assign cfg_exp = cfg_low && cfg_addr_i[CfgAW-1:ExpIdxW] == 4'b1110;
    assign cfg_jit = cfg_low && cfg_addr_i[CfgAW-1:JitIdxW] == 6'b111100;

    cube5_shader_ram #(
      .Depth (2**JitIdxW),
      .Width (JitW),
      .AddrW (JitIdxW)
    ) u_jit_lut (
      .clk_i   (clk_i),
      .we_i    (cfg_jit),
      .waddr_i (cfg_addr_i[JitIdxW-1:0]),
      .wdata_i (cfg_data_i[JitW-1:0]),
      .re_i    (shd_en),
      .raddr_i (idx_rd),
      .rdata_o (jit_q)
    );

    cube5_shader_ram #(
      .Depth (2**AlphaW),
      .Width (LogW),
      .AddrW (AlphaW)
    ) u_log_lut (
      .clk_i   (clk_i),
      .we_i    (cfg_log),
      .waddr_i (cfg_addr_i[AlphaW-1:0]),
      .wdata_i (cfg_data_i[LogW-1:0]),
      .re_i    (shd_en),
      .raddr_i (sh_rgba[3*ColorW +: AlphaW]),
      .rdata_o (log_q)
    );

    // p = rnd(L (2^7 + J), 8), U(4.12); below 2^16 for every L < 2^16 - 1.
    localparam int unsigned PW = LogW + JitW + 1;
    logic [PW-1:0]   prod_p;
    logic [LogW-1:0] p;
    logic            opaque;

    always_comb begin
      prod_p = PW'(log_q) * PW'({1'b1, jit_q}) + PW'(1 << JitW);
      p      = prod_p[JitW+1 +: LogW];
      opaque = log_q == '1;
    end

    // The power-LUT stage: E, D at p >> 6, the fraction, the opaque flag, the sample's colour and
    // the packet move on with it.
    logic                en_j;
    logic [ExpW-1:0]     exp_q;
    logic [ExpShift-1:0] frac_q;
    logic                opaque_q;
    logic [3*ColorW-1:0] rgb_q;
    logic [4*ChanW-1:0]  pkt_j_q;

    assign en_j = shd_ready[ShdStages-1];

    cube5_shader_ram #(
      .Depth (2**ExpIdxW),
      .Width (ExpW),
      .AddrW (ExpIdxW)
    ) u_exp_lut (
      .clk_i   (clk_i),
      .we_i    (cfg_exp),
      .waddr_i (cfg_addr_i[ExpIdxW-1:0]),
      .wdata_i (cfg_data_i[ExpW-1:0]),
      .re_i    (en_j),
      .raddr_i (p[LogW-1:ExpShift]),
      .rdata_o (exp_q)
    );

    always_ff @(posedge clk_i) begin
      if (en_j) begin
        frac_q   <= p[ExpShift-1:0];
        opaque_q <= opaque;
        rgb_q    <= shd_rgb;
        pkt_j_q  <= pkt_q;
      end
    end

    // a_j = E + rnd(D f, 6), or 4095 for an opaque sample.
    localparam int unsigned IpW = ExpDiffW + ExpShift;
    logic [IpW-1:0] interp;

    always_comb begin
      interp   = IpW'(exp_q[AlphaW +: ExpDiffW]) * IpW'(frac_q) + IpW'(1 << (ExpShift - 1));
      cx_alpha = opaque_q ? {AlphaW{1'b1}}
                          : exp_q[AlphaW-1:0] + AlphaW'(interp >> ExpShift);
      cx_rgb   = rgb_q;
      cx_pkt   = pkt_j_q;
    end

    // The alpha code the shade stage registered is read through the log LUT instead; the
    // product's bits below the rounding are dropped.
    logic unused_jitter;
    assign unused_jitter = ^{alpha_q, prod_p[JitW:0]};
  end else begin : gen_no_jitter
    always_comb begin
      cx_alpha = alpha_q;
      cx_rgb   = shd_rgb;
      cx_pkt   = pkt_q;
    end
  end

  // ---------------------------------------------------------------------------
  // K: compositing. Coxel (R, G, B, A = the packet's channels, U(1.12); Z = 1; no geometry; not
  // terminated), sample (rgb, alpha, depth 0, front to back).
  // ---------------------------------------------------------------------------
  logic [CxInW-1:0]  cx_in;
  logic [CoxelW-1:0] cx_out;

  always_comb begin
    cx_in = '0;
    for (int c = 0; c < 4; c++) begin
      cx_in[c*CxChanW +: CxChanW] = CxChanW'(cx_pkt[c*ChanW +: ChanW]);
    end
    cx_in[4*CxChanW +: ZW]                      = ZW'(1);
    cx_in[CoxelW +: 3*ColorW]                   = cx_rgb;
    cx_in[CoxelW + 3*ColorW +: AlphaW]          = cx_alpha;
    cx_in[CoxelW + 3*ColorW + AlphaW + ZW +: 3] = cube5_compos_pkg::ModeFrontToBack;
  end

  cube5_compos #(
    .ColorW (ColorW),
    .AlphaW (AlphaW),
    .ExtraW (0),
    .AccW   (AccW),
    .ZW     (ZW)
  ) u_compos (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .cfg_valid_i (cfg_compos),
    .cfg_addr_i  (cfg_addr_i[AlphaW:0]),
    .cfg_data_i  (cfg_data_i[AccW:0]),
    .in_valid_i  (shd_valid),
    .in_ready_o  (cx_in_ready),
    .in_data_i   (cx_in),
    .out_valid_o (out_valid_o),
    .out_ready_i (out_ready_i),
    .out_data_o  (cx_out)
  );

  // ---------------------------------------------------------------------------
  // Out: each channel min(c', 4095); terminated
  // ---------------------------------------------------------------------------
  always_comb begin
    for (int c = 0; c < 4; c++) begin
      logic [CxChanW-1:0] v;
      v = cx_out[c*CxChanW +: CxChanW];
      out_data_o[c*ChanW +: ChanW] = v[ChanW] ? {ChanW{1'b1}} : v[ChanW-1:0];
    end
    out_data_o[4*ChanW] = cx_out[CoxelW-1];
  end

  // Bits not read: the irradiance trilin's ready (always 1), the compositor's Z and geometry out.
  logic unused_bits;
  assign unused_bits = ^{irr_in_ready, cx_out[4*CxChanW +: ZW + 3*ColorW]};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_sample: output changed while stalled");
  // The irradiance trilin is never stalled, so it takes every item the density trilin takes.
  IrrTrilinNeverStalls: assert property (@(posedge clk_i) disable iff (!rst_ni) irr_in_ready)
    else $error("gicube_sample: irradiance trilin not ready");
  // The irradiance of the item popped has been written (it left its trilin at least 12 clocks
  // earlier than the classified sample).
  IrrBeforePop: assert property (@(posedge clk_i) disable iff (!rst_ni)
      pop |-> irr_wp_q != rp_q)
    else $error("gicube_sample: popped an irradiance not yet written");
  // The FIFOs never hold more than their depth (one entry per item in the trilin and shader).
  SideFifoNeverOverflows: assert property (@(posedge clk_i) disable iff (!rst_ni)
      in_fire && !pop |-> side_wp_q + FifoAW'(1) != rp_q)
    else $error("gicube_sample: side FIFO overflow");
`endif

endmodule
