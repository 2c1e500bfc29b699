// cube5_accel_ctrl: the accelerator's control core (issue 12). Behind the AXI4-Lite register
// block cube5_axil_regs (the map of cube5_accel.regs.toml, instantiated here) it sequences one
// frame as sections of `Section` anchors. Contract: docs/numerics/accel_ctrl.md.
//
// On a write of Ctrl.start (idle): latch the frame registers and the bases; four cycles of checks
// (refused: IrqStatus.error, Status.code); then, per section in order (left to right when DX >= 0,
// right to left when DX < 0), one command on each of the fetch, section-buffer and frame ports
// (each port independent, its own back-pressure); once the frame port has its last section, one
// row command per base-plane row on the writer port; then wait for the frame's done and every
// row's completion and set IrqStatus.done (or .error). Ctrl.soft_reset while busy: no new
// command, flush_o until the data path reports drained_i (its AXI4 transactions finished, its
// units reset), then the frame ends with code Aborted. The table window's TableData writes become
// writes on the table port, the index stepping after each.
`include "cube5_axi_ports.svh"

module cube5_accel_ctrl #(
  /// Pipelines: voxels per beam (1, 2, 4, 8).
  parameter int unsigned P = 4,
  /// Largest volume edge, a power of two (8..1024); `m = log2 MaxDim`.
  parameter int unsigned MaxDim = 64,
  /// Block edge `B` of the fetch and the section buffer.
  parameter int unsigned BlockDim = 8,
  /// Section width `S` in anchors.
  parameter int unsigned Section = 16,
  /// Byte address width of the AXI4 ports (volume and image bases).
  parameter int unsigned AddrW = 32,
  /// Data width of the AXI4 read port: the volume base must be a multiple of DataW / 8.
  parameter int unsigned DataW = 64,
  /// Bytes per base-plane pixel (the unit of the writer's `len`). Image rows start at multiples
  /// of the row alignment min(P PixelBytes, DataW / 8) bytes (the image writer's item).
  parameter int unsigned PixelBytes = 4,
  /// Bits of the writer's `len` field.
  parameter int unsigned LenW = 16,
  /// 1: the top has the frame's compositing window (cube5_accel Window = 1): the row commands go
  /// out from the frame's start (the top writes them with the initial coxel's code before the
  /// final pixels of each row), not after its last section. 0: after the last section.
  parameter int unsigned Window = 0
) (
  input  logic        clk_i,
  input  logic        rst_ni,
  // ---- AXI4-Lite subordinate: the host registers ----
  `CUBE5_AXIL_SUB_PORTS(s_axil_, 10),
  /// Level interrupt: |(IrqStatus & IrqEnable).
  output logic        irq_o,
  // ---- command ports (valid/ready; payload LSB first, docs/numerics/accel_ctrl.md) ----
  /// cube5_vol_fetch's sweep (op 1 payload): base, nb_x, nb_y, nb_z, axis_k, reversed, sec_lo, sec_hi.
  output logic        fetch_cmd_valid_o,
  input  logic        fetch_cmd_ready_i,
  output logic [AddrW+5*$clog2(MaxDim/BlockDim)+6:0] fetch_cmd_data_o,
  /// cube5_section_buf's section (op 1 payload): axis_k, reversed, ni, nj, nk, a0.
  output logic        sbuf_cmd_valid_o,
  input  logic        sbuf_cmd_ready_i,
  output logic [4*$clog2(MaxDim)+5:0] sbuf_cmd_data_o,
  /// The frame's section: Dims, View, Dx, Dy, Mode, Skip, sec_a0, sec_ns, sec_first, sec_last.
  output logic        frame_cmd_valid_o,
  input  logic        frame_cmd_ready_i,
  output logic [7*$clog2(MaxDim)+50:0] frame_cmd_data_o,
  /// cube5_axi_wr's command: addr, len (pixels).
  output logic        wr_cmd_valid_o,
  input  logic        wr_cmd_ready_i,
  output logic [AddrW+LenW-1:0] wr_cmd_data_o,
  // ---- events (taken every cycle) ----
  /// The frame finished its read-out (`frame_done_error_i`: it stopped on an error).
  input  logic        frame_done_valid_i,
  input  logic        frame_done_error_i,
  /// The writer completed a row (cube5_axi_wr's completion, `resp`).
  input  logic        wr_cpl_valid_i,
  input  logic [1:0]  wr_cpl_resp_i,
  // ---- soft reset: drain the data path ----
  /// After Ctrl.soft_reset: the data path is to stop its AXI4 transactions and reset its units.
  output logic        flush_o,
  /// The data path is quiet and its units reset in this cycle: the frame ends (Aborted); every
  /// command still offered is withdrawn.
  input  logic        drained_i,
  // ---- table port (one write per TableData write) ----
  output logic        table_valid_o,
  output logic [3:0]  table_id_o,
  output logic [15:0] table_index_o,
  output logic [31:0] table_data_o,
  // ---- the frame's set-up for the top's window writes (held from the checks to the next start) ----
  /// ImgBase, the bytes from row to row (ImgPitch, or the packed pitch), ParkBase, and the
  /// pixels of a row as written (W rounded up to P).
  output logic [AddrW-1:0] img_base_o,
  output logic [AddrW-1:0] row_step_o,
  output logic [AddrW-1:0] park_base_o,
  output logic [$clog2(MaxDim)+1:0] row_pixels_o
);

  localparam int unsigned AxilWords = cube5_accel_regs_pkg::AxilWords;
  localparam int unsigned RegCtrl = cube5_accel_regs_pkg::RegCtrl;
  localparam int unsigned RegStatus = cube5_accel_regs_pkg::RegStatus;
  localparam int unsigned RegIrqStatus = cube5_accel_regs_pkg::RegIrqStatus;
  localparam int unsigned RegDims = cube5_accel_regs_pkg::RegDims;
  localparam int unsigned RegView = cube5_accel_regs_pkg::RegView;
  localparam int unsigned RegDx = cube5_accel_regs_pkg::RegDx;
  localparam int unsigned RegDy = cube5_accel_regs_pkg::RegDy;
  localparam int unsigned RegMode = cube5_accel_regs_pkg::RegMode;
  localparam int unsigned RegSkip = cube5_accel_regs_pkg::RegSkip;
  localparam int unsigned RegVolBaseLo = cube5_accel_regs_pkg::RegVolBaseLo;
  localparam int unsigned RegVolBaseHi = cube5_accel_regs_pkg::RegVolBaseHi;
  localparam int unsigned RegImgBaseLo = cube5_accel_regs_pkg::RegImgBaseLo;
  localparam int unsigned RegImgBaseHi = cube5_accel_regs_pkg::RegImgBaseHi;
  localparam int unsigned RegImgPitch = cube5_accel_regs_pkg::RegImgPitch;
  localparam int unsigned RegParkBaseLo = cube5_accel_regs_pkg::RegParkBaseLo;
  localparam int unsigned RegParkBaseHi = cube5_accel_regs_pkg::RegParkBaseHi;
  localparam int unsigned RegCycleLo = cube5_accel_regs_pkg::RegCycleLo;
  localparam int unsigned RegCycleHi = cube5_accel_regs_pkg::RegCycleHi;
  localparam int unsigned RegSampleLo = cube5_accel_regs_pkg::RegSampleLo;
  localparam int unsigned RegSampleHi = cube5_accel_regs_pkg::RegSampleHi;
  localparam int unsigned RegTableAddr = cube5_accel_regs_pkg::RegTableAddr;
  localparam int unsigned RegTableData = cube5_accel_regs_pkg::RegTableData;
  localparam int unsigned RegTablePos = cube5_accel_regs_pkg::RegTablePos;

  localparam int unsigned M = $clog2(MaxDim);
  localparam int unsigned M1 = M + 1;
  localparam int unsigned NbW = $clog2(MaxDim / BlockDim);
  localparam int unsigned LogB = $clog2(BlockDim);
  localparam int unsigned LogS = $clog2(Section);
  localparam int unsigned LogP = $clog2(P);
  localparam int unsigned LogPix = $clog2(PixelBytes);
  localparam int unsigned Words = AxilWords;
  localparam int unsigned StepW = 16;
  localparam int unsigned VolMask = DataW / 8 - 1;
  /// Row alignment: the image writer's item, P pixels or a bus beat if that is narrower.
  localparam int unsigned RowAlign = (P * PixelBytes < DataW / 8) ? P * PixelBytes : DataW / 8;
  localparam int unsigned ImgMask = RowAlign - 1;
  /// Rows of the base plane fit M + 1 bits (H < 2 MaxDim); counters get one more.
  localparam int unsigned RowW = M + 2;

