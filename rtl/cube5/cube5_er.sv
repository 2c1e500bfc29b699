// cube5_er: the ER-Perspective sweep (patent [155]-[197]; contract docs/numerics/er_perspective.md,
// "The RTL: cube5_er"). A first, sequential version: one composite sample every seven clocks, one
// MIP sample a clock.
//
// The volume sits in four parity-interleaved block-RAM banks (bank i%2 + 2 (j%2)), so the 2 x 2
// voxels of one bilinear sample are one read of every bank. The host sends the per-slice ray
// spacing H(s), the rays that sample the slice and the region extents; the top walks the rays of a
// slice, and for each issues its seven bilinear samples (C, x-, x+, y-, y+, B, A, one per clock)
// to cube5_trilin, gathers them into cube5_frame_shade (cube5_gradient N6, the adapter,
// cube5_shader), and composites the shaded sample onto the ray's coxel with cube5_compos
// (BackToFront or Max). Two coxel buffers hold the current region's rays and the next nearer
// one's; a Merge runs the 3 x 3 Bartlett (or centre) filter from one into the other.
//
//   items -> registers / voxel banks / unit tables
//   Slice -> ray walk -> 7 taps -> banks -> cube5_trilin -> gather 7 -> cube5_frame_shade
//         -> cube5_compos (+ the ray's coxel from the buffer) -> buffer
//   Merge -> 9 reads of the old buffer per new coxel -> tent sum -> other buffer
//   Emit  -> current buffer -> out
module cube5_er #(
  /// Largest volume edge (a power of two); four banks of MaxDim^3 / 4 voxels.
  parameter int unsigned MaxDim    = 64,
  /// Largest region extent edge in rays; two buffers of MaxRays^2 coxels.
  parameter int unsigned MaxRays   = 132,
  /// Unit widths (cube5_frame's names and defaults).
  parameter int unsigned VoxelW    = 12,
  parameter int unsigned WeightW   = 8,
  parameter int unsigned FracW     = 4,
  parameter int unsigned ClassIdxW = 12,
  parameter int unsigned MagIdxW   = 4,
  parameter int unsigned MagShift  = 10,
  parameter int unsigned ColorW    = 8,
  parameter int unsigned AlphaW    = 12,
  parameter int unsigned RmLog2    = 3,
  parameter int unsigned RmFracW   = 4,
  parameter int unsigned DiffW     = 9,
  parameter int unsigned SpecW     = 8,
  parameter int unsigned ExtraW    = 4,
  parameter int unsigned AccW      = 20,
  parameter int unsigned ZW        = 12
) (
  input  logic clk_i,
  /// Synchronous, active low: control state to idle; memories keep their contents.
  input  logic rst_ni,

  /// Items: payload, addr, op (LSB first; cube5_er_pkg).
  input  logic                                                                  in_valid_i,
  output logic                                                                  in_ready_o,
  input  logic [cube5_er_pkg::PayW+cube5_er_pkg::RegAddrW+2:0]                  in_data_i,

  /// Coxels of an Emit, row-major: the coxel (cube5_compos packing), then cycles (CntW).
  output logic                                                                  out_valid_o,
  input  logic                                                                  out_ready_i,
  output logic [cube5_compos_pkg::coxel_w(ColorW, AccW, ZW)+cube5_er_pkg::CntW-1:0] out_data_o
);

  localparam int unsigned PayW    = cube5_er_pkg::PayW;
  localparam int unsigned AddrW   = cube5_er_pkg::RegAddrW;
  localparam int unsigned RayW    = cube5_er_pkg::RayW;
  localparam int unsigned HW      = cube5_er_pkg::SpacingW;
  localparam int unsigned PosW    = cube5_er_pkg::PosW;
  localparam int unsigned CntW    = cube5_er_pkg::CntW;
  localparam int unsigned F       = 16;
  localparam int unsigned M       = $clog2(MaxDim);
  localparam int unsigned DimW    = M + 1;
  localparam int unsigned BankAW  = 3 * M - 2;
  localparam int unsigned BankD   = MaxDim * MaxDim * MaxDim / 4;
  localparam int unsigned BufD    = MaxRays * MaxRays;
  localparam int unsigned BufAW   = $clog2(BufD);
  localparam int unsigned SampleW = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned TrInW   = cube5_pkg::trilin_in_w(VoxelW, WeightW);
  localparam int unsigned RgbaW   = 3 * ColorW + AlphaW;
  localparam int unsigned ChW     = AccW + 1;
  localparam int unsigned CoxW    = cube5_compos_pkg::coxel_w(ColorW, AccW, ZW);
  localparam int unsigned CInW    = cube5_compos_pkg::in_w(ColorW, AlphaW, AccW, ZW);
  localparam int unsigned ShAW    = cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2);
  localparam int unsigned ShDW    = cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW);
  localparam int unsigned AnchW   = PosW - F + 1;   // an anchor plus an offset of -1..2
  localparam int unsigned TW      = RayW + 2;       // a tap's slice, s - 1 .. s + 1
  localparam int unsigned SumW    = ChW + 5;        // a merge's weighted sum (weights sum to 16)

  if (MaxDim < 4 || MaxDim > 512 || (1 << M) != MaxDim) begin : gen_bad_max_dim
    $fatal(1, "cube5_er: MaxDim must be a power of two in 4..512");
  end
  if (MaxRays < 4 || MaxRays >= (1 << (RayW - 1))) begin : gen_bad_max_rays
    $fatal(1, "cube5_er: MaxRays must be in 4..2^(RayW-1)");
  end
  if (ShAW > AddrW || ShDW > PayW || AlphaW + 1 > AddrW || ChW > PayW) begin : gen_bad_cfg
    $fatal(1, "cube5_er: a unit's configuration write does not fit an item");
  end
  if (ZW > 16 || (1 << ZW) < MaxDim) begin : gen_bad_zw
    $fatal(1, "cube5_er: ZW must hold every slice number (2^ZW >= MaxDim)");
  end

  // ---------------------------------------------------------------------------------------------
  // Input items
  // ---------------------------------------------------------------------------------------------

  logic [2:0]       op;
  logic [AddrW-1:0] addr;
  logic [PayW-1:0]  payload;
  assign payload = in_data_i[PayW-1:0];
  assign addr    = in_data_i[PayW +: AddrW];
  assign op      = in_data_i[PayW+AddrW +: 3];

  typedef enum logic [2:0] {
    StIdle, StClear, StSlice, StDrain, StMerge, StMergeEnd, StEmit
  } state_e;
  state_e state_q, state_d;

  logic in_fire;
  assign in_ready_o = (state_q == StIdle);
  assign in_fire    = in_valid_i & in_ready_o;

  logic is_write, is_voxel, is_shader, is_compos, is_clear, is_slice, is_merge, is_emit;
  assign is_write  = in_fire && (op == cube5_er_pkg::OpWrite);
  assign is_voxel  = in_fire && (op == cube5_er_pkg::OpVoxel);
  assign is_shader = in_fire && (op == cube5_er_pkg::OpShader);
  assign is_compos = in_fire && (op == cube5_er_pkg::OpCompos);
  assign is_clear  = in_fire && (op == cube5_er_pkg::OpClear);
  assign is_slice  = in_fire && (op == cube5_er_pkg::OpSlice);
  assign is_merge  = in_fire && (op == cube5_er_pkg::OpMerge);
  assign is_emit   = in_fire && (op == cube5_er_pkg::OpEmit);

  // Payload fields of Clear / Merge (extent) and Slice.
  logic signed [RayW-1:0] p_m0, p_m1, p_n0, p_n1;
  logic signed [RayW-1:0] p_em0, p_en0;
  logic        [RayW-1:0] p_w, p_h;
  logic        [HW-1:0]   p_sp;
  logic        [RayW-1:0] p_s;
  assign p_m0 = payload[0 +: RayW];
  assign p_m1 = payload[RayW +: RayW];
  assign p_n0 = payload[2*RayW +: RayW];
  assign p_n1 = payload[3*RayW +: RayW];
  assign p_em0 = payload[0 +: RayW];
  assign p_en0 = payload[RayW +: RayW];
  assign p_w  = payload[2*RayW +: RayW];
  assign p_h  = payload[3*RayW +: RayW];
  assign p_sp = payload[4*RayW +: HW];
  assign p_s  = payload[4*RayW+HW +: RayW];

  // ---------------------------------------------------------------------------------------------
  // Registers
  // ---------------------------------------------------------------------------------------------

  logic [DimW-1:0]        ni_q, ni_d, nj_q, nj_d, nk_q, nk_d;
  logic signed [PosW-1:0] ei_q, ei_d, ej_q, ej_d;
  logic                   mip_q, mip_d, centre_q, centre_d;

  always_comb begin
    ni_d     = ni_q;
    nj_d     = nj_q;
    nk_d     = nk_q;
    ei_d     = ei_q;
    ej_d     = ej_q;
    mip_d    = mip_q;
    centre_d = centre_q;
    if (is_write) begin
      unique case (addr)
        AddrW'(cube5_er_pkg::RegDims): begin
          ni_d = DimW'(payload[cube5_er_pkg::RegDimsNiLsb +: cube5_er_pkg::RegDimsNiW]);
          nj_d = DimW'(payload[cube5_er_pkg::RegDimsNjLsb +: cube5_er_pkg::RegDimsNjW]);
          nk_d = DimW'(payload[cube5_er_pkg::RegDimsNkLsb +: cube5_er_pkg::RegDimsNkW]);
        end
        AddrW'(cube5_er_pkg::RegEI): ei_d = payload[PosW-1:0];
        AddrW'(cube5_er_pkg::RegEJ): ej_d = payload[PosW-1:0];
        AddrW'(cube5_er_pkg::RegMode): begin
          mip_d    = payload[cube5_er_pkg::RegModeMipLsb];
          centre_d = payload[cube5_er_pkg::RegModeCentreLsb];
        end
        default: ;
      endcase
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      ni_q     <= '0;
      nj_q     <= '0;
      nk_q     <= '0;
      ei_q     <= '0;
      ej_q     <= '0;
      mip_q    <= 1'b0;
      centre_q <= 1'b0;
    end else begin
      ni_q     <= ni_d;
      nj_q     <= nj_d;
      nk_q     <= nk_d;
      ei_q     <= ei_d;
      ej_q     <= ej_d;
      mip_q    <= mip_d;
      centre_q <= centre_d;
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Volume: four parity banks, loaded at (li, lj, lt), i fastest
  // ---------------------------------------------------------------------------------------------

  logic [DimW-1:0] li_q, li_d, lj_q, lj_d, lt_q, lt_d;
  always_comb begin
    li_d = li_q;
    lj_d = lj_q;
    lt_d = lt_q;
    if (is_write && addr == AddrW'(cube5_er_pkg::RegDims)) begin
      li_d = '0;
      lj_d = '0;
      lt_d = '0;
    end else if (is_voxel) begin
      if (li_q + DimW'(1) >= ni_q) begin
        li_d = '0;
        if (lj_q + DimW'(1) >= nj_q) begin
          lj_d = '0;
          lt_d = lt_q + DimW'(1);
        end else begin
          lj_d = lj_q + DimW'(1);
        end
      end else begin
        li_d = li_q + DimW'(1);
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      li_q <= '0;
      lj_q <= '0;
      lt_q <= '0;
    end else begin
      li_q <= li_d;
      lj_q <= lj_d;
      lt_q <= lt_d;
    end
  end

  logic [BankAW-1:0] load_addr;
  assign load_addr = {lt_q[M-1:0], lj_q[M-1:1], li_q[M-1:1]};

  // Read side (the tap issue below): one address per bank, registered data.
  logic [4*BankAW-1:0] bank_raddr;
  logic                bank_re;
  logic [4*VoxelW-1:0] bank_rdata;

  for (genvar k = 0; k < 4; k++) begin : gen_bank
    cube5_section_buf_ram #(
      .Depth (BankD),
      .Width (VoxelW),
      .AddrW (BankAW)
    ) u_bank (
      .clk_i   (clk_i),
      .we_i    (is_voxel && ({lj_q[0], li_q[0]} == 2'(k))),
      .waddr_i (load_addr),
      .wdata_i (payload[VoxelW-1:0]),
      .re_i    (bank_re),
      .raddr_i (bank_raddr[k*BankAW +: BankAW]),
      .rdata_o (bank_rdata[k*VoxelW +: VoxelW])
    );
  end

  // ---------------------------------------------------------------------------------------------
  // Current extent, buffer select, frame cycle counter
  // ---------------------------------------------------------------------------------------------

  logic signed [RayW-1:0] cm0_q, cm0_d, cn0_q, cn0_d;
  logic [RayW-1:0]        cw_q, cw_d, ch_q, ch_d;
  logic [2*RayW-1:0]      total_q, total_d;
  logic                   cur_q, cur_d;
  logic [CntW-1:0]        cyc_q, cyc_d, cyc_out_q, cyc_out_d;

  // Merge target (the new extent) while a Merge runs.
  logic signed [RayW-1:0] nm0_q, nm0_d, nn0_q, nn0_d;
  logic [RayW-1:0]        nw_q, nw_d, nh_q, nh_d;

  // ---------------------------------------------------------------------------------------------
  // Slice: the ray walk and the tap issue
  // ---------------------------------------------------------------------------------------------

  logic [RayW-1:0]        s_q, s_d;
  logic [HW-1:0]          sp_q, sp_d;
  logic signed [RayW-1:0] sm0_q, sm0_d, sm1_q, sm1_d, sn1_q, sn1_d;
  logic signed [RayW-1:0] m_q, m_d, n_q, n_d;
  logic signed [PosW-1:0] x0_q, x0_d, x_q, x_d, y_q, y_d;
  logic [2:0]             tap_q, tap_d;
  logic [7:0]             inflight_q, inflight_d;
  logic                   ray_issue, ray_done, last_tap;

  // MIP shades unlit: the shader ignores the gradient, so a MIP ray takes its C tap alone (one
  // clock per sample) and the gradient sees zeros for the six neighbours.
  assign last_tap = mip_q ? 1'b1 : (tap_q == 3'd6);

  // X = EI + m H and Y = EJ + n H of the slice's first ray (exact integer products).
  logic signed [PosW-1:0] x_first, y_first;
  assign x_first = PosW'(ei_q + $signed({{(PosW-RayW){p_m0[RayW-1]}}, p_m0}) * $signed({1'b0, p_sp}));
  assign y_first = PosW'(ej_q + $signed({{(PosW-RayW){p_n0[RayW-1]}}, p_n0}) * $signed({1'b0, p_sp}));

  // This clock's tap: offsets (da, db, dk) of C, x-, x+, y-, y+, B, A.
  logic signed [1:0] da, db, dk;
  always_comb begin
    da = 2'sd0;
    db = 2'sd0;
    dk = 2'sd0;
    unique case (tap_q)
      3'd1:    da = -2'sd1;
      3'd2:    da = 2'sd1;
      3'd3:    db = -2'sd1;
      3'd4:    db = 2'sd1;
      3'd5:    dk = -2'sd1;
      3'd6:    dk = 2'sd1;
      default: ;
    endcase
  end

  logic signed [AnchW-1:0] ta, tb;
  logic signed [TW-1:0]    tt;
  logic                    t_in;
  logic [WeightW-1:0]      twx, twy;
  assign ta  = AnchW'(x_q >>> F) + AnchW'(da);
  assign tb  = AnchW'(y_q >>> F) + AnchW'(db);
  assign tt  = $signed({2'b00, s_q}) + TW'(dk);
  assign twx = x_q[F-1 -: WeightW];
  assign twy = y_q[F-1 -: WeightW];
  // The anchor inside the face and the slice inside 0..nk (else the sample is 0).
  logic signed [AnchW-1:0] ni_s, nj_s;
  logic signed [TW-1:0]    nk_s;
  assign ni_s = $signed(AnchW'(ni_q));
  assign nj_s = $signed(AnchW'(nj_q));
  assign nk_s = $signed(TW'(nk_q));
  assign t_in = (ta >= 0) && (ta < ni_s) && (tb >= 0) && (tb < nj_s) && (tt >= 0) && (tt < nk_s);

  // Bank (p, q) holds corner (u, v) = (p ^ a[0], q ^ b[0]) at ((a + u) / 2, (b + v) / 2, t).
  always_comb begin
    for (int unsigned k = 0; k < 4; k++) begin
      logic [M-2:0] ci, cj;
      ci = (M-1)'((ta[M-1:0] + M'(((k % 2) != 0) != ta[0])) >> 1);
      cj = (M-1)'((tb[M-1:0] + M'(((k / 2) != 0) != tb[0])) >> 1);
      bank_raddr[k*BankAW +: BankAW] = {tt[M-1:0], cj, ci};
    end
  end

  assign ray_issue = (state_q == StSlice) && (tap_q == 3'd0);
  assign bank_re   = (state_q == StSlice);

  // The tap's flags beside the banks' registered data.
  logic               tv_q, tv_d;
  logic [3:0]         tmask_q, tmask_d;
  logic [1:0]         tpar_q, tpar_d;
  logic [WeightW-1:0] twx_q, twx_d, twy_q, twy_d;

  always_comb begin
    tv_d  = (state_q == StSlice);
    tpar_d = {tb[0], ta[0]};
    twx_d = twx;
    twy_d = twy;
    for (int unsigned c = 0; c < 4; c++) begin
      // Corner c = u + 2v: inside the face (voxels beyond the far faces read as zero).
      tmask_d[c] = t_in && ((ta + $signed(AnchW'(c % 2))) < ni_s)
                        && ((tb + $signed(AnchW'(c / 2))) < nj_s);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      tv_q <= 1'b0;
    end else begin
      tv_q <= tv_d;
    end
  end
  always_ff @(posedge clk_i) begin
    tmask_q <= tmask_d;
    tpar_q  <= tpar_d;
    twx_q   <= twx_d;
    twy_q   <= twy_d;
  end

  // ---------------------------------------------------------------------------------------------
  // Bilinear samples (cube5_trilin, Lerp, wz = 0, upper corners 0), gathered seven at a time
  // ---------------------------------------------------------------------------------------------

  logic [TrInW-1:0] tr_in;
  always_comb begin
    logic [4*VoxelW-1:0] corners;
    for (int unsigned c = 0; c < 4; c++) begin
      logic [1:0] bank;
      bank = 2'(c) ^ tpar_q;
      corners[c*VoxelW +: VoxelW] = tmask_q[c] ? bank_rdata[bank*VoxelW +: VoxelW] : '0;
    end
    tr_in = {cube5_pkg::TrilinModeLerp, WeightW'(0), twy_q, twx_q, (4*VoxelW)'(0), corners};
  end

  logic               tr_ready, tr_valid;
  logic [SampleW-1:0] tr_out;

  cube5_trilin #(
    .VoxelW  (VoxelW),
    .WeightW (WeightW),
    .FracW   (FracW)
  ) u_trilin (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (tv_q),
    .in_ready_o  (tr_ready),
    .in_data_i   (tr_in),
    .out_valid_o (tr_valid),
    .out_ready_i (1'b1),
    .out_data_o  (tr_out)
  );

  logic [2:0]           gk_q, gk_d;
  logic [6*SampleW-1:0] gnb_q, gnb_d;
  logic                 nb_valid;
  logic [7*SampleW-1:0] nb;

  always_comb begin
    gk_d  = gk_q;
    gnb_d = gnb_q;
    if (tr_valid && !mip_q) begin
      gk_d = (gk_q == 3'd6) ? 3'd0 : gk_q + 3'd1;
      if (gk_q != 3'd6) gnb_d[gk_q*SampleW +: SampleW] = tr_out;
    end
  end
  assign nb_valid = tr_valid && (mip_q || gk_q == 3'd6);
  assign nb       = mip_q ? {(6*SampleW)'(0), tr_out} : {tr_out, gnb_q};

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      gk_q <= '0;
    end else begin
      gk_q <= gk_d;
    end
  end
  always_ff @(posedge clk_i) begin
    gnb_q <= gnb_d;
  end

  // ---------------------------------------------------------------------------------------------
  // Gradient, adapter, shader (the frame's lane, P = 1)
  // ---------------------------------------------------------------------------------------------

  logic             rgba_valid;
  logic [RgbaW-1:0] rgba;

  cube5_frame_shade #(
    .P          (1),
    .VoxelW     (VoxelW),
    .FracW      (FracW),
    .WeightW    (WeightW),
    .ClassIdxW  (ClassIdxW),
    .MagIdxW    (MagIdxW),
    .MagShift   (MagShift),
    .ColorW     (ColorW),
    .AlphaW     (AlphaW),
    .RmLog2     (RmLog2),
    .RmFracW    (RmFracW),
    .DiffW      (DiffW),
    .SpecW      (SpecW),
    .ShCfgAddrW (ShAW),
    .ShCfgDataW (ShDW)
  ) u_shade (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .start_i       (is_clear),
    .shader_mode_i ({mip_q, 1'b0}),
    .nb_valid_i    (nb_valid),
    .nb_i          (nb),
    .cfg_valid_i   (is_shader),
    .cfg_addr_i    (addr[ShAW-1:0]),
    .cfg_data_i    (payload[ShDW-1:0]),
    .rgba_valid_o  (rgba_valid),
    .rgba_o        (rgba)
  );

  // ---------------------------------------------------------------------------------------------
  // Coxel buffers
  // ---------------------------------------------------------------------------------------------

  logic             buf_we_cur, buf_we_oth, buf_re;
  logic [BufAW-1:0] buf_waddr, buf_raddr;
  logic [CoxW-1:0]  buf_wdata, buf_rd_a, buf_rd_b, buf_rd;

  cube5_section_buf_ram #(
    .Depth (BufD),
    .Width (CoxW),
    .AddrW (BufAW)
  ) u_buf_a (
    .clk_i   (clk_i),
    .we_i    ((buf_we_cur && !cur_q) || (buf_we_oth && cur_q)),
    .waddr_i (buf_waddr),
    .wdata_i (buf_wdata),
    .re_i    (buf_re),
    .raddr_i (buf_raddr),
    .rdata_o (buf_rd_a)
  );

  cube5_section_buf_ram #(
    .Depth (BufD),
    .Width (CoxW),
    .AddrW (BufAW)
  ) u_buf_b (
    .clk_i   (clk_i),
    .we_i    ((buf_we_cur && cur_q) || (buf_we_oth && !cur_q)),
    .waddr_i (buf_waddr),
    .wdata_i (buf_wdata),
    .re_i    (buf_re),
    .raddr_i (buf_raddr),
    .rdata_o (buf_rd_b)
  );

  assign buf_rd = cur_q ? buf_rd_b : buf_rd_a;

  // The empty coxel: colour and opacity 0, Z none (all ones), no geometry, not terminated.
  logic [CoxW-1:0] empty_cox;
  assign empty_cox = {1'b0, (3*ColorW)'(0), {ZW{1'b1}}, (4*ChW)'(0)};

  // ---------------------------------------------------------------------------------------------
  // Compositing: the ray's coxel read when its shaded sample arrives
  // ---------------------------------------------------------------------------------------------

  // Ray coxel addresses, pushed at the ray's issue, popped at its shaded sample; then again
  // from the compositing input to its output.
  logic [BufAW-1:0] ray_addr, fa_q, fb_q;
  logic             fa_empty, fa_full, fb_empty, fb_full;
  logic [2*RayW-1:0] ray_row;
  assign ray_row  = (2*RayW)'(RayW'(n_q - cn0_q)) * (2*RayW)'(cw_q);
  assign ray_addr = BufAW'(ray_row + (2*RayW)'(RayW'(m_q - cm0_q)));

  cube5_frame_fifo #(
    .Width (BufAW),
    .Depth (32)
  ) u_fifo_a (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (is_clear),
    .push_i  (ray_issue),
    .d_i     (ray_addr),
    .pop_i   (rgba_valid),
    .q_o     (fa_q),
    .empty_o (fa_empty),
    .full_o  (fa_full)
  );

  logic             c1_valid_q;
  logic [RgbaW-1:0] c1_rgba_q;
  logic [BufAW-1:0] c1_addr_q;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      c1_valid_q <= 1'b0;
    end else begin
      c1_valid_q <= rgba_valid;
    end
  end
  always_ff @(posedge clk_i) begin
    c1_rgba_q <= rgba;
    c1_addr_q <= fa_q;
  end

  logic [CInW-1:0] cp_in;
  logic            cp_ready, cp_valid;
  logic [CoxW-1:0] cp_out;
  assign cp_in = {(mip_q ? cube5_compos_pkg::ModeMax : cube5_compos_pkg::ModeBackToFront),
                  ZW'(s_q), c1_rgba_q, buf_rd};

  cube5_compos #(
    .ColorW (ColorW),
    .AlphaW (AlphaW),
    .ExtraW (ExtraW),
    .AccW   (AccW),
    .ZW     (ZW)
  ) u_compos (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .cfg_valid_i (is_compos),
    .cfg_addr_i  (addr[AlphaW:0]),
    .cfg_data_i  (payload[AccW:0]),
    .in_valid_i  (c1_valid_q),
    .in_ready_o  (cp_ready),
    .in_data_i   (cp_in),
    .out_valid_o (cp_valid),
    .out_ready_i (1'b1),
    .out_data_o  (cp_out)
  );

  cube5_frame_fifo #(
    .Width (BufAW),
    .Depth (16)
  ) u_fifo_b (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (is_clear),
    .push_i  (c1_valid_q),
    .d_i     (c1_addr_q),
    .pop_i   (cp_valid),
    .q_o     (fb_q),
    .empty_o (fb_empty),
    .full_o  (fb_full)
  );

  assign ray_done = cp_valid;

  // ---------------------------------------------------------------------------------------------
  // Merge: nine reads of the old buffer per new coxel, the tent sum, one write of the other
  // ---------------------------------------------------------------------------------------------

  logic [RayW-1:0] mi_q, mi_d, mj_q, mj_d;       // the new coxel, relative to the new extent
  logic [1:0]      mu_q, mu_d, mv_q, mv_d;       // its tap (u, v) in 0..2
  logic [BufAW-1:0] mwa_q, mwa_d;                // its address in the new buffer
  logic            merge_issue;
  assign merge_issue = (state_q == StMerge);

  // Old-region ray (2m' + u - 1, 2n' + v - 1), relative to the old extent.
  logic signed [RayW+2:0] om, on;
  logic                   m_in;
  logic [BufAW-1:0]       m_raddr;
  logic [2*RayW-1:0]      m_row;
  logic signed [RayW+2:0] nm_s, nn_s, mi_s, mj_s, mu_s, mv_s, cm_s, cn_s, cw_s, ch_s;
  always_comb begin
    nm_s = (RayW+3)'(nm0_q);
    nn_s = (RayW+3)'(nn0_q);
    cm_s = (RayW+3)'(cm0_q);
    cn_s = (RayW+3)'(cn0_q);
    mi_s = $signed((RayW+3)'(mi_q));
    mj_s = $signed((RayW+3)'(mj_q));
    mu_s = $signed((RayW+3)'(mu_q));
    mv_s = $signed((RayW+3)'(mv_q));
    cw_s = $signed((RayW+3)'(cw_q));
    ch_s = $signed((RayW+3)'(ch_q));
    om   = ((nm_s + mi_s) <<< 1) + mu_s - (RayW+3)'(1) - cm_s;
    on   = ((nn_s + mj_s) <<< 1) + mv_s - (RayW+3)'(1) - cn_s;
    m_in = (om >= 0) && (om < cw_s) && (on >= 0) && (on < ch_s);
    m_row   = (2*RayW)'(RayW'(on)) * (2*RayW)'(cw_q);
    m_raddr = BufAW'(m_row + (2*RayW)'(RayW'(om)));
  end

  // The tap's place in its coxel's nine.
  logic m_first, m_last;
  assign m_first = (mu_q == 2'd0) && (mv_q == 2'd0);
  assign m_last  = (mu_q == 2'd2) && (mv_q == 2'd2);

  // Tent weights (1, 2, 1) x (1, 2, 1), or 16 on the centre alone.
  logic [4:0] m_w;
  always_comb begin
    if (centre_q) begin
      m_w = (mu_q == 2'd1 && mv_q == 2'd1) ? 5'd16 : 5'd0;
    end else begin
      m_w = 5'((mu_q == 2'd1) ? 2 : 1) * 5'((mv_q == 2'd1) ? 2 : 1);
    end
  end

  logic             mq_valid_q, mq_first_q, mq_last_q, mq_in_q;
  logic [4:0]       mq_w_q;
  logic [BufAW-1:0] mq_wa_q;
  logic [4*SumW-1:0] acc_q, acc_d;
  logic [4*ChW-1:0]  merged;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      mq_valid_q <= 1'b0;
    end else begin
      mq_valid_q <= merge_issue;
    end
  end
  always_ff @(posedge clk_i) begin
    mq_first_q <= m_first;
    mq_last_q  <= m_last;
    mq_in_q    <= m_in;
    mq_w_q     <= m_w;
    mq_wa_q    <= mwa_q;
    acc_q      <= acc_d;
  end

  always_comb begin
    acc_d = acc_q;
    for (int unsigned c = 0; c < 4; c++) begin
      logic [SumW-1:0] term, sum;
      term = mq_in_q ? SumW'(mq_w_q) * SumW'(buf_rd[c*ChW +: ChW]) : '0;
      sum  = (mq_first_q ? '0 : acc_q[c*SumW +: SumW]) + term;
      if (mq_valid_q) acc_d[c*SumW +: SumW] = sum;
      merged[c*ChW +: ChW] = ChW'((sum + SumW'(8)) >> 4);
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Emit
  // ---------------------------------------------------------------------------------------------

  logic [2*RayW-1:0] ea_q, ea_d;
  logic              eph_q, eph_d;            // 1: a read is in flight
  logic              out_valid_q, out_valid_d;
  logic [CoxW+CntW-1:0] out_data_q, out_data_d;

  // ---------------------------------------------------------------------------------------------
  // Control
  // ---------------------------------------------------------------------------------------------

  logic [2*RayW-1:0] ca_q, ca_d;              // Clear's address

  always_comb begin
    state_d     = state_q;
    cm0_d       = cm0_q;
    cn0_d       = cn0_q;
    cw_d        = cw_q;
    ch_d        = ch_q;
    total_d     = total_q;
    cur_d       = cur_q;
    cyc_d       = cyc_q + CntW'(1);
    cyc_out_d   = cyc_out_q;
    nm0_d       = nm0_q;
    nn0_d       = nn0_q;
    nw_d        = nw_q;
    nh_d        = nh_q;
    s_d         = s_q;
    sp_d        = sp_q;
    sm0_d       = sm0_q;
    sm1_d       = sm1_q;
    sn1_d       = sn1_q;
    m_d         = m_q;
    n_d         = n_q;
    x0_d        = x0_q;
    x_d         = x_q;
    y_d         = y_q;
    tap_d       = tap_q;
    inflight_d  = inflight_q + 8'(ray_issue) - 8'(ray_done);
    mi_d        = mi_q;
    mj_d        = mj_q;
    mu_d        = mu_q;
    mv_d        = mv_q;
    mwa_d       = mwa_q;
    ea_d        = ea_q;
    eph_d       = eph_q;
    ca_d        = ca_q;
    out_valid_d = out_valid_q && !out_ready_i;
    out_data_d  = out_data_q;

    buf_we_cur = 1'b0;
    buf_we_oth = 1'b0;
    buf_waddr  = '0;
    buf_wdata  = empty_cox;
    buf_re     = 1'b0;
    buf_raddr  = '0;

    // Buffer reads: the compositing's coxel, a merge's tap, an emit's coxel.
    if (rgba_valid) begin
      buf_re    = 1'b1;
      buf_raddr = fa_q;
    end else if (merge_issue) begin
      buf_re    = m_in;
      buf_raddr = m_raddr;
    end else if (state_q == StEmit && !eph_q && !out_valid_q && ea_q < total_q) begin
      buf_re    = 1'b1;
      buf_raddr = BufAW'(ea_q);
    end

    // Buffer writes: the compositing's coxel, a merge's coxel (other buffer), a clear.
    if (cp_valid) begin
      buf_we_cur = 1'b1;
      buf_waddr  = fb_q;
      buf_wdata  = cp_out;
    end else if (mq_valid_q && mq_last_q) begin
      buf_we_oth = 1'b1;
      buf_waddr  = mq_wa_q;
      buf_wdata  = {empty_cox[CoxW-1:4*ChW], merged};
    end else if (state_q == StClear && ca_q < total_q) begin
      buf_we_cur = 1'b1;
      buf_waddr  = BufAW'(ca_q);
    end

    unique case (state_q)
      StIdle: begin
        if (is_clear) begin
          cm0_d   = p_em0;
          cn0_d   = p_en0;
          cw_d    = p_w;
          ch_d    = p_h;
          total_d = (2*RayW)'(p_w) * (2*RayW)'(p_h);
          cyc_d   = '0;
          ca_d    = '0;
          state_d = StClear;
        end else if (is_slice) begin
          s_d   = p_s;
          sp_d  = p_sp;
          sm0_d = p_m0;
          sm1_d = p_m1;
          sn1_d = p_n1;
          m_d   = p_m0;
          n_d   = p_n0;
          x0_d  = x_first;
          x_d   = x_first;
          y_d   = y_first;
          tap_d = '0;
          if (p_m0 <= p_m1 && p_n0 <= p_n1) state_d = StSlice;
        end else if (is_merge) begin
          nm0_d   = p_em0;
          nn0_d   = p_en0;
          nw_d    = p_w;
          nh_d    = p_h;
          mi_d    = '0;
          mj_d    = '0;
          mu_d    = '0;
          mv_d    = '0;
          mwa_d   = '0;
          if (p_w != '0 && p_h != '0) state_d = StMerge;
          else state_d = StMergeEnd;
        end else if (is_emit) begin
          cyc_out_d = cyc_q;
          ea_d      = '0;
          eph_d     = 1'b0;
          state_d   = StEmit;
        end
      end

      StClear: begin
        if (ca_q >= total_q) begin
          state_d = StIdle;
        end else begin
          ca_d = ca_q + (2*RayW)'(1);
        end
      end

      StSlice: begin
        if (last_tap) begin
          tap_d = '0;
          if (m_q == sm1_q) begin
            m_d = sm0_q;
            x_d = x0_q;
            if (n_q == sn1_q) begin
              state_d = StDrain;
            end else begin
              n_d = n_q + RayW'(1);
              y_d = y_q + PosW'(sp_q);
            end
          end else begin
            m_d = m_q + RayW'(1);
            x_d = x_q + PosW'(sp_q);
          end
        end else begin
          tap_d = tap_q + 3'd1;
        end
      end

      StDrain: begin
        if (inflight_q == '0) state_d = StIdle;
      end

      StMerge: begin
        if (mu_q != 2'd2) begin
          mu_d = mu_q + 2'd1;
        end else begin
          mu_d = '0;
          if (mv_q != 2'd2) begin
            mv_d = mv_q + 2'd1;
          end else begin
            mv_d  = '0;
            mwa_d = mwa_q + BufAW'(1);
            if (mi_q + RayW'(1) != nw_q) begin
              mi_d = mi_q + RayW'(1);
            end else begin
              mi_d = '0;
              if (mj_q + RayW'(1) != nh_q) begin
                mj_d = mj_q + RayW'(1);
              end else begin
                state_d = StMergeEnd;
              end
            end
          end
        end
      end

      StMergeEnd: begin
        // The last coxel is written in this clock; the new buffer is the current one after it.
        cur_d   = !cur_q;
        cm0_d   = nm0_q;
        cn0_d   = nn0_q;
        cw_d    = nw_q;
        ch_d    = nh_q;
        total_d = (2*RayW)'(nw_q) * (2*RayW)'(nh_q);
        state_d = StIdle;
      end

      StEmit: begin
        if (eph_q) begin
          out_valid_d = 1'b1;
          out_data_d  = {cyc_out_q, buf_rd};
          ea_d        = ea_q + (2*RayW)'(1);
          eph_d       = 1'b0;
        end else if (ea_q >= total_q) begin
          state_d = StIdle;
        end else if (!out_valid_q) begin
          eph_d = 1'b1;
        end
      end

      default: state_d = StIdle;
    endcase
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      state_q     <= StIdle;
      cur_q       <= 1'b0;
      cm0_q       <= '0;
      cn0_q       <= '0;
      cw_q        <= '0;
      ch_q        <= '0;
      total_q     <= '0;
      cyc_q       <= '0;
      cyc_out_q   <= '0;
      tap_q       <= '0;
      inflight_q  <= '0;
      mu_q        <= '0;
      mv_q        <= '0;
      mi_q        <= '0;
      mj_q        <= '0;
      mwa_q       <= '0;
      ea_q        <= '0;
      eph_q       <= 1'b0;
      ca_q        <= '0;
      out_valid_q <= 1'b0;
    end else begin
      state_q     <= state_d;
      cur_q       <= cur_d;
      cm0_q       <= cm0_d;
      cn0_q       <= cn0_d;
      cw_q        <= cw_d;
      ch_q        <= ch_d;
      total_q     <= total_d;
      cyc_q       <= cyc_d;
      cyc_out_q   <= cyc_out_d;
      tap_q       <= tap_d;
      inflight_q  <= inflight_d;
      mu_q        <= mu_d;
      mv_q        <= mv_d;
      mi_q        <= mi_d;
      mj_q        <= mj_d;
      mwa_q       <= mwa_d;
      ea_q        <= ea_d;
      eph_q       <= eph_d;
      ca_q        <= ca_d;
      out_valid_q <= out_valid_d;
    end
  end

  always_ff @(posedge clk_i) begin
    nm0_q      <= nm0_d;
    nn0_q      <= nn0_d;
    nw_q       <= nw_d;
    nh_q       <= nh_d;
    s_q        <= s_d;
    sp_q       <= sp_d;
    sm0_q      <= sm0_d;
    sm1_q      <= sm1_d;
    sn1_q      <= sn1_d;
    m_q        <= m_d;
    n_q        <= n_d;
    x0_q       <= x0_d;
    x_q        <= x_d;
    y_q        <= y_d;
    out_data_q <= out_data_d;
  end

  assign out_valid_o = out_valid_q;
  assign out_data_o  = out_data_q;

  logic unused_er;
  assign unused_er = ^{fa_empty, fa_full, fb_empty, fb_full, tr_ready, cp_ready,
                       lt_q[DimW-1:M], payload[PayW-1:VoxelW]};

`ifndef SYNTHESIS
  ErOutStable: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_er: a stalled output changed");
  ErTrilinReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      tv_q |-> tr_ready)
    else $error("cube5_er: cube5_trilin was not ready");
  ErComposReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      c1_valid_q |-> cp_ready)
    else $error("cube5_er: cube5_compos was not ready");
  ErFifoA: assert property (@(posedge clk_i) disable iff (!rst_ni)
      !(ray_issue && fa_full) && !(rgba_valid && fa_empty))
    else $error("cube5_er: ray address FIFO over- or underflow");
  ErFifoB: assert property (@(posedge clk_i) disable iff (!rst_ni)
      !(c1_valid_q && fb_full) && !(cp_valid && fb_empty))
    else $error("cube5_er: compositing address FIFO over- or underflow");
  ErWritesApart: assert property (@(posedge clk_i) disable iff (!rst_ni)
      !(cp_valid && mq_valid_q && mq_last_q))
    else $error("cube5_er: two buffer writes in one clock");
`endif

endmodule
