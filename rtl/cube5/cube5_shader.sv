// cube5_shader: classification and reflectance-map illumination of one sample per cycle (patent
// [45], [354], [383]; contract in docs/numerics/shader.md).
//
// The sample's density (or density and gradient magnitude, mode tf2d) indexes the classification
// LUT; the gradient's major axis and sign pick one of six cube faces, an exact pipelined divider
// places the two minor components on that face, and four texels around that point, read in one
// cycle from four banks split by (i, j) parity (two per dual-port memory), are interpolated
// bilinearly into a diffuse and a specular intensity. Output: colour * diffuse + specular, rounded
// once and saturated; alpha passes through. Both tables and the zero-gradient entry are written
// through the configuration port and survive reset. Every stage holds while the next one is full,
// so the unit takes one item per cycle when the output is never stalled and never drops or
// duplicates an item.
module cube5_shader #(
  /// Voxel width; the sample is U(VoxelW.FracW).
  parameter int unsigned VoxelW    = 12,
  /// Fraction bits of the sample and of the gradient.
  parameter int unsigned FracW     = 4,
  /// Classification LUT index bits (2^ClassIdxW entries).
  parameter int unsigned ClassIdxW = 12,
  /// Magnitude bits of the 2-D classification index.
  parameter int unsigned MagIdxW   = 4,
  /// Magnitude bits dropped before the 2-D index saturates it.
  parameter int unsigned MagShift  = 10,
  /// R, G, B width, U(0.ColorW).
  parameter int unsigned ColorW    = 8,
  /// Alpha width (passed through).
  parameter int unsigned AlphaW    = 12,
  /// Reflectance-map cells per face side: 2^RmLog2 (texels: 2^RmLog2 + 1).
  parameter int unsigned RmLog2    = 3,
  /// Fraction bits of a face coordinate (bilinear weights).
  parameter int unsigned RmFracW   = 4,
  /// Diffuse intensity width, U(1.(DiffW-1)).
  parameter int unsigned DiffW     = 9,
  /// Specular intensity width, U(0.SpecW).
  parameter int unsigned SpecW     = 8,
  /// 0: the stages below; 1 (for clock rate, the frame's shaders): the decode in three stages
  /// (|g|; the major axis and the minor components; the dividends) and the output's products in
  /// a register of their own, three cycles more latency, the same bits (docs/numerics/shader.md,
  /// "Timing").
  parameter int unsigned Pipe      = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// sample (U(VoxelW.FracW)), gx, gy, gz (S(VoxelW+2 . FracW)), mag (U(VoxelW+2 . FracW)),
  /// mode (2: bit 0 tf2d, bit 1 unlit), LSB first.
  input  logic [cube5_shader_pkg::in_w(VoxelW, FracW)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// r, g, b (ColorW each), a (AlphaW), LSB first.
  output logic [cube5_shader_pkg::rgba_w(ColorW, AlphaW)-1:0] out_data_o,

  /// Configuration write this cycle (tables; see the contract's address map).
  input  logic cfg_valid_i,
  /// Region (top two bits) and offset.
  input  logic [cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2)-1:0] cfg_addr_i,
  /// Entry: r, g, b, a for the classification LUT; d, sp for a texel or the zero entry.
  input  logic [cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW)-1:0] cfg_data_i
);

  // ---------------------------------------------------------------------------
  // Widths
  // ---------------------------------------------------------------------------
  localparam int unsigned SampleW   = cube5_shader_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned GradW     = cube5_shader_pkg::grad_w(VoxelW, FracW);
  localparam int unsigned RgbaW     = cube5_shader_pkg::rgba_w(ColorW, AlphaW);
  localparam int unsigned CfgAW     = cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2);
  localparam int unsigned OffW      = CfgAW - 2;
  localparam int unsigned QW        = cube5_shader_pkg::quotient_w(RmLog2, RmFracW);
  localparam int unsigned DivStages = cube5_shader_pkg::div_stages(RmLog2, RmFracW);
  localparam int unsigned EW        = GradW + 1;        // divisor 2m, and each remainder window
  localparam int unsigned RemW      = GradW + QW;       // dividend (g + m) * 2^(QW-1) + m
  localparam int unsigned K1        = RmLog2 + 1;       // texel index i, j in 0 .. 2^RmLog2
  localparam int unsigned M         = cube5_shader_pkg::bank_side(RmLog2);
  localparam int unsigned BankDepth = 6 * M * M;
  localparam int unsigned BankAW    = $clog2(BankDepth);
  localparam int unsigned TexW      = DiffW + SpecW;
  localparam int unsigned WgtW      = RmFracW + 1;      // bilinear weight, 2^RmFracW = 1.0
  localparam int unsigned DenW      = ClassIdxW - MagIdxW;
  localparam int unsigned RowDW     = DiffW + RmFracW;  // one bilinear row, exact
  localparam int unsigned RowSW     = SpecW + RmFracW;
  localparam int unsigned ProdW     = ColorW + DiffW + SpecW + 1;
  localparam int unsigned OutShift  = DiffW - 1 + SpecW;

  // Input fields, LSB first.
  localparam int unsigned GxLsb   = SampleW;
  localparam int unsigned GyLsb   = SampleW + GradW;
  localparam int unsigned GzLsb   = SampleW + 2 * GradW;
  localparam int unsigned MagLsb  = SampleW + 3 * GradW;
  localparam int unsigned ModeLsb = SampleW + 4 * GradW;

  // Stages: decode (1 + 2 Pipe), the divider, bank addresses, texel reads (block RAM output
  // registers), the texels in fabric registers in cell order, bilinear U (prep, product),
  // bilinear V (prep with the classification read, product), the output's products (Pipe = 1),
  // output.
  localparam int unsigned DecSt = 1 + 2 * Pipe;
  localparam int unsigned StAdr = DecSt + DivStages;
  localparam int unsigned StRd  = StAdr + 1;
  localparam int unsigned StRq  = StAdr + 2;
  localparam int unsigned StUd  = StAdr + 3;
  localparam int unsigned StBu  = StAdr + 4;
  localparam int unsigned StVd  = StAdr + 5;
  localparam int unsigned StBv  = StAdr + 6;
  localparam int unsigned StOut = StBv + 1 + Pipe;
  localparam int unsigned NSt   = StOut + 1;

  // Elaboration checks mirror ShaderConfig::validate in the model.
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_shader: VoxelW must be 4..16");
  end
  if (FracW > 8) begin : gen_bad_frac_w
    $fatal(1, "cube5_shader: FracW must be 0..8");
  end
  if (ClassIdxW < 2 || ClassIdxW > 12 || ClassIdxW > SampleW) begin : gen_bad_class_idx_w
    $fatal(1, "cube5_shader: ClassIdxW must be 2..12 and at most VoxelW + FracW");
  end
  if (MagIdxW < 1 || MagIdxW >= ClassIdxW) begin : gen_bad_mag_idx_w
    $fatal(1, "cube5_shader: MagIdxW must be 1..ClassIdxW-1");
  end
  if (MagShift >= GradW) begin : gen_bad_mag_shift
    $fatal(1, "cube5_shader: MagShift must be 0..VoxelW+FracW+1");
  end
  if (ColorW < 1 || ColorW > 12) begin : gen_bad_color_w
    $fatal(1, "cube5_shader: ColorW must be 1..12");
  end
  if (AlphaW < 1 || AlphaW > 16) begin : gen_bad_alpha_w
    $fatal(1, "cube5_shader: AlphaW must be 1..16");
  end
  if (RmLog2 < 1 || RmLog2 > 7) begin : gen_bad_rm_log2
    $fatal(1, "cube5_shader: RmLog2 must be 1..7");
  end
  if (RmFracW < 1 || RmFracW > 8) begin : gen_bad_rm_frac_w
    $fatal(1, "cube5_shader: RmFracW must be 1..8");
  end
  if (DiffW < 2 || DiffW > 12) begin : gen_bad_diff_w
    $fatal(1, "cube5_shader: DiffW must be 2..12");
  end
  if (SpecW < 1 || SpecW > 12) begin : gen_bad_spec_w
    $fatal(1, "cube5_shader: SpecW must be 1..12");
  end
  if (Pipe > 1) begin : gen_bad_pipe
    $fatal(1, "cube5_shader: Pipe must be 0 or 1");
  end

  /// x * M with M = 2^(RmLog2-1) + 1, as a shift and an add (no multiplier).
  function automatic logic [BankAW-1:0] times_m(logic [BankAW-1:0] x);
    times_m = (x << (RmLog2 - 1)) + x;
  endfunction

  /// Address (face * M + jh) * M + ih of texel half-indices (jh, ih) in the bank of their parity.
  function automatic logic [BankAW-1:0] bank_addr(logic [2:0] face, logic [RmLog2-1:0] jh,
                                                  logic [RmLog2-1:0] ih);
    bank_addr = times_m(times_m(BankAW'(face)) + BankAW'(jh)) + BankAW'(ih);
  endfunction

  // ---------------------------------------------------------------------------
  // Stage handshakes: stage k loads when it or any later stage is empty, or the output moves
  // ---------------------------------------------------------------------------
  logic [NSt-1:0] en;

  cube5_valid_chain #(
    .Stages (NSt)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     (en),
    .out_valid_o (out_valid_o)
  );
  assign in_ready_o = en[0];

  // ---------------------------------------------------------------------------
  // Configuration port: classification entries, texels (to the bank of their parity), zero entry
  // ---------------------------------------------------------------------------
  logic [1:0]        cfg_region;
  logic [OffW-1:0]   cfg_off;
  logic [K1-1:0]     cfg_i, cfg_j;
  logic [OffW-1:0]   cfg_face;
  logic              class_we, texel_we, zero_we;
  logic [3:0]        bank_we;
  logic [BankAW-1:0] bank_waddr;

  always_comb begin
    cfg_region = cfg_addr_i[CfgAW-1 -: 2];
    cfg_off    = cfg_addr_i[OffW-1:0];
    cfg_i      = cfg_off[0 +: K1];
    cfg_j      = cfg_off[K1 +: K1];
    cfg_face   = cfg_off >> (2 * K1);
    class_we   = cfg_valid_i && cfg_region == cube5_shader_pkg::RegionClass
                 && (cfg_off >> ClassIdxW) == '0;
    texel_we   = cfg_valid_i && cfg_region == cube5_shader_pkg::RegionTexel
                 && cfg_face < OffW'(6)
                 && cfg_i <= K1'(1 << RmLog2) && cfg_j <= K1'(1 << RmLog2);
    zero_we    = cfg_valid_i && cfg_region == cube5_shader_pkg::RegionZero && cfg_off == '0;
    for (int b = 0; b < 4; b++) begin
      bank_we[b] = texel_we && {cfg_j[0], cfg_i[0]} == 2'(b);
    end
    bank_waddr = bank_addr(cfg_face[2:0], cfg_j[K1-1:1], cfg_i[K1-1:1]);
  end

  logic [TexW-1:0] zero_tex_q;

  always_ff @(posedge clk_i) begin
    if (zero_we) begin
      zero_tex_q <= cfg_data_i[TexW-1:0];
    end
  end

  // ---------------------------------------------------------------------------
  // Decode: |g|, major axis and sign, dividends, zero flag, classification index
  // ---------------------------------------------------------------------------
  // Divider side band: {cidx, unlit, zero, face, e = 2m}, LSB first at these offsets.
  localparam int unsigned SdFace  = EW;
  localparam int unsigned SdZero  = EW + 3;
  localparam int unsigned SdUnlit = EW + 4;
  localparam int unsigned SdCidx  = EW + 5;
  localparam int unsigned SideW   = EW + 5 + ClassIdxW;

  logic [SampleW-1:0]   sample;
  logic [GradW-1:0]     gx, gy, gz, mag, ax, ay, az, m, gu, gv;
  logic [1:0]           mode, axis;
  logic                 neg, zero, x_major, y_major;
  logic [EW-1:0]        num_u, num_v;
  logic [MagIdxW-1:0]   mag_bin;
  logic [ClassIdxW-1:0] cidx;
  logic [RemW-1:0]      dec_rem_u_d, dec_rem_v_d, dec_rem_u_q, dec_rem_v_q;
  logic [SideW-1:0]     dec_side_d, dec_side_q;

  // Part 1: |g| and the classification index.
  always_comb begin
    sample = in_data_i[0 +: SampleW];
    gx     = in_data_i[GxLsb +: GradW];
    gy     = in_data_i[GyLsb +: GradW];
    gz     = in_data_i[GzLsb +: GradW];
    mag    = in_data_i[MagLsb +: GradW];
    mode   = in_data_i[ModeLsb +: 2];

    // Absolute values are exact in GradW unsigned bits (|-2^(GradW-1)| = 2^(GradW-1)).
    ax = gx[GradW-1] ? ~gx + GradW'(1) : gx;
    ay = gy[GradW-1] ? ~gy + GradW'(1) : gy;
    az = gz[GradW-1] ? ~gz + GradW'(1) : gz;

    // Classification index: the top bits of the sample, or density bits over magnitude bins.
    mag_bin = ((mag >> MagShift) >> MagIdxW) != '0 ? '1 : MagIdxW'(mag >> MagShift);
    cidx    = mode[cube5_shader_pkg::ModeTf2d] ? {sample[SampleW-1 -: DenW], mag_bin}
                                               : sample[SampleW-1 -: ClassIdxW];
  end

  // Part 2 reads part 1's values, through a register with Pipe = 1: |g|, g, the index, unlit.
  localparam int unsigned P1W = 6 * GradW + ClassIdxW + 1;
  logic [P1W-1:0] p1_d, p1;
  logic [GradW-1:0] ax2, ay2, az2, gx2, gy2, gz2;
  logic [ClassIdxW-1:0] cidx2;
  logic unlit2;
  assign p1_d = {mode[cube5_shader_pkg::ModeUnlit], cidx, gz, gy, gx, az, ay, ax};
  cube5_delay_regs #(.Width(P1W), .Stages(Pipe)) u_dec1 (
    .clk_i, .en_i(en[0]), .d_i(p1_d), .q_o(p1)
  );
  assign {unlit2, cidx2, gz2, gy2, gx2, az2, ay2, ax2} = p1;

  // Part 2: the major axis, its sign and |g| (m), the minor components (g_U, g_V), zero.
  localparam int unsigned P2W = 3 * GradW + ClassIdxW + 5;
  logic [P2W-1:0] p2_d, p2;
  logic [GradW-1:0] m3, gu3, gv3;
  logic [ClassIdxW-1:0] cidx3;
  logic [1:0] axis3;
  logic unlit3, zero3, neg3;

  always_comb begin
    zero    = (ax2 | ay2 | az2) == '0;
    x_major = ax2 >= ay2 && ax2 >= az2;
    y_major = !x_major && ay2 >= az2;
    // Minor axes are cyclic: x -> (y, z), y -> (z, x), z -> (x, y).
    if (x_major) begin
      axis = 2'd0; m = ax2; neg = gx2[GradW-1]; gu = gy2; gv = gz2;
    end else if (y_major) begin
      axis = 2'd1; m = ay2; neg = gy2[GradW-1]; gu = gz2; gv = gx2;
    end else begin
      axis = 2'd2; m = az2; neg = gz2[GradW-1]; gu = gx2; gv = gy2;
    end
  end
  assign p2_d = {unlit2, cidx2, zero, axis, neg, gv, gu, m};
  cube5_delay_regs #(.Width(P2W), .Stages(Pipe)) u_dec2 (
    .clk_i, .en_i(en[Pipe]), .d_i(p2_d), .q_o(p2)
  );
  assign {unlit3, cidx3, zero3, axis3, neg3, gv3, gu3, m3} = p2;

  // Part 3: the dividends.
  always_comb begin
    // g + m lies in [0, 2m]: nonnegative, EW bits.
    num_u = EW'($signed({gu3[GradW-1], gu3}) + $signed({1'b0, m3}));
    num_v = EW'($signed({gv3[GradW-1], gv3}) + $signed({1'b0, m3}));
    // q = floor(((g + m) * 2^(QW-1) + m) / (2m)): round half up of (g + m) * 2^(QW-2) / m.
    dec_rem_u_d = (RemW'(num_u) << (QW - 1)) + RemW'(m3);
    dec_rem_v_d = (RemW'(num_v) << (QW - 1)) + RemW'(m3);
    dec_side_d  = {cidx3, unlit3, zero3, axis3, neg3, m3, 1'b0};
  end

  always_ff @(posedge clk_i) begin
    if (en[DecSt - 1]) begin
      dec_rem_u_q <= dec_rem_u_d;
      dec_rem_v_q <= dec_rem_v_d;
      dec_side_q  <= dec_side_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Divider: restoring, DivBitsPerStage quotient bits per stage for q_U and q_V side by side
  // ---------------------------------------------------------------------------
  // Before the step that yields quotient bit b the remainder is below 2m * 2^(b+1), so only the
  // EW-bit window rem[b +: EW] takes part in that step. A zero gradient (m = 0) yields all-ones
  // quotients, which the address stage maps to a valid cell; its result is replaced anyway.
  logic [DivStages*RemW-1:0]  div_rem_u_in, div_rem_v_in, div_rem_u_d, div_rem_v_d;
  logic [DivStages*RemW-1:0]  div_rem_u_q, div_rem_v_q;
  logic [DivStages*QW-1:0]    div_qu_in, div_qv_in, div_qu_d, div_qv_d, div_qu_q, div_qv_q;
  logic [DivStages*SideW-1:0] div_side_in, div_side_q;

  always_comb begin
    div_rem_u_in[0 +: RemW]  = dec_rem_u_q;
    div_rem_v_in[0 +: RemW]  = dec_rem_v_q;
    div_qu_in[0 +: QW]       = '0;
    div_qv_in[0 +: QW]       = '0;
    div_side_in[0 +: SideW]  = dec_side_q;
    for (int s = 1; s < DivStages; s++) begin
      div_rem_u_in[s*RemW +: RemW]   = div_rem_u_q[(s-1)*RemW +: RemW];
      div_rem_v_in[s*RemW +: RemW]   = div_rem_v_q[(s-1)*RemW +: RemW];
      div_qu_in[s*QW +: QW]          = div_qu_q[(s-1)*QW +: QW];
      div_qv_in[s*QW +: QW]          = div_qv_q[(s-1)*QW +: QW];
      div_side_in[s*SideW +: SideW]  = div_side_q[(s-1)*SideW +: SideW];
    end

    div_rem_u_d = div_rem_u_in;
    div_rem_v_d = div_rem_v_in;
    div_qu_d    = div_qu_in;
    div_qv_d    = div_qv_in;
    for (int s = 0; s < DivStages; s++) begin
      for (int t = s * cube5_shader_pkg::DivBitsPerStage;
           t < (s + 1) * cube5_shader_pkg::DivBitsPerStage; t++) begin
        if (t < QW) begin
          logic [EW-1:0] e, hi_u, hi_v;
          e    = div_side_in[s*SideW +: EW];
          hi_u = div_rem_u_d[s*RemW + (QW - 1 - t) +: EW];
          hi_v = div_rem_v_d[s*RemW + (QW - 1 - t) +: EW];
          if (hi_u >= e) begin
            div_rem_u_d[s*RemW + (QW - 1 - t) +: EW] = hi_u - e;
            div_qu_d[s*QW + (QW - 1 - t)]            = 1'b1;
          end
          if (hi_v >= e) begin
            div_rem_v_d[s*RemW + (QW - 1 - t) +: EW] = hi_v - e;
            div_qv_d[s*QW + (QW - 1 - t)]            = 1'b1;
          end
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    for (int s = 0; s < DivStages; s++) begin
      if (en[DecSt + s]) begin
        div_rem_u_q[s*RemW +: RemW]  <= div_rem_u_d[s*RemW +: RemW];
        div_rem_v_q[s*RemW +: RemW]  <= div_rem_v_d[s*RemW +: RemW];
        div_qu_q[s*QW +: QW]         <= div_qu_d[s*QW +: QW];
        div_qv_q[s*QW +: QW]         <= div_qv_d[s*QW +: QW];
        div_side_q[s*SideW +: SideW] <= div_side_in[s*SideW +: SideW];
      end
    end
  end

  // ---------------------------------------------------------------------------
  // Cell, weights and the four bank addresses
  // ---------------------------------------------------------------------------
  logic [QW-1:0]        qu, qv;
  logic [SideW-1:0]     div_side;
  logic [2:0]           face;
  logic [RmLog2-1:0]    i0, j0;
  logic [WgtW-1:0]      eu, ev;
  logic [4*BankAW-1:0]  adr_bank_d, adr_bank_q;
  logic [1:0]           adr_par_q;
  logic [2*WgtW-1:0]    adr_w_q;
  logic [ClassIdxW-1:0] adr_cidx_q;
  logic                 adr_zero_q, adr_unlit_q;

  always_comb begin
    qu       = div_qu_q[(DivStages-1)*QW +: QW];
    qv       = div_qv_q[(DivStages-1)*QW +: QW];
    div_side = div_side_q[(DivStages-1)*SideW +: SideW];
    face     = div_side[SdFace +: 3];
    // q = 2^(QW-1) is the far edge: the last cell with weight 1.0 on its far texel.
    if (qu[QW-1]) begin
      i0 = '1;
      eu = WgtW'(1) << RmFracW;
    end else begin
      i0 = qu[RmFracW +: RmLog2];
      eu = {1'b0, qu[RmFracW-1:0]};
    end
    if (qv[QW-1]) begin
      j0 = '1;
      ev = WgtW'(1) << RmFracW;
    end else begin
      j0 = qv[RmFracW +: RmLog2];
      ev = {1'b0, qv[RmFracW-1:0]};
    end
    // Bank bi + 2 bj holds the texel of the cell's corners with i parity bi and j parity bj.
    for (int bj = 0; bj < 2; bj++) begin
      for (int bi = 0; bi < 2; bi++) begin
        logic [K1-1:0] ib, jb;
        ib = K1'(i0) + K1'(i0[0] != 1'(bi));
        jb = K1'(j0) + K1'(j0[0] != 1'(bj));
        adr_bank_d[(bi + 2*bj)*BankAW +: BankAW] = bank_addr(face, RmLog2'(jb >> 1),
                                                             RmLog2'(ib >> 1));
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (en[StAdr]) begin
      adr_bank_q  <= adr_bank_d;
      adr_par_q   <= {j0[0], i0[0]};
      adr_w_q     <= {ev, eu};
      adr_cidx_q  <= div_side[SdCidx +: ClassIdxW];
      adr_zero_q  <= div_side[SdZero];
      adr_unlit_q <= div_side[SdUnlit];
    end
  end

  // ---------------------------------------------------------------------------
  // Texel reads: four banks, registered (the block RAMs' output registers)
  // ---------------------------------------------------------------------------
  logic [4*TexW-1:0]    bank_rdata;
  logic [1:0]           rd_par_q;
  logic [2*WgtW-1:0]    rd_w_q;
  logic [ClassIdxW-1:0] rd_cidx_q;
  logic                 rd_zero_q, rd_unlit_q;

  // Banks 2 bj and 2 bj + 1 (the two i parities of one j parity) in one memory, one port each
  // (cube5_shader_ram2): a dual-port block RAM holds two banks. A texel write disturbs the texel
  // reads of its cycle (docs/numerics/shader.md, "Configuration port").
  for (genvar bj = 0; bj < 2; bj++) begin : gen_bank
    cube5_shader_ram2 #(
      .Depth (BankDepth),
      .Width (TexW),
      .AddrW (BankAW)
    ) u_banks (
      .clk_i   (clk_i),
      .we_i    (bank_we[2*bj +: 2]),
      .waddr_i (bank_waddr),
      .wdata_i (cfg_data_i[TexW-1:0]),
      .re_i    (en[StRd]),
      .raddr_i (adr_bank_q[2*bj*BankAW +: 2*BankAW]),
      .rdata_o (bank_rdata[2*bj*TexW +: 2*TexW])
    );
  end

  always_ff @(posedge clk_i) begin
    if (en[StRd]) begin
      rd_par_q   <= adr_par_q;
      rd_w_q     <= adr_w_q;
      rd_cidx_q  <= adr_cidx_q;
      rd_zero_q  <= adr_zero_q;
      rd_unlit_q <= adr_unlit_q;
    end
  end

  // ---------------------------------------------------------------------------
  // The texels in fabric registers, in cell order (block RAM clock-to-out is slow)
  // ---------------------------------------------------------------------------
  logic [4*TexW-1:0]    by_i, quad_d, quad_q;  // texel (i0 + a, j0 + b) at [(a + 2b)*TexW +: TexW]
  logic [2*WgtW-1:0]    rq_w_q;
  logic [ClassIdxW-1:0] rq_cidx_q;
  logic                 rq_zero_q, rq_unlit_q;

  always_comb begin
    // Texel (i0 + a, j0 + b) sits in bank (par_i ^ a) + 2 (par_j ^ b): undo the parity order,
    // first along i (swap within pairs), then along j (swap the pairs).
    by_i   = rd_par_q[0] ? {bank_rdata[2*TexW +: TexW], bank_rdata[3*TexW +: TexW],
                            bank_rdata[0 +: TexW], bank_rdata[TexW +: TexW]}
                         : bank_rdata;
    quad_d = rd_par_q[1] ? {by_i[0 +: 2*TexW], by_i[2*TexW +: 2*TexW]} : by_i;
  end

  always_ff @(posedge clk_i) begin
    if (en[StRq]) begin
      quad_q     <= quad_d;
      rq_w_q     <= rd_w_q;
      rq_cidx_q  <= rd_cidx_q;
      rq_zero_q  <= rd_zero_q;
      rq_unlit_q <= rd_unlit_q;
    end
  end

  // ---------------------------------------------------------------------------
  // Bilinear along U, exact (two stages: prep, product):
  //   row b = T(i0, j0+b) * (1 - eu) + T(i0+1, j0+b) * eu
  // ---------------------------------------------------------------------------
  logic [2*RowDW-1:0]   row_d;  // rows j0, j0+1, registered in the lerps
  logic [2*RowSW-1:0]   row_s;
  logic [2*WgtW-1:0]    ud_w_q;
  logic [WgtW-1:0]      bu_ev_q;
  logic [ClassIdxW-1:0] ud_cidx_q, bu_cidx_q;
  logic                 ud_zero_q, ud_unlit_q, bu_zero_q, bu_unlit_q;

  for (genvar b = 0; b < 2; b++) begin : gen_row
    cube5_shader_lerp #(
      .ValW     (DiffW),
      .WgtFracW (RmFracW),
      .RndShift (0)
    ) u_lerp_d (
      .clk_i     (clk_i),
      .en_prep_i (en[StUd]),
      .en_mul_i  (en[StBu]),
      .a_i       (quad_q[(2*b)*TexW +: DiffW]),
      .b_i       (quad_q[(2*b+1)*TexW +: DiffW]),
      .e_i       (ud_w_q[0 +: WgtW]),
      .y_o       (row_d[b*RowDW +: RowDW])
    );
    cube5_shader_lerp #(
      .ValW     (SpecW),
      .WgtFracW (RmFracW),
      .RndShift (0)
    ) u_lerp_s (
      .clk_i     (clk_i),
      .en_prep_i (en[StUd]),
      .en_mul_i  (en[StBu]),
      .a_i       (quad_q[(2*b)*TexW + DiffW +: SpecW]),
      .b_i       (quad_q[(2*b+1)*TexW + DiffW +: SpecW]),
      .e_i       (ud_w_q[0 +: WgtW]),
      .y_o       (row_s[b*RowSW +: RowSW])
    );
  end

  always_ff @(posedge clk_i) begin
    if (en[StUd]) begin
      ud_w_q     <= rq_w_q;
      ud_cidx_q  <= rq_cidx_q;
      ud_zero_q  <= rq_zero_q;
      ud_unlit_q <= rq_unlit_q;
    end
    if (en[StBu]) begin
      bu_ev_q    <= ud_w_q[WgtW +: WgtW];
      bu_cidx_q  <= ud_cidx_q;
      bu_zero_q  <= ud_zero_q;
      bu_unlit_q <= ud_unlit_q;
    end
  end

  // ---------------------------------------------------------------------------
  // Bilinear along V and rounding (prep, product): rnd(row0 * (1 - ev) + row1 * ev, 2 RmFracW).
  // A zero gradient feeds the zero-gradient entry, aligned as a row, to both ends: exact.
  // ---------------------------------------------------------------------------
  logic [2*RowDW-1:0] col_in_d;
  logic [2*RowSW-1:0] col_in_s;
  logic [DiffW-1:0]   lit_d;
  logic [SpecW-1:0]   lit_s;
  logic [WgtW-1:0]    vd_ev_q;
  logic               vd_unlit_q, bv_unlit_q;

  always_comb begin
    if (bu_zero_q) begin
      col_in_d = {2{zero_tex_q[0 +: DiffW], {RmFracW{1'b0}}}};
      col_in_s = {2{zero_tex_q[DiffW +: SpecW], {RmFracW{1'b0}}}};
    end else begin
      col_in_d = row_d;
      col_in_s = row_s;
    end
  end

  cube5_shader_lerp #(
    .ValW     (RowDW),
    .WgtFracW (RmFracW),
    .RndShift (2 * RmFracW)
  ) u_lerp_col_d (
    .clk_i     (clk_i),
    .en_prep_i (en[StVd]),
    .en_mul_i  (en[StBv]),
    .a_i       (col_in_d[0 +: RowDW]),
    .b_i       (col_in_d[RowDW +: RowDW]),
    .e_i       (vd_ev_q),
    .y_o       (lit_d)
  );

  cube5_shader_lerp #(
    .ValW     (RowSW),
    .WgtFracW (RmFracW),
    .RndShift (2 * RmFracW)
  ) u_lerp_col_s (
    .clk_i     (clk_i),
    .en_prep_i (en[StVd]),
    .en_mul_i  (en[StBv]),
    .a_i       (col_in_s[0 +: RowSW]),
    .b_i       (col_in_s[RowSW +: RowSW]),
    .e_i       (vd_ev_q),
    .y_o       (lit_s)
  );

  // The classification entry: read in the V prep stage (block RAM output register), then held in
  // a fabric register beside the V product.
  logic [RgbaW-1:0] class_rdata, bv_rgba_q;

  cube5_shader_ram #(
    .Depth (1 << ClassIdxW),
    .Width (RgbaW),
    .AddrW (ClassIdxW)
  ) u_class (
    .clk_i   (clk_i),
    .we_i    (class_we),
    .waddr_i (cfg_off[ClassIdxW-1:0]),
    .wdata_i (cfg_data_i[RgbaW-1:0]),
    .re_i    (en[StVd]),
    .raddr_i (bu_cidx_q),
    .rdata_o (class_rdata)
  );

  always_ff @(posedge clk_i) begin
    if (en[StVd]) begin
      vd_ev_q    <= bu_ev_q;
      vd_unlit_q <= bu_unlit_q;
    end
    if (en[StBv]) begin
      bv_rgba_q  <= class_rdata;
      bv_unlit_q <= vd_unlit_q;
    end
  end

  // ---------------------------------------------------------------------------
  // Output: c' = sat(rnd(c * d * 2^SpecW + sp * 2^(ColorW+DiffW-1), DiffW-1+SpecW)); alpha as is
  // ---------------------------------------------------------------------------
  logic [RgbaW-1:0] out_d, out_q;
  // The colour products c * d of the three channels, the specular intensity, the entry and the
  // unlit flag: as the V stages leave them, or (Pipe = 1) in a register of their own.
  localparam int unsigned CdW = ColorW + DiffW;
  localparam int unsigned PrW = 3 * CdW + SpecW + RgbaW + 1;
  logic [PrW-1:0]   pr_d, pr;
  logic [3*CdW-1:0] cd, cd_d;
  logic [SpecW-1:0] pr_lit_s;
  logic [RgbaW-1:0] pr_rgba;
  logic             pr_unlit;

  always_comb begin
    for (int ch = 0; ch < 3; ch++) begin
      cd_d[ch*CdW +: CdW] = CdW'(bv_rgba_q[ch*ColorW +: ColorW]) * CdW'(lit_d);
    end
  end
  assign pr_d = {bv_unlit_q, bv_rgba_q, lit_s, cd_d};
  cube5_delay_regs #(.Width(PrW), .Stages(Pipe)) u_prod (
    .clk_i, .en_i(en[StBv + Pipe]), .d_i(pr_d), .q_o(pr)
  );
  assign {pr_unlit, pr_rgba, pr_lit_s, cd} = pr;

  always_comb begin
    out_d = pr_rgba;  // alpha, and the colours when unlit
    for (int ch = 0; ch < 3; ch++) begin
      logic [ProdW-1:0]  sum;
      logic [ColorW+1:0] res;
      sum = (ProdW'(cd[ch*CdW +: CdW]) << SpecW)
          + (ProdW'(pr_lit_s) << (ColorW + DiffW - 1))
          + (ProdW'(1) << (OutShift - 1));
      res = (ColorW + 2)'(sum >> OutShift);
      if (!pr_unlit) begin
        out_d[ch*ColorW +: ColorW] = res[ColorW +: 2] != 2'b00 ? '1 : res[ColorW-1:0];
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (en[StOut]) begin
      out_q <= out_d;
    end
  end

  assign out_data_o  = out_q;

  // Bits read only in part: low sample bits, the remainders, the divisor after the divider,
  // padding above the fields of a configuration word.
  logic unused_bits;
  assign unused_bits = ^{sample, cfg_data_i, div_rem_u_q, div_rem_v_q, div_side[EW-1:0]};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_shader: output changed while stalled");
`endif

endmodule