`ifndef SYNTHESIS
  initial begin
    if (P != 1 && P != 2 && P != 4 && P != 8) $fatal(1, "cube5_accel_ctrl: P = %0d is not 1, 2, 4 or 8", P);
    if (MaxDim < 8 || MaxDim > 1024 || (MaxDim & (MaxDim - 1)) != 0)
      $fatal(1, "cube5_accel_ctrl: MaxDim = %0d is not a power of two in 8..1024", MaxDim);
    if ((BlockDim & (BlockDim - 1)) != 0 || BlockDim < P || BlockDim < 2 || BlockDim > 16 || BlockDim >= MaxDim)
      $fatal(1, "cube5_accel_ctrl: BlockDim = %0d is not a power of two with max(2, P) <= B <= 16, B < MaxDim", BlockDim);
    if ((Section & (Section - 1)) != 0 || Section < BlockDim || Section >= MaxDim)
      $fatal(1, "cube5_accel_ctrl: Section = %0d is not a power of two with BlockDim <= S < MaxDim", Section);
    if (AddrW < 13 || AddrW > 64) $fatal(1, "cube5_accel_ctrl: AddrW = %0d outside 13..64", AddrW);
    if ((DataW & (DataW - 1)) != 0 || DataW < 16 * P || DataW > 16 * BlockDim * BlockDim * BlockDim)
      $fatal(1, "cube5_accel_ctrl: DataW = %0d is not a power of two in 16 P .. 16 B^3", DataW);
    if ((PixelBytes & (PixelBytes - 1)) != 0 || PixelBytes < 1 || PixelBytes > 128)
      $fatal(1, "cube5_accel_ctrl: PixelBytes = %0d is not a power of two up to 128", PixelBytes);
    if (LenW < M + 2 || LenW > 32) $fatal(1, "cube5_accel_ctrl: LenW = %0d outside m + 2 .. 32", LenW);
  end
`endif

  // ---------------------------------------------------------------------------------------------
  // The register block
  // ---------------------------------------------------------------------------------------------

  logic [Words*32-1:0] reg_q, ro, set;
  logic [Words-1:0]    wr_stb, rd_stb;

  cube5_axil_regs #(
    .Words    (Words),
    .AddrW    (10),
    .Stored   (cube5_accel_regs_pkg::AxilStored),
    .Readable (cube5_accel_regs_pkg::AxilReadable),
    .Ro       (cube5_accel_regs_pkg::AxilRo),
    .W1c      (cube5_accel_regs_pkg::AxilW1c),
    .HasReset (cube5_accel_regs_pkg::AxilHasReset),
    .Mask     (cube5_accel_regs_pkg::AxilMask),
    .Reset    (cube5_accel_regs_pkg::AxilReset),
    .HasIrq   (cube5_accel_regs_pkg::AxilHasIrq),
    .IrqStatus(cube5_accel_regs_pkg::AxilIrqStatus),
    .IrqEnable(cube5_accel_regs_pkg::AxilIrqEnable)
  ) u_regs (
    .clk_i            (clk_i),
    .rst_ni           (rst_ni),
    .s_axil_awvalid_i (s_axil_awvalid_i),
    .s_axil_awready_o (s_axil_awready_o),
    .s_axil_awaddr_i  (s_axil_awaddr_i),
    .s_axil_awprot_i  (3'b000),
    .s_axil_wvalid_i  (s_axil_wvalid_i),
    .s_axil_wready_o  (s_axil_wready_o),
    .s_axil_wdata_i   (s_axil_wdata_i),
    .s_axil_wstrb_i   (s_axil_wstrb_i),
    .s_axil_bvalid_o  (s_axil_bvalid_o),
    .s_axil_bready_i  (s_axil_bready_i),
    .s_axil_bresp_o   (s_axil_bresp_o),
    .s_axil_arvalid_i (s_axil_arvalid_i),
    .s_axil_arready_o (s_axil_arready_o),
    .s_axil_araddr_i  (s_axil_araddr_i),
    .s_axil_arprot_i  (3'b000),
    .s_axil_rvalid_o  (s_axil_rvalid_o),
    .s_axil_rready_i  (s_axil_rready_i),
    .s_axil_rdata_o   (s_axil_rdata_o),
    .s_axil_rresp_o   (s_axil_rresp_o),
    .reg_q_o          (reg_q),
    .ro_i             (ro),
    .w1c_set_i        (set),
    .wr_stb_o         (wr_stb),
    .rd_stb_o         (rd_stb),
    .irq_o            (irq_o)
  );

  function automatic logic [31:0] word(logic [Words*32-1:0] v, int unsigned i);
    word = v[i*32 +: 32];
  endfunction

  typedef enum logic [2:0] {StIdle, StAxes, StSetup, StPlane, StSize, StCheck, StRun} state_e;
  state_e state_q, state_d;

  logic start_stb, abort_stb;
  assign start_stb = wr_stb[RegCtrl] & reg_q[RegCtrl*32 + 0];
  assign abort_stb = wr_stb[RegCtrl] & reg_q[RegCtrl*32 + 1];

  // ---------------------------------------------------------------------------------------------
  // Latched frame registers (at the start strobe)
  // ---------------------------------------------------------------------------------------------

  logic [M:0]       nx_q, ny_q, nz_q, front_q, back_q;
  logic [1:0]       axis_q;
  logic             rev_q;
  logic [17:0]      dx_q, dy_q;
  logic [3:0]       mode_q;           // Mode: render (3), tf2d (1)
  logic [AddrW-1:0] vbase_q, ibase_q, pbase_q;
  logic [31:0]      pitch_q;
  logic [63:0]      vbase_w, ibase_w, pbase_w;

  assign vbase_w = {word(reg_q, RegVolBaseHi), word(reg_q, RegVolBaseLo)};
  assign ibase_w = {word(reg_q, RegImgBaseHi), word(reg_q, RegImgBaseLo)};
  assign pbase_w = {word(reg_q, RegParkBaseHi), word(reg_q, RegParkBaseLo)};

  always_ff @(posedge clk_i) begin
    if (start_stb && state_q == StIdle) begin
      nx_q    <= reg_q[RegDims*32 + 0*M1 +: M1];
      ny_q    <= reg_q[RegDims*32 + 1*M1 +: M1];
      nz_q    <= reg_q[RegDims*32 + 2*M1 +: M1];
      axis_q  <= reg_q[RegView*32 +: 2];
      rev_q   <= reg_q[RegView*32 + 2];
      dx_q    <= reg_q[RegDx*32 +: 18];
      dy_q    <= reg_q[RegDy*32 +: 18];
      mode_q  <= reg_q[RegMode*32 +: 4];
      front_q <= reg_q[RegSkip*32 + 0*M1 +: M1];
      back_q  <= reg_q[RegSkip*32 + 1*M1 +: M1];
      vbase_q <= vbase_w[AddrW-1:0];
      ibase_q <= ibase_w[AddrW-1:0];
      pbase_q <= pbase_w[AddrW-1:0];
      pitch_q <= word(reg_q, RegImgPitch);
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Checks and set-up arithmetic (the Check cycle)
  // ---------------------------------------------------------------------------------------------

  logic [M:0]  ni, nj, nk;
  logic [3:0]  code;
  logic signed [M+19:0] tx, ty;           // (nk - 1) DX, (nk - 1) DY
  logic signed [M+3:0]  sx, sy;           // shifts of the last slice
  logic [M:0]  wpix, hpix;                // base-plane size
  logic [2*M+1:0] ninj, ni_nj1;
  logic [3*M+2:0] samples;
  logic [M:0]  swept, nj_m1;
  logic [M:0]  nsec;
  logic [NbW:0] nbx, nby, nbz, nbi;
  logic        dx_neg;

  function automatic logic [NbW:0] blocks(logic [M:0] n);
    logic [M:0] t;
    t = n + M1'(BlockDim - 1);
    blocks = (NbW + 1)'(t >> LogB);
  endfunction

  function automatic logic bad_dim(logic [M:0] n);
    bad_dim = (n < M1'(P)) || (n > M1'(MaxDim)) || ((n & M1'(P - 1)) != '0);
  endfunction

  function automatic logic bad_step(logic [17:0] d);
    logic [17:0] a;
    a = d[17] ? (~d + 18'd1) : d;
    bad_step = a > 18'h10000;
  endfunction

  function automatic logic [M+3:0] abs_shift(logic signed [M+3:0] s);
    abs_shift = (s < 0) ? -s : s;
  endfunction

  // Stage 1 (the Axes cycle, t0 + 1): the frame axes and the checks that need no product.
  logic [3:0] code_a;
  logic [M:0] nk_m1_q, nj_m1_q;
  always_comb begin
    unique case (axis_q)
      2'd0:    begin ni = ny_q; nj = nz_q; nk = nx_q; end
      2'd1:    begin ni = nx_q; nj = nz_q; nk = ny_q; end
      default: begin ni = nx_q; nj = ny_q; nk = nz_q; end
    endcase
    nj_m1 = nj - M1'(1);
    swept = nk - front_q - back_q;
    nsec = (ni + M1'(Section - 1)) >> LogS;
    nbx = blocks(nx_q);
    nby = blocks(ny_q);
    nbz = blocks(nz_q);
    unique case (axis_q)
      2'd0:    nbi = nby;
      default: nbi = nbx;
    endcase
    dx_neg = dx_q[17];
    // Refusals, the first that applies (docs/numerics/accel_ctrl.md, "Refused frames").
    if (axis_q == 2'd3) code_a = cube5_accel_regs_pkg::CodeAxisK;
    else if (bad_dim(nx_q) || bad_dim(ny_q) || bad_dim(nz_q)) code_a = cube5_accel_regs_pkg::CodeDims;
    else if (mode_q[2:0] >= 3'd5) code_a = cube5_accel_regs_pkg::CodeRender;
    else if (bad_step(dx_q) || bad_step(dy_q)) code_a = cube5_accel_regs_pkg::CodeStep;
    else if ({1'b0, front_q} + {1'b0, back_q} >= {1'b0, nk}) code_a = cube5_accel_regs_pkg::CodeSkip;
    else code_a = cube5_accel_regs_pkg::CodeNone;
  end

  // Stage 1.5 (the Setup cycle, t0 + 2): the products, from stage 1's registers.
  always_comb begin
    tx = $signed({1'b0, nk_m1_q}) * $signed(dx_q);
    ty = $signed({1'b0, nk_m1_q}) * $signed(dy_q);
    sx = tx[M+19:StepW];
    sy = ty[M+19:StepW];
    ninj = (2*M+2)'(ni_q) * (2*M+2)'(nj_q);
    ni_nj1 = (2*M+2)'(ni_q) * (2*M+2)'(nj_m1_q);
  end

  // Stage 1's and 1.5's results (datapath registers).
  logic [M:0]         ni_q, nj_q, nk_q, nsec_q, swept_q;
  logic [NbW:0]       nbx_q, nby_q, nbz_q, nbi_q;
  logic               neg_q;
  logic signed [M+3:0] sx_q, sy_q;
  logic [2*M+1:0]     ninj_q, ni_nj1_q;
  logic [3:0]         code_a_q;

  // Stage 1.75 (the Plane cycle, t0 + 3): the base plane's size and the samples, from stage
  // 1.5's registers (for clock rate: the shift's absolute value and the sum end in a register
  // before the row's rounding and bytes; the product alone in its stage).
  logic [M:0]     wpix_q, hpix_q;
  logic [3*M+2:0] samples_q;
  always_comb begin
    wpix    = ni_q + M1'(abs_shift(sx_q));
    hpix    = nj_q + M1'(abs_shift(sy_q));
    samples = (3*M+3)'(ninj_q) * (3*M+3)'(swept_q);
  end

  // Stage 2 (the Size cycle, t0 + 4): a row's pixels and bytes, the rules that need the products,
  // but for the pitch against a row's bytes (code_b).
  // A row as written: W rounded up to P pixels (the frame's read-out items), its bytes (the
  // pitch when ImgPitch is 0; a multiple of the row alignment, which divides P PixelBytes).
  localparam int unsigned RowBW = M + LogPix + 2;
  logic [M+1:0]     wpad;
  logic [RowBW-1:0] row_bytes;
  logic [3:0]       code_b;
  always_comb begin
    wpad = ((M+2)'(wpix_q) + (M+2)'(P - 1)) >> LogP << LogP;
    row_bytes = RowBW'(wpad) << LogPix;
    if (code_a_q != cube5_accel_regs_pkg::CodeNone) code_b = code_a_q;
    else if (ni_q < M1'(2 * P) || (ni_nj1_q >> LogP) < (2*M+2)'(9)) code_b = cube5_accel_regs_pkg::CodeSmall;
    else if ((vbase_q & AddrW'(VolMask)) != '0) code_b = cube5_accel_regs_pkg::CodeVolAlign;
    else if ((ibase_q & AddrW'(ImgMask)) != '0) code_b = cube5_accel_regs_pkg::CodeImgAlign;
    else if ((pitch_q & 32'(ImgMask)) != '0) code_b = cube5_accel_regs_pkg::CodePitch;
    else code_b = cube5_accel_regs_pkg::CodeNone;
  end

  // Stage 2's results: the row command's pixels and rows, the row step, a row's bytes and the
  // codes so far (the samples, stage 1.75's, are held from there to the next start).
  logic [M:0]       h_q;
  logic [M+1:0]     w_q;           // pixels per row command: W rounded up to P
  logic [AddrW-1:0] row_step_q;
  logic [RowBW-1:0] row_bytes_q;
  logic [3:0]       code_b_q;

  // Stage 3 (the Check cycle, t0 + 5): a nonzero pitch below a row's bytes, the verdict.
  always_comb begin
    if (code_b_q != cube5_accel_regs_pkg::CodeNone) code = code_b_q;
    else if (pitch_q != '0 && pitch_q < 32'(row_bytes_q)) code = cube5_accel_regs_pkg::CodePitch;
    else code = cube5_accel_regs_pkg::CodeNone;
  end

  // ---------------------------------------------------------------------------------------------
  // Sequencer
  // ---------------------------------------------------------------------------------------------


  logic [M:0]       fidx_q, fidx_d, sidx_q, sidx_d, gidx_q, gidx_d;
  logic [RowW-1:0]  row_q, row_d, cpl_q, cpl_d;
  logic [AddrW-1:0] waddr_q, waddr_d;
  logic             fdone_q, fdone_d, ferr_q, ferr_d, werr_q, werr_d, abort_q, abort_d;
  logic             fhold_q, shold_q, ghold_q, whold_q;
  logic             done_q, done_d, err_q, err_d;
  logic [3:0]       code_q, code_d;
  logic [63:0]      cyc_q, cyc_d, samp_q, samp_d;
  logic [31:0]      cyc_hi_q, samp_hi_q;
  logic [19:0]      tpos_q, tpos_d;
  logic             set_done, set_err, finish, run;

  logic fetch_fire, sbuf_fire, frame_fire, wr_fire;
  assign fetch_fire = fetch_cmd_valid_o & fetch_cmd_ready_i;
  assign sbuf_fire  = sbuf_cmd_valid_o & sbuf_cmd_ready_i;
  assign frame_fire = frame_cmd_valid_o & frame_cmd_ready_i;
  assign wr_fire    = wr_cmd_valid_o & wr_cmd_ready_i;

  assign run = state_q == StRun;
  assign flush_o = run && abort_q;
  // A port offers its next command while the frame runs; after an abort only the one it holds.
  assign fetch_cmd_valid_o = run && fidx_q < nsec_q && (!abort_q || fhold_q);
  assign sbuf_cmd_valid_o  = run && sidx_q < nsec_q && (!abort_q || shold_q);
  assign frame_cmd_valid_o = run && gidx_q < nsec_q && (!abort_q || ghold_q);
  assign wr_cmd_valid_o    = run && (Window != 0 || gidx_q == nsec_q) && row_q < RowW'(h_q) && (!abort_q || whold_q);

  always_comb begin
    state_d  = state_q;
    fidx_d   = fidx_q + M1'(fetch_fire);
    sidx_d   = sidx_q + M1'(sbuf_fire);
    gidx_d   = gidx_q + M1'(frame_fire);
    row_d    = row_q + RowW'(wr_fire);
    waddr_d  = wr_fire ? waddr_q + row_step_q : waddr_q;
    cpl_d    = cpl_q;
    fdone_d  = fdone_q;
    ferr_d   = ferr_q;
    werr_d   = werr_q;
    abort_d  = abort_q;
    done_d   = done_q;
    err_d    = err_q;
    code_d   = code_q;
    cyc_d    = (state_q != StIdle) ? cyc_q + 64'd1 : cyc_q;
    samp_d   = samp_q;
    set_done = 1'b0;
    set_err  = 1'b0;
    finish   = 1'b0;
    if (abort_stb && state_q != StIdle) abort_d = 1'b1;
    if (run) begin
      if (frame_done_valid_i) begin
        fdone_d = 1'b1;
        ferr_d  = ferr_q | frame_done_error_i;
      end
      if (wr_cpl_valid_i) begin
        cpl_d  = cpl_q + RowW'(1);
        werr_d = werr_q | (wr_cpl_resp_i != 2'b00);
      end
      if (abort_q) begin
        finish = drained_i;
      end else begin
        finish = fidx_q == nsec_q && sidx_q == nsec_q && gidx_q == nsec_q
                 && row_q == RowW'(h_q) && cpl_q == RowW'(h_q) && fdone_q;
      end
    end
    unique case (state_q)
      StIdle: begin
        if (start_stb) begin
          state_d = StAxes;
          cyc_d   = 64'd0;
          samp_d  = 64'd0;
          done_d  = 1'b0;
          err_d   = 1'b0;
          code_d  = cube5_accel_regs_pkg::CodeNone;
          abort_d = 1'b0;
        end
      end
      StAxes:  state_d = StSetup;
      StSetup: state_d = StPlane;
      StPlane: state_d = StSize;
      StSize:  state_d = StCheck;
      StCheck: begin
        fidx_d  = '0;
        sidx_d  = '0;
        gidx_d  = '0;
        row_d   = '0;
        cpl_d   = '0;
        waddr_d = ibase_q;
        fdone_d = 1'b0;
        ferr_d  = 1'b0;
        werr_d  = 1'b0;
        if (code != cube5_accel_regs_pkg::CodeNone) begin
          state_d = StIdle;
          set_err = 1'b1;
          err_d   = 1'b1;
          code_d  = code;
        end else begin
          state_d = StRun;
          samp_d  = 64'(samples_q);
        end
      end
      StRun: begin
        if (finish) begin
          state_d = StIdle;
          if (abort_q) code_d = cube5_accel_regs_pkg::CodeAborted;
          else if (ferr_q) code_d = cube5_accel_regs_pkg::CodeFrame;
          else if (werr_q) code_d = cube5_accel_regs_pkg::CodeWrite;
          else code_d = cube5_accel_regs_pkg::CodeNone;
          err_d    = abort_q | ferr_q | werr_q;
          done_d   = !(abort_q | ferr_q | werr_q);
          set_err  = err_d;
          set_done = done_d;
        end
      end
      default: state_d = StIdle;
    endcase
    // The table window.
    tpos_d = tpos_q;
    if (wr_stb[RegTableAddr]) tpos_d = reg_q[RegTableAddr*32 +: 20];
    else if (wr_stb[RegTableData]) tpos_d = {tpos_q[19:16], tpos_q[15:0] + 16'd1};
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      state_q   <= StIdle;
      fidx_q    <= '0;
      sidx_q    <= '0;
      gidx_q    <= '0;
      row_q     <= '0;
      cpl_q     <= '0;
      fdone_q   <= 1'b0;
      ferr_q    <= 1'b0;
      werr_q    <= 1'b0;
      abort_q   <= 1'b0;
      fhold_q   <= 1'b0;
      shold_q   <= 1'b0;
      ghold_q   <= 1'b0;
      whold_q   <= 1'b0;
      done_q    <= 1'b0;
      err_q     <= 1'b0;
      code_q    <= '0;
      cyc_q     <= '0;
      samp_q    <= '0;
      cyc_hi_q  <= '0;
      samp_hi_q <= '0;
      tpos_q    <= '0;
    end else begin
      state_q   <= state_d;
      fidx_q    <= fidx_d;
      sidx_q    <= sidx_d;
      gidx_q    <= gidx_d;
      row_q     <= row_d;
      cpl_q     <= cpl_d;
      fdone_q   <= fdone_d;
      ferr_q    <= ferr_d;
      werr_q    <= werr_d;
      abort_q   <= abort_d;
      fhold_q   <= fetch_cmd_valid_o & ~fetch_cmd_ready_i;
      shold_q   <= sbuf_cmd_valid_o & ~sbuf_cmd_ready_i;
      ghold_q   <= frame_cmd_valid_o & ~frame_cmd_ready_i;
      whold_q   <= wr_cmd_valid_o & ~wr_cmd_ready_i;
      done_q    <= done_d;
      err_q     <= err_d;
      code_q    <= code_d;
      cyc_q     <= cyc_d;
      samp_q    <= samp_d;
      cyc_hi_q  <= rd_stb[RegCycleLo] ? cyc_q[63:32] : cyc_hi_q;
      samp_hi_q <= rd_stb[RegSampleLo] ? samp_q[63:32] : samp_hi_q;
      tpos_q    <= tpos_d;
    end
  end

  // Datapath registers (no reset): the set-up results and the row address.
  always_ff @(posedge clk_i) begin
    if (state_q == StAxes) begin
      ni_q     <= ni;
      nj_q     <= nj;
      nk_q     <= nk;
      nk_m1_q  <= nk - M1'(1);
      nj_m1_q  <= nj_m1;
      nsec_q   <= nsec;
      swept_q  <= swept;
      nbx_q    <= nbx;
      nby_q    <= nby;
      nbz_q    <= nbz;
      nbi_q    <= nbi;
      neg_q    <= dx_neg;
      code_a_q <= code_a;
    end
    if (state_q == StSetup) begin
      sx_q     <= sx;
      sy_q     <= sy;
      ninj_q   <= ninj;
      ni_nj1_q <= ni_nj1;
    end
    if (state_q == StPlane) begin
      wpix_q    <= wpix;
      hpix_q    <= hpix;
      samples_q <= samples;
    end
    if (state_q == StSize) begin
      w_q         <= wpad;
      h_q         <= hpix_q;
      row_step_q  <= (pitch_q != '0) ? AddrW'(pitch_q) : AddrW'(row_bytes);
      row_bytes_q <= row_bytes;
      code_b_q    <= code_b;
    end
    waddr_q <= waddr_d;
  end

  // ---------------------------------------------------------------------------------------------
  // Command payloads: each port's from its own section index
  // ---------------------------------------------------------------------------------------------

  // The anchor of the n-th section in issue order.
  function automatic logic [M:0] anchor(logic [M:0] n);
    logic [M:0] idx;
    idx = neg_q ? (nsec_q - M1'(1) - n) : n;
    anchor = idx << LogS;
  endfunction

  logic [M:0]   f_a0, s_a0, g_a0, g_ns, g_rest, a0_end;
  logic [NbW:0] sec_hi_raw, sec_hi;
  logic [M:0]   sec_lo_w;

  always_comb begin
    f_a0 = anchor(fidx_q);
    s_a0 = anchor(sidx_q);
    g_a0 = anchor(gidx_q);
    // Sweep::with_anchor_section(B, A0, S): [(A0 - 1) div B, min((A0 + S) div B + 1, nb_i)).
    sec_lo_w   = (f_a0 == '0) ? '0 : ((f_a0 - M1'(1)) >> LogB);
    a0_end     = f_a0 + M1'(Section);
    sec_hi_raw = a0_end[LogB +: NbW + 1] + (NbW + 1)'(1);
    sec_hi     = (sec_hi_raw < nbi_q) ? sec_hi_raw : nbi_q;
    g_rest     = ni_q - g_a0;
    g_ns       = (g_rest < M1'(Section)) ? g_rest : M1'(Section);
  end

  assign fetch_cmd_data_o = {sec_hi, sec_lo_w[NbW-1:0], rev_q, axis_q, nbz_q, nby_q, nbx_q, vbase_q};
  assign sbuf_cmd_data_o  = {s_a0[M-1:0], nk_q, nj_q, ni_q, rev_q, axis_q};
  assign frame_cmd_data_o = {gidx_q == nsec_q - M1'(1), gidx_q == '0, g_ns, g_a0[M-1:0],
                             back_q, front_q, mode_q, dy_q, dx_q, rev_q, axis_q, nz_q, ny_q, nx_q};
  assign wr_cmd_data_o    = {LenW'(w_q), waddr_q};
  assign img_base_o       = ibase_q;
  assign row_step_o       = row_step_q;
  assign park_base_o      = pbase_q;
  assign row_pixels_o     = w_q;

  // ---------------------------------------------------------------------------------------------
  // Status, counters, interrupt, table port
  // ---------------------------------------------------------------------------------------------

  always_comb begin
    ro  = '0;
    set = '0;
    ro[RegStatus*32 +: 8]    = {code_q, 1'b0, err_q, done_q, state_q != StIdle};
    ro[RegCycleLo*32 +: 32]  = cyc_q[31:0];
    ro[RegCycleHi*32 +: 32]  = cyc_hi_q;
    ro[RegSampleLo*32 +: 32] = samp_q[31:0];
    ro[RegSampleHi*32 +: 32] = samp_hi_q;
    ro[RegTablePos*32 +: 20] = tpos_q;
    set[RegIrqStatus*32 +: 2] = {set_err, set_done};
  end

  assign table_valid_o = wr_stb[RegTableData];
  assign table_id_o    = tpos_q[19:16];
  assign table_index_o = tpos_q[15:0];
  assign table_data_o  = word(reg_q, RegTableData);

  logic unused;
  assign unused = ^{reg_q, rd_stb, wr_stb, nk_q, vbase_w, ibase_w, pbase_w, sec_lo_w, a0_end, tx, ty, ninj, s_a0};

`ifndef SYNTHESIS
  // A stalled command holds its valid and payload (until the drain of a soft reset ends).
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      fetch_cmd_valid_o && !fetch_cmd_ready_i && !(flush_o && drained_i) |=> fetch_cmd_valid_o && $stable(fetch_cmd_data_o))
    else $error("cube5_accel_ctrl: fetch command changed while stalled");
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      sbuf_cmd_valid_o && !sbuf_cmd_ready_i && !(flush_o && drained_i) |=> sbuf_cmd_valid_o && $stable(sbuf_cmd_data_o))
    else $error("cube5_accel_ctrl: section-buffer command changed while stalled");
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      frame_cmd_valid_o && !frame_cmd_ready_i && !(flush_o && drained_i) |=> frame_cmd_valid_o && $stable(frame_cmd_data_o))
    else $error("cube5_accel_ctrl: frame command changed while stalled");
  assert property (@(posedge clk_i) disable iff (!rst_ni)
      wr_cmd_valid_o && !wr_cmd_ready_i && !(flush_o && drained_i) |=> wr_cmd_valid_o && $stable(wr_cmd_data_o))
    else $error("cube5_accel_ctrl: write command changed while stalled");
`endif

endmodule
