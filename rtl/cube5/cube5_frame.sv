// cube5_frame: the Cube-5 slice-order rendering machine (patent [37]-[51], [165], [240];
// cube3-paper §2, §5; docs/numerics/frame.md, docs/frame-rtl.md).
//
// A `render` command sweeps the volume held in the skewed memory (cube5_skewmem) slice by slice,
// front to back, one beam of P voxels per clock, for the base plane and step (DX, DY) in the frame
// registers. P pipelines each interpolate three samples per anchor (cube5_trilin: slices s-1, s, s+1
// at slice s's weights), take the gradient on the orthogonal neighbourhood (cube5_gradient, N6),
// shade (cube5_shader) and composite (cube5_compos) into the coxel of the sample's ray in the
// compositing buffer (banked by ray mod P, rotated by the slice's shift). After the sweep the
// base-plane image leaves as W x H coxels, q outer, r inner, one per output item. Every output item
// also carries an error flag and two counters of the frame: memory beats read and sweep cycles.
//
// The volume, the frame registers and every table are written through the configuration port
// (address map: docs/numerics/frame.md, "RTL configuration map"); writes that arrive while a frame
// is being swept are ignored.
//
// Source = 1 (issue 12, the accelerator; docs/numerics/frame.md, "Sections"): no skewed memory and
// no voxel or block LUT region. The input stream carries commands and beats (a kind bit first): a
// render command names a section [sec_a0, sec_a0 + sec_ns) of the face's i axis, and the section's
// beams follow as cube5_section_buf hands them over (slice, row, beat order; lo beside a row's first
// beat, hi0 and hi1 beside its last). The windows take rows of sec_ns / P beats; the compositing
// buffer keeps the whole base plane from the first section of a frame (sec_first) to the read-out
// after its last (sec_last). Beats may come with gaps: every stage advances per beat.
module cube5_frame #(
  /// Pipelines = memory modules = voxels per beat: 1, 2, 4 or 8.
  parameter int unsigned P          = 4,
  /// Largest volume edge, a power of two (the skewed memory holds MaxDim^3 voxels).
  parameter int unsigned MaxDim     = 64,
  /// Voxel, interpolation weight and sample fraction widths (cube5_trilin).
  parameter int unsigned VoxelW     = 12,
  parameter int unsigned WeightW    = 8,
  parameter int unsigned FracW      = 4,
  /// Skewed memory: block edge of the block LUT and module read latency (cube5_skewmem).
  parameter int unsigned BlockDim   = 8,
  parameter int unsigned MemLatency = 1,
  /// Shader (cube5_shader).
  parameter int unsigned ClassIdxW  = 12,
  parameter int unsigned MagIdxW    = 4,
  parameter int unsigned MagShift   = 10,
  parameter int unsigned ColorW     = 8,
  parameter int unsigned AlphaW     = 12,
  parameter int unsigned RmLog2     = 3,
  parameter int unsigned RmFracW    = 4,
  parameter int unsigned DiffW      = 9,
  parameter int unsigned SpecW      = 8,
  /// Compositing (cube5_compos).
  parameter int unsigned ExtraW     = 4,
  parameter int unsigned AccW       = 20,
  parameter int unsigned ZW         = 12,
  /// Units of the pipelines: 1 gradient and shader (every mode); 0 neither, for the unlit modes
  /// only (MIP, MinIP, X-ray): each pipeline classifies its sample with the shader's 1-D table
  /// alone (cube5_frame_class; docs/numerics/frame.md, "A frame without gradient and shader").
  parameter int unsigned Shade      = 1,
  /// Where the beams come from: 0 the skewed memory inside (cube5_skewmem, loaded through the
  /// configuration port); 1 the input stream, a section at a time (above).
  parameter int unsigned Source     = 0,
  /// The depth test against opaque geometry ([62], [217]-[218]; docs/numerics/frame.md, "Opaque
  /// geometry"): 1 keeps a per-pixel RGBA-Z table (configuration region 5) beside the compositing
  /// buffer, every ray starts from its pixel's Z and colour, and the read-out flushes the geometry
  /// colour under each ray through one more cube5_compos (mode Flush). 0: none of it.
  parameter int unsigned DepthTest  = 0,
  /// Pixels per output item: 1, or P (DepthTest = 0 only): the read-out takes the P banks' words
  /// at one address, P consecutive pixels of a row per cycle, H ceil(W / P) items in all
  /// (docs/frame-rtl.md, "The read-out").
  parameter int unsigned OutLanes   = 1,
  /// Source = 1: the widest section the frame takes (sec_ns <= MaxSection, else refused), a
  /// multiple of P in 2 P ..= MaxDim; the slice FIFOs hold MaxSection MaxDim / P beats instead of
  /// MaxDim^2 / P (docs/frame-rtl.md, "Fed by a beat stream"). Source = 0: MaxDim.
  parameter int unsigned MaxSection = MaxDim,
  /// 1 (Source = 1 only): the compositing window (docs/numerics/compos_window.md, *RTL*): the
  /// buffer keeps the coxels of the section's active rays only ((MaxDim x WinCols) words per bank,
  /// WinCols = MaxSection / P rounded up to a power of two); pixels leaving it go out on the park
  /// stream (a later section samples them) or the final stream (the image's pixels), parked ones
  /// come back on the restore streams; no read-out (the output stream carries error items only).
  /// 0: the whole base plane in the buffer, the read-out after the last section.
  parameter int unsigned Window     = 0,
  /// Window = 1: the window's descriptor FIFO depth (cube5_frame_win DescDepth, a power of two):
  /// 32 admits at most 0.94 beats per clock, 64 one (docs/accel.md, *Throughput against memory
  /// bandwidth*).
  parameter int unsigned WinDescDepth = 32
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Command valid.
  input  logic in_valid_i,
  /// The frame takes a command (idle, buffer cleared).
  output logic in_ready_o,
  /// Source = 0: op (2): 0 render; 1..3 reserved (answered by one error item). Source = 1: kind
  /// (1), then a command {op (2), sec_a0 (m), sec_ns (m + 1), sec_first, sec_last} or a beat
  /// {P lanes, lo, hi0, hi1 (VoxelW each), row_first, row_last, slice_last, last, error}.
  input  logic [cube5_frame_pkg::in_w(Source, P, VoxelW, $clog2(MaxDim))-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item.
  input  logic out_ready_i,
  /// OutLanes coxels (compos packing; lane k is pixel R + k of the item's row, lanes past the
  /// row's end carry the empty coxel), error (1), beats read (32), sweep cycles (32); LSB first.
  output logic [cube5_frame_pkg::out_lanes_w(OutLanes, AccW, ZW, ColorW)-1:0] out_data_o,

  /// Configuration write (frame registers, voxels, block LUT, shader and compositing tables).
  input  logic cfg_valid_i,
  input  logic [cube5_frame_pkg::CfgRegionW + cube5_frame_pkg::cfg_off_w(
                  $clog2(MaxDim), cube5_skewmem_pkg::blk_w($clog2(MaxDim), BlockDim),
                  cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2), AlphaW)-1:0] cfg_addr_i,
  input  logic [cube5_frame_pkg::cfg_data_w(
                  $clog2(MaxDim), VoxelW, cube5_skewmem_pkg::blk_w($clog2(MaxDim), BlockDim),
                  cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW), AccW)-1:0] cfg_data_i,

  /// Window = 1 (else idle: valid low, ready high): parked coxels, key {Q, R} (R low, DimW bits
  /// each) and the stored coxel {terminated, A, B, G, R}.
  output logic park_valid_o,
  input  logic park_ready_i,
  output logic [2*($clog2(MaxDim)+1)-1:0] park_key_o,
  output logic [4*(AccW+1):0] park_cox_o,
  /// Final pixels: key {Q, R} of lane 0, the lanes that are final (lane k is pixel (R + k, Q)),
  /// the lanes' stored coxels.
  output logic fin_valid_o,
  input  logic fin_ready_i,
  output logic [2*($clog2(MaxDim)+1)-1:0] fin_key_o,
  output logic [P-1:0] fin_mask_o,
  output logic [P*(4*(AccW+1)+1)-1:0] fin_cox_o,
  /// Restore requests {Q, R}, and the restored coxels, in request order.
  output logic rq_valid_o,
  input  logic rq_ready_i,
  output logic [2*($clog2(MaxDim)+1)-1:0] rq_key_o,
  input  logic rs_valid_i,
  output logic rs_ready_o,
  input  logic [4*(AccW+1):0] rs_cox_i
);

  // ---------------------------------------------------------------------------
  // Widths
  // ---------------------------------------------------------------------------
  localparam int unsigned M        = $clog2(MaxDim);        // coordinate bits
  localparam int unsigned DimW     = M + 1;                 // a dimension, 1 ..= MaxDim
  localparam int unsigned LogP     = $clog2(P);
  localparam int unsigned StepW    = cube5_frame_pkg::StepW;
  localparam int unsigned DW       = StepW + 2;             // DX, DY: S(2.StepW)
  localparam int unsigned TW       = DimW + StepW + 2;      // T_x(s) = s * DX
  localparam int unsigned CntW     = cube5_frame_pkg::CntW;
  localparam int unsigned SampleW  = cube5_pkg::sample_w(VoxelW, FracW);
  localparam int unsigned RgbaW    = 3 * ColorW + AlphaW;
  localparam int unsigned ChanW    = AccW + 1;              // coxel channel U(1.AccW)
  localparam int unsigned StoreW   = 4 * ChanW + 1;         // R, G, B, A, terminated
  localparam int unsigned CoxelW   = cube5_frame_pkg::coxel_w(AccW, ZW, ColorW);
  localparam int unsigned CSampW   = 3 * ColorW + AlphaW + ZW + 3;  // compos sample
  localparam int unsigned CInW     = CoxelW + CSampW;
  localparam int unsigned BlkW     = cube5_skewmem_pkg::blk_w(M, BlockDim);
  localparam int unsigned SkInW    = cube5_skewmem_pkg::in_w(P, VoxelW, M);
  localparam int unsigned SkCntW   = 8;
  localparam int unsigned SkOutW   = cube5_skewmem_pkg::out_w(P, VoxelW, SkCntW);
  localparam int unsigned SkAddrW  = cube5_skewmem_pkg::cfg_addr_w(M, BlockDim);
  localparam int unsigned SkDataW  = cube5_skewmem_pkg::cfg_data_w(M, BlockDim);
  localparam int unsigned ShAddrW  = cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2);
  localparam int unsigned ShDataW  = cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW);
  localparam int unsigned CoAddrW  = AlphaW + 1;
  localparam int unsigned CoDataW  = AccW + 1;
  localparam int unsigned OffW     = cube5_frame_pkg::cfg_off_w(M, BlkW, ShAddrW, AlphaW);
  localparam int unsigned RowLenW  = $clog2(MaxDim/P + 1);
  localparam int unsigned SliceLenW = $clog2(MaxDim*MaxDim/P + 1);
  localparam int unsigned LagW     = SliceLenW + 1;
  localparam int unsigned TotW     = 3 * M + 1;             // beats of a frame, <= MaxDim^3 / P
  localparam int unsigned PixW     = 2 * DimW + 1;          // W * H <= (2 MaxDim)^2
  localparam int unsigned NbsW     = 2 * DimW;              // ni * nj
  /// The coxel update loop: nbs - nbr - 1 >= ReuseMin (docs/frame-rtl.md, "Smallest volumes").
  localparam int unsigned ReuseMin = cube5_frame_pkg::ReuseMin;
  localparam int unsigned InW      = cube5_frame_pkg::in_w(Source, P, VoxelW, M);
  localparam int unsigned XBeatW   = (P + 3 * Source) * VoxelW;  // a beat and its edge voxels
  localparam int unsigned GeoW     = ZW + 3 * ColorW;       // a coxel's Z, gR, gG, gB
  localparam int unsigned CbGeoW   = (DepthTest != 0) ? GeoW : 0;   // the buffer's table
  localparam int unsigned CbGeoPW  = (DepthTest != 0) ? GeoW : 1;
  localparam int unsigned CfgDataW = cube5_frame_pkg::cfg_data_w(M, VoxelW, BlkW, ShDataW, AccW);

  // Elaboration checks.
  if (P != 1 && P != 2 && P != 4 && P != 8) begin : gen_bad_p
    $fatal(1, "cube5_frame: P must be 1, 2, 4 or 8");
  end
  if (MaxDim < 8 || MaxDim > 256 || (1 << M) != MaxDim) begin : gen_bad_max_dim
    $fatal(1, "cube5_frame: MaxDim must be a power of two, 8 ..= 256");
  end
  if (2 * P > MaxDim) begin : gen_bad_p_dim
    $fatal(1, "cube5_frame: MaxDim must be at least 2 P (a row holds at least two beats)");
  end
  if (ZW < DimW) begin : gen_bad_zw
    $fatal(1, "cube5_frame: ZW must hold every slice number below MaxDim (ZW >= log2(MaxDim) + 1)");
  end
  if (VoxelW + FracW < ClassIdxW) begin : gen_bad_class
    $fatal(1, "cube5_frame: ClassIdxW must not exceed the sample width");
  end
  if (Shade > 1) begin : gen_bad_shade
    $fatal(1, "cube5_frame: Shade must be 0 (no gradient, no shader: MIP, MinIP, X-ray) or 1");
  end
  if (Source > 1) begin : gen_bad_source
    $fatal(1, "cube5_frame: Source must be 0 (the skewed memory) or 1 (a beat stream)");
  end
  if (OutLanes != 1 && (OutLanes != P || DepthTest != 0)) begin : gen_bad_out_lanes
    $fatal(1, "cube5_frame: OutLanes must be 1, or P without the depth test");
  end
  if (MaxSection > MaxDim || MaxSection < 2 * P || MaxSection % P != 0
      || (Source == 0 && MaxSection != MaxDim)) begin : gen_bad_max_section
    $fatal(1, "cube5_frame: MaxSection must be a multiple of P in 2 P ..= MaxDim (MaxDim when Source = 0)");
  end
  if (Window > 1 || (Window != 0 && (Source != 1 || DepthTest != 0 || OutLanes != 1)))
  begin : gen_bad_window
    $fatal(1, "cube5_frame: Window = 1 needs Source = 1, no depth test and OutLanes = 1");
  end
  if (DepthTest > 1) begin : gen_bad_depth_test
    $fatal(1, "cube5_frame: DepthTest must be 0 or 1");
  end
  if (DepthTest != 0 && (GeoW > CfgDataW || 2 * DimW > OffW)) begin : gen_bad_geo_cfg
    $fatal(1, "cube5_frame: a geometry word (ZW + 3 ColorW) must fit the configuration data, a pixel's (R, Q) its offset");
  end
  if (OffW + cube5_frame_pkg::CfgRegionW > 32) begin : gen_bad_cfg
    $fatal(1, "cube5_frame: the configuration address must fit 32 bits");
  end

  // ---------------------------------------------------------------------------
  // Configuration port: decode
  // ---------------------------------------------------------------------------
  typedef enum logic [2:0] {
    StIdle, StSetup1, StSetup2, StSetup3, StSweep, StReadout, StError
  } state_e;
  state_e state_q, state_d;

  logic [2:0]      cfg_region;
  logic [OffW-1:0] cfg_off;
  logic            cfg_on;
  assign cfg_region = cfg_addr_i[OffW +: 3];
  assign cfg_off    = cfg_addr_i[OffW-1:0];
  assign cfg_on     = cfg_valid_i && state_q != StSetup1 && state_q != StSetup2
                      && state_q != StSetup3 && state_q != StSweep;

  logic cfg_frame, cfg_voxel, cfg_block, cfg_shader, cfg_compos, cfg_geo;
  assign cfg_frame  = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionFrame;
  assign cfg_voxel  = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionVoxel && Source == 0;
  assign cfg_block  = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionBlock && Source == 0;
  assign cfg_shader = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionShader;
  assign cfg_compos = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionCompos;
  assign cfg_geo    = cfg_on && cfg_region == cube5_frame_pkg::CfgRegionGeometry && DepthTest != 0;

  // Frame registers (configuration: not reset).
  logic [3*DimW-1:0]    dims_q;             // nx, ny, nz
  logic [1:0]           axis_k_q;
  logic                 k_rev_q;
  logic signed [DW-1:0] dx_q, dy_q;
  logic [2:0]           render_q;
  logic                 tf2d_q;
  logic [2*DimW-1:0]    skip_q;             // empty slices skipped: before, after
  logic                 we_dims, we_view, we_dx, we_dy, we_mode, we_skip;

  assign we_dims = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegDims);
  assign we_view = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegView);
  assign we_dx   = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegDx);
  assign we_dy   = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegDy);
  assign we_mode = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegMode);
  assign we_skip = cfg_frame && cfg_off == OffW'(cube5_frame_pkg::RegSkip);

  always_ff @(posedge clk_i) begin
    if (we_dims) dims_q <= cfg_data_i[0 +: 3*DimW];
    if (we_view) {k_rev_q, axis_k_q} <= cfg_data_i[2:0];
    if (we_dx)   dx_q <= cfg_data_i[DW-1:0];
    if (we_dy)   dy_q <= cfg_data_i[DW-1:0];
    if (we_mode) {tf2d_q, render_q} <= cfg_data_i[3:0];
    if (we_skip) skip_q <= cfg_data_i[0 +: 2*DimW];
  end

  // What the render mode asks of the pipelines (docs/numerics/frame.md, "Render modes"): the
  // shader runs unlit for MIP, MinIP and X-ray; the compositing unit's mode; the coxel a ray
  // starts from (MinIP: A all ones, above every sample, so the first sample always wins).
  logic       unlit, minip;
  logic [2:0] co_mode;
  always_comb begin
    unlit   = 1'b0;
    minip   = 1'b0;
    co_mode = cube5_frame_pkg::ComposFrontToBack;
    unique case (render_q)
      cube5_frame_pkg::RenderMip: begin
        unlit   = 1'b1;
        co_mode = cube5_frame_pkg::ComposMax;
      end
      cube5_frame_pkg::RenderMinip: begin
        unlit   = 1'b1;
        minip   = 1'b1;
        co_mode = cube5_frame_pkg::ComposMin;
      end
      cube5_frame_pkg::RenderXray: begin
        unlit   = 1'b1;
        co_mode = cube5_frame_pkg::ComposXraySum;
      end
      cube5_frame_pkg::RenderFirstOpaque: co_mode = cube5_frame_pkg::ComposFirstOpaque;
      default: ;  // Composite (the refused codes never sweep)
    endcase
  end

  // ---------------------------------------------------------------------------
  // Input items: commands and (Source = 1) beats; the section of a command
  // ---------------------------------------------------------------------------
  logic            in_is_cmd, cmd_first;
  logic [1:0]      cmd_op;
  logic [M-1:0]    cmd_a0;
  logic [DimW-1:0] cmd_ns;
  logic            cmd_last;
  logic [InW-1:0]  unused_in;

  if (Source == 0) begin : gen_cmd_op
    assign in_is_cmd = 1'b1;
    assign cmd_op    = in_data_i[1:0];
    assign cmd_a0    = '0;
    assign cmd_ns    = '0;
    assign cmd_first = 1'b1;
    assign cmd_last  = 1'b1;
  end else begin : gen_cmd_sec
    assign in_is_cmd = in_data_i[0] == cube5_frame_pkg::InKindCmd;
    assign cmd_op    = in_data_i[1 +: 2];
    assign cmd_a0    = in_data_i[3 +: M];
    assign cmd_ns    = in_data_i[3 + M +: DimW];
    assign cmd_first = in_data_i[3 + M + DimW];
    assign cmd_last  = in_data_i[4 + M + DimW];
  end
  assign unused_in = in_data_i;

  // The section being swept (Source = 0: the whole face, one section, first and last).
  logic [M-1:0]    sec_a0_q;
  logic [DimW-1:0] sec_ns_q;
  logic            sec_last_q;
  logic [M-1:0]    sa0;
  logic [DimW-1:0] sns;
  logic            slast;

  // ---------------------------------------------------------------------------
  // Frame set-up: frame-axis dimensions, counts, base plane, checks (three cycles)
  // ---------------------------------------------------------------------------
  logic [DimW-1:0] nx, ny, nz;
  assign nx = dims_q[0 +: DimW];
  assign ny = dims_q[DimW +: DimW];
  assign nz = dims_q[2*DimW +: DimW];

  function automatic logic dim_ok(logic [DimW-1:0] n);
    dim_ok = (n >= DimW'(P)) && (n <= DimW'(MaxDim)) && ((n & DimW'(P - 1)) == '0);
  endfunction

  logic signed [DW-1:0] one_step;
  assign one_step = DW'(1) <<< StepW;

  // Set-up 1: frame axes ((i, j) = (y, z), (x, z), (x, y) for k = x, y, z) and the register checks.
  logic [DimW-1:0] ni_q, nj_q, nk_q, ni_d, nj_d, nk_d;
  logic            dims_ok_q, view_ok_q, dims_ok_d, view_ok_d;

  always_comb begin
    unique case (axis_k_q)
      2'd0:    begin ni_d = ny; nj_d = nz; nk_d = nx; end
      2'd1:    begin ni_d = nx; nj_d = nz; nk_d = ny; end
      default: begin ni_d = nx; nj_d = ny; nk_d = nz; end
    endcase
    dims_ok_d = dim_ok(nx) && dim_ok(ny) && dim_ok(nz);
    view_ok_d = (axis_k_q != 2'd3)
                && (render_q <= cube5_frame_pkg::RenderFirstOpaque)
                // Without gradient and shader: the unlit modes with the 1-D classification only.
                && (Shade != 0 || (unlit && !tf2d_q))
                && (dx_q <= one_step) && (dx_q >= -one_step)
                && (dy_q <= one_step) && (dy_q >= -one_step);
  end

  always_ff @(posedge clk_i) begin
    if (state_q == StSetup1) begin
      ni_q      <= ni_d;
      nj_q      <= nj_d;
      nk_q      <= nk_d;
      dims_ok_q <= dims_ok_d;
      view_ok_q <= view_ok_d;
    end
  end

  // Set-up 2: products; the slice range of the sweep (the skipped empty slices before and after).
  logic [NbsW-1:0]      nij_q, nij_d;
  logic signed [TW-1:0] tx_last_q, ty_last_q, tx_last_d, ty_last_d;  // (nk - 1) * DX, * DY
  logic signed [TW-1:0] tx0_q, ty0_q, tx0_d, ty0_d;                  // s_first * DX, * DY
  logic [DimW-1:0]      skip_front, skip_back, s_first_q, s_last_q, s_first_d, s_last_d;
  logic [DimW-1:0]      swept_q, swept_d;                          // slices swept
  logic [DimW:0]        skipped;
  logic                 skip_ok_q, skip_ok_d;
  logic                 sec_ok_q, sec_ok_d;
  logic [DimW:0]        sec_end, sec_end_q;
  logic [DimW-1:0]      nbr_q;                                     // beats per row

  // Source = 1 sweeps every slice of a section (the stream brings them all): Skip is ignored.
  assign skip_front = (Source == 0) ? skip_q[0 +: DimW] : '0;
  assign skip_back  = (Source == 0) ? skip_q[DimW +: DimW] : '0;
  assign skipped    = {1'b0, skip_front} + {1'b0, skip_back};

  always_comb begin
    nij_d     = NbsW'(sns) * NbsW'(nj_q);
    tx_last_d = TW'($signed({1'b0, nk_q - DimW'(1)})) * TW'(dx_q);
    ty_last_d = TW'($signed({1'b0, nk_q - DimW'(1)})) * TW'(dy_q);
    tx0_d     = TW'($signed({1'b0, skip_front})) * TW'(dx_q);
    ty0_d     = TW'($signed({1'b0, skip_front})) * TW'(dy_q);
    s_first_d = skip_front;
    s_last_d  = nk_q - DimW'(1) - skip_back;
    swept_d   = nk_q - skip_front - skip_back;
    // At least one slice is swept.
    skip_ok_d = skipped < {1'b0, nk_q};
    // The section: P-aligned, inside the face (Source = 0: the face itself).
    sec_end   = {1'b0, DimW'(sa0)} + {1'b0, sns};
    sec_ok_d  = ((sa0 & M'(P - 1)) == '0) && ((sns & DimW'(P - 1)) == '0)
                && (sec_end <= {1'b0, ni_q}) && (sns <= DimW'(MaxSection));
  end

  always_ff @(posedge clk_i) begin
    if (state_q == StSetup2) begin
      nij_q     <= nij_d;
      tx_last_q <= tx_last_d;
      ty_last_q <= ty_last_d;
      tx0_q     <= tx0_d;
      ty0_q     <= ty0_d;
      s_first_q <= s_first_d;
      s_last_q  <= s_last_d;
      swept_q   <= swept_d;
      skip_ok_q <= skip_ok_d;
      sec_ok_q  <= sec_ok_d;
      sec_end_q <= sec_end;
      nbr_q     <= sns >> LogP;
    end
  end

  // Set-up 3: beats per row (registered in set-up 2) and slice (wires of registers that hold until
  // the next set-up), the base plane, the flush, the volume rule.
  logic [DimW-1:0]      nbr, max_sx_q, max_sy_q, max_sx_d, max_sy_d;
  logic [NbsW-1:0]      nbs;
  logic [TotW-1:0]      total_q, total_d;
  logic [DimW:0]        w_q, h_q, w_d, h_d;
  logic [PixW-1:0]      pixels_q;
  logic [LagW:0]        flush_q, flush_d;
  logic signed [TW-1:0] sx_last, sy_last;
  logic [DimW-1:0]      abs_sx, abs_sy;
  logic                 frame_ok;

  assign nbr = nbr_q;

  always_comb begin
    nbs      = nij_q >> LogP;
    sx_last  = tx_last_q >>> StepW;
    sy_last  = ty_last_q >>> StepW;
    abs_sx   = DimW'(sx_last < 0 ? -sx_last : sx_last);
    abs_sy   = DimW'(sy_last < 0 ? -sy_last : sy_last);
    // W = ni + max sx - min sx; sx(s) is monotone, so the extremes are sx(0) = 0 and sx(nk-1).
    w_d      = {1'b0, ni_q} + {1'b0, abs_sx};
    h_d      = {1'b0, nj_q} + {1'b0, abs_sy};
    max_sx_d = (sx_last > 0) ? DimW'(sx_last) : '0;
    max_sy_d = (sy_last > 0) ? DimW'(sy_last) : '0;
    total_d  = TotW'(nbs) * TotW'(swept_q);
    flush_d  = (LagW+1)'(nbs) + (LagW+1)'(2 * nbr) + (LagW+1)'(2);
    // Rows of at least two beats; a coxel's reuse distance nbs - nbr - 1 of at least ReuseMin.
    frame_ok = dims_ok_q && view_ok_q && skip_ok_q && sec_ok_q && (nbr >= DimW'(2))
               && (nbs >= NbsW'(nbr) + NbsW'(1 + ReuseMin));
  end

  always_ff @(posedge clk_i) begin
    if (state_q == StSetup3) begin
      total_q  <= total_d;
      max_sx_q <= max_sx_d;
      max_sy_q <= max_sy_d;
      w_q      <= w_d;
      h_q      <= h_d;
      flush_q  <= flush_d;
    end
  end

  // The read-out's items, H ceil(W / OutLanes) (W H at one lane), needed only by the read-out:
  // multiplied from the registers during the sweep.
  localparam int unsigned LogLanes = $clog2(OutLanes);
  logic [PixW-1:0] pixels_d;
  logic [DimW:0]   w_items;
  assign w_items  = (w_q + (DimW+1)'(OutLanes - 1)) >> LogLanes;
  assign pixels_d = PixW'(w_items) * PixW'(h_q);

  always_ff @(posedge clk_i) begin
    if (state_q == StSweep) pixels_q <= pixels_d;
  end

  // ---------------------------------------------------------------------------
  // Control
  // ---------------------------------------------------------------------------
  logic in_fire, cmd_fire, out_fire, cbuf_clear_busy, start, ro_start, cmd_ready, beat_ready;
  logic dirty_q, dirty_d, wipe_q, wipe_d;
  logic sweep_done, ro_last;
  logic [TotW-1:0] recvd_q, recvd_d, written_q, written_d;
  logic [LagW:0]   flushed_q, flushed_d;
  logic [PixW-1:0] sent_q, sent_d;
  logic [CntW-1:0] reads_q, reads_d, cycles_q, cycles_d;
  logic            mem_beat, mem_read, flush_beat, upd_done;
  logic            win_ok;     // Window = 1: the window can take the next beat's sample beat
  // The sweep needs more beats (state_q == StSweep && recvd_q != total_q, as a register: the
  // take's logic then has no counter compare in it), and the next beat is the last
  // (recvd_q + 1 == total_q).
  logic            more_q, more_d, last_beat_q, last_beat_d;

  // Commands while idle; beats (Source = 1) while the sweep still needs them, or while idle (a
  // stray beat after a reset: taken and dropped).
  assign cmd_ready  = (state_q == StIdle) && !cbuf_clear_busy;
  assign beat_ready = (state_q == StIdle) || (more_q && win_ok);
  assign in_ready_o = in_is_cmd ? cmd_ready : beat_ready;
  assign in_fire    = in_valid_i && in_ready_o;
  assign cmd_fire   = in_fire && in_is_cmd;
  assign out_fire   = out_valid_o && out_ready_i;
  assign start      = (state_q == StSetup3) && frame_ok;
  assign sweep_done = (state_q == StSweep) && (written_q == total_q);
  assign ro_start   = sweep_done && slast && Window == 0;
  assign ro_last    = (state_q == StReadout) && out_fire && (sent_q == pixels_q - PixW'(1));

  // The section's fields (configuration-like: kept until the next command).
  always_ff @(posedge clk_i) begin
    if (cmd_fire) begin
      sec_a0_q   <= cmd_a0;
      sec_ns_q   <= cmd_ns;
      sec_last_q <= cmd_last;
    end
  end
  assign sa0   = (Source == 0) ? '0 : sec_a0_q;
  assign sns   = (Source == 0) ? ni_q : sec_ns_q;
  assign slast = (Source == 0) ? 1'b1 : sec_last_q;

  // The compositing buffer holds a frame's coxels from its first section's sweep to the end of
  // its read-out (dirty). A first section that finds it dirty (the last frame was left without
  // its last section) has it cleared first, through the buffer's clear pass (wipe).
  always_comb begin
    dirty_d = dirty_q;
    wipe_d  = 1'b0;
    if (start && Source != 0 && Window == 0) dirty_d = 1'b1;
    if (ro_last) dirty_d = 1'b0;
    if (cmd_fire && Source != 0 && cmd_first && dirty_q
        && cmd_op == cube5_frame_pkg::OpRender) begin
      wipe_d  = 1'b1;
      dirty_d = 1'b0;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      dirty_q <= 1'b0;
      wipe_q  <= 1'b0;
    end else begin
      dirty_q <= dirty_d;
      wipe_q  <= wipe_d;
    end
  end

  always_comb begin
    state_d  = state_q;
    unique case (state_q)
      StIdle: if (cmd_fire) begin
        state_d = (cmd_op != cube5_frame_pkg::OpRender) ? StError : StSetup1;
      end
      // (Waits while a wipe clears the compositing buffer: Source = 1 only.)
      StSetup1: if (!wipe_q && !cbuf_clear_busy) state_d = StSetup2;
      StSetup2: state_d = StSetup3;
      StSetup3: state_d = frame_ok ? StSweep : StError;
      StSweep:   if (sweep_done) state_d = (slast && Window == 0) ? StReadout : StIdle;
      StReadout: if (ro_last) state_d = StIdle;
      StError:   if (out_fire) state_d = StIdle;
      default:   state_d = StIdle;
    endcase
  end

  // Counters of the sweep. A sweep has at least one beat (frame_ok: nbs and the slices swept are
  // at least 1), so the start sets more_q.
  always_comb begin
    more_d      = more_q;
    last_beat_d = last_beat_q;
    if (start) begin
      more_d      = 1'b1;
      last_beat_d = 1'b0;   // total >= nbs >= nbr + 1 + ReuseMin > 1
    end else if (mem_beat) begin
      more_d      = !last_beat_q;
      last_beat_d = recvd_q + TotW'(2) == total_q;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      more_q      <= 1'b0;
      last_beat_q <= 1'b0;
    end else begin
      more_q      <= more_d;
      last_beat_q <= last_beat_d;
    end
  end
`ifndef SYNTHESIS
  MoreAsCounted: assert property (@(posedge clk_i) disable iff (!rst_ni)
      more_q == (state_q == StSweep && recvd_q != total_q)
      && (!more_q || last_beat_q == (recvd_q + TotW'(1) == total_q)))
    else $error("cube5_frame: more_q or last_beat_q disagrees with the beat count");
`endif

  always_comb begin
    recvd_d   = recvd_q;
    written_d = written_q;
    flushed_d = flushed_q;
    sent_d    = sent_q;
    reads_d   = reads_q;
    cycles_d  = cycles_q;
    // A frame's counters run from its first section's command (Source = 0: every command).
    if (cmd_fire && cmd_first) begin
      reads_d  = '0;
      cycles_d = '0;
    end else if (state_q != StIdle && state_q != StReadout && state_q != StError) begin
      cycles_d = cycles_q + CntW'(1);
    end
    if (start) begin
      recvd_d   = '0;
      written_d = '0;
      flushed_d = '0;
    end else begin
      if (mem_beat)   recvd_d   = recvd_q + TotW'(1);
      if (flush_beat) flushed_d = flushed_q + (LagW+1)'(1);
      if (upd_done)   written_d = written_q + TotW'(1);
      if (mem_read)   reads_d   = reads_q + CntW'(1);
    end
    if (ro_start) begin
      sent_d = '0;
    end else if (state_q == StReadout && out_fire) begin
      sent_d = sent_q + PixW'(1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      state_q   <= StIdle;
      recvd_q   <= '0;
      written_q <= '0;
      flushed_q <= '0;
      sent_q    <= '0;
      reads_q   <= '0;
      cycles_q  <= '0;
    end else begin
      state_q   <= state_d;
      recvd_q   <= recvd_d;
      written_q <= written_d;
      flushed_q <= flushed_d;
      sent_q    <= sent_d;
      reads_q   <= reads_d;
      cycles_q  <= cycles_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Where the beats come from: the skewed memory (Source = 0) or the input stream (Source = 1)
  // ---------------------------------------------------------------------------
  logic [XBeatW-1:0] mem_lanes;

  if (Source == 0) begin : gen_skewmem
    logic         cmd_valid, sk_in_ready, sk_in_valid;
    logic [M-1:0] cmd_x, cmd_y, cmd_z;
    logic [1:0]   cmd_axis;
    logic [SkInW-1:0] sk_in;

    cube5_frame_agen #(
      .P          (P),
      .MaxDimLog2 (M)
    ) u_agen (
      .clk_i        (clk_i),
      .rst_ni       (rst_ni),
      .start_i      (start),
      .nbr_i        (nbr),
      .nj_i         (nj_q),
      .nk_i         (nk_q),
      .s_first_i    (s_first_q),
      .s_last_i     (s_last_q),
      .axis_k_i     (axis_k_q),
      .k_reversed_i (k_rev_q),
      .cmd_valid_o  (cmd_valid),
      .cmd_ready_i  (sk_in_ready && state_q == StSweep),
      .cmd_x_o      (cmd_x),
      .cmd_y_o      (cmd_y),
      .cmd_z_o      (cmd_z),
      .cmd_axis_o   (cmd_axis)
    );

    // A voxel write (configuration region 1) or a beam read; the two never meet (no writes while
    // sweeping). Command: op, axis, x, y, z, data, probe.
    always_comb begin
      if (state_q == StSweep) begin
        sk_in_valid = cmd_valid;
        sk_in = {{cube5_skewmem_pkg::mod_w(P){1'b0}}, {VoxelW{1'b0}}, cmd_z, cmd_y, cmd_x, cmd_axis,
                 cube5_skewmem_pkg::OpRead};
      end else begin
        sk_in_valid = cfg_voxel;
        sk_in = {{cube5_skewmem_pkg::mod_w(P){1'b0}}, cfg_data_i[VoxelW-1:0], cfg_off[2*M +: M],
                 cfg_off[M +: M], cfg_off[0 +: M], 2'd0, cube5_skewmem_pkg::OpWrite};
      end
    end

    // Skewed memory configuration: the dimensions follow the frame register; block LUT entries.
    logic               sk_cfg_valid;
    logic [SkAddrW-1:0] sk_cfg_addr;
    logic [SkDataW-1:0] sk_cfg_data;
    always_comb begin
      sk_cfg_valid = we_dims || cfg_block;
      sk_cfg_addr  = cfg_block ? {1'b1, cfg_off[BlkW-1:0]} : '0;
      sk_cfg_data  = SkDataW'(cfg_data_i);
    end

    logic              sk_out_valid;
    logic [SkOutW-1:0] sk_out;

    cube5_skewmem #(
      .P           (P),
      .VoxelW      (VoxelW),
      .MaxDim      (MaxDim),
      .BlockDim    (BlockDim),
      .MemLatency  (MemLatency),
      .CntW        (SkCntW)
    ) u_mem (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (sk_in_valid),
      .in_ready_o  (sk_in_ready),
      .in_data_i   (sk_in),
      .out_valid_o (sk_out_valid),
      .out_ready_i (1'b1),
      .out_data_o  (sk_out),
      .cfg_valid_i (sk_cfg_valid),
      .cfg_addr_i  (sk_cfg_addr),
      .cfg_data_i  (sk_cfg_data)
    );

    // Responses: lanes, is_beam, outside, empty, masked, conflict, rd, wr.
    logic                rsp_beam, rsp_outside, rsp_empty, rsp_masked;
    assign mem_lanes   = sk_out[0 +: P*VoxelW];
    assign rsp_beam    = sk_out[P*VoxelW];
    assign rsp_outside = sk_out[P*VoxelW + 1];
    assign rsp_empty   = sk_out[P*VoxelW + 2];
    assign rsp_masked  = sk_out[P*VoxelW + 3];
    assign mem_beat    = sk_out_valid && rsp_beam && state_q == StSweep;
    assign mem_read    = mem_beat && !rsp_outside && !rsp_empty && !rsp_masked;
`ifndef SYNTHESIS
    // Voxel writes are never lost: the memory takes a command every cycle while idle.
    VoxelWriteTaken: assert property (@(posedge clk_i) disable iff (!rst_ni)
        cfg_voxel |-> sk_in_ready)
      else $error("cube5_frame: the skewed memory refused a voxel write");
    MemoryBeatsInSweep: assert property (@(posedge clk_i) disable iff (!rst_ni)
        sk_out_valid && rsp_beam |-> state_q == StSweep)
      else $error("cube5_frame: a memory beat outside the sweep");
`endif
    logic unused_sk;
    assign unused_sk = ^sk_out;
  end else begin : gen_stream
    // A beat: lanes, lo, hi0, hi1, then row_first, row_last, slice_last, last, error. The frame
    // counts positions itself; the marks are checked against its count in simulation.
    logic beat_take, beat_err;
    logic [4:0] beat_marks;
    // in_fire && !in_is_cmd in the sweep, written out so that the command side's ready (the
    // compositing buffer's clear) is no input of the take (for clock rate: the routed line's
    // critical path at d5c8287 ran from that clear through in_ready_o into the window's admission).
    assign beat_take  = in_valid_i && !in_is_cmd && state_q == StSweep && more_q && win_ok;
`ifndef SYNTHESIS
    BeatTakeAsFire: assert property (@(posedge clk_i) disable iff (!rst_ni)
        beat_take == (in_fire && !in_is_cmd && state_q == StSweep))
      else $error("cube5_frame: the beat take disagrees with the input's handshake");
`endif
    assign beat_err   = in_data_i[1 + XBeatW + 4];
    assign beat_marks = in_data_i[1 + XBeatW +: 5];
    assign mem_lanes  = in_data_i[1 +: XBeatW];
    // A refused section's error beam carries nothing: dropped.
    assign mem_beat   = beat_take && !beat_err;
    assign mem_read   = mem_beat;
    logic unused_marks;
    assign unused_marks = ^{beat_marks, cfg_voxel, cfg_block, k_rev_q};
`ifndef SYNTHESIS
    // The beats' marks agree with the frame's own count of the section (same geometry on both
    // sides of the stream): a counter of the beats taken, checked on every beat.
    logic [DimW-1:0] in_m, in_b, in_s;
    logic signed [1:0] in_tx, in_ty;
    logic in_fb, in_lb, in_fr, in_lr, in_fs, in_ls;
    cube5_frame_pos #(
      .DimW (DimW),
      .TW   (2),
      .DW   (2)
    ) u_in_pos (
      .clk_i         (clk_i),
      .rst_ni        (rst_ni),
      .start_i       (start),
      .step_i        (mem_beat),
      .nbr_i         (nbr),
      .nj_i          (nj_q),
      .s_first_i     ('0),
      .s_last_i      (nk_q - DimW'(1)),
      .tx0_i         (2'sd0),
      .ty0_i         (2'sd0),
      .dx_i          (2'sd0),
      .dy_i          (2'sd0),
      .m_o           (in_m),
      .b_o           (in_b),
      .s_o           (in_s),
      .tx_o          (in_tx),
      .ty_o          (in_ty),
      .first_beat_o  (in_fb),
      .last_beat_o   (in_lb),
      .first_row_o   (in_fr),
      .last_row_o    (in_lr),
      .first_slice_o (in_fs),
      .last_slice_o  (in_ls)
    );
    logic unused_in_pos;
    assign unused_in_pos = ^{in_m, in_b, in_s, in_tx, in_ty, in_fr, in_fs};
    BeatMarksAsCounted: assert property (@(posedge clk_i) disable iff (!rst_ni)
        mem_beat |-> beat_marks[3:0] == {in_lb && in_lr && in_ls, in_lb && in_lr, in_lb, in_fb})
      else $error("cube5_frame: a beat's marks (row_first, row_last, slice_last, last) disagree with the section's geometry");
`endif
  end

  // After the last memory beat: nbs + 2 nbr + 2 beats of zeros flush the windows.
  assign flush_beat  = (state_q == StSweep) && !more_q && (flushed_q != flush_q) && win_ok;

  logic                beat_valid;
  assign beat_valid = mem_beat || flush_beat;

  // The beat register (BeatLatency cycles): the interpolators' windows, whose every register and
  // block RAM advances per beat, take the beat a cycle after it is taken, so that their enable is
  // a flip-flop and not the take (the input's valid, the window's admission, the state), which
  // would otherwise reach across the whole frame in one cycle (docs/accel.md, *Synthesis*). The
  // window's admission counts the beat as it is taken.
  if (cube5_frame_pkg::BeatLatency != 1) begin : gen_bad_beat_latency
    $fatal(1, "cube5_frame: the beat register is one stage (BeatLatency = 1)");
  end
  // The lanes are registered as they come and zeroed after the register for a flush beat, so
  // that the take does not fan out to every lane's bit.
  logic                beat_valid_q, beat_mem_q;
  logic [XBeatW-1:0]   beat_q, beat_in;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      beat_valid_q <= 1'b0;
      beat_mem_q   <= 1'b0;
    end else begin
      beat_valid_q <= beat_valid;
      beat_mem_q   <= mem_beat;
    end
  end
  always_ff @(posedge clk_i) begin
    beat_q <= mem_lanes;
  end
  assign beat_in = beat_mem_q ? beat_q : '0;

  // ---------------------------------------------------------------------------
  // The P pipelines
  // ---------------------------------------------------------------------------
  logic                   smp_valid;
  logic [(3*P+2*Source)*SampleW-1:0] smp;
  // The section's edge samples exist unless the section starts or ends at the face's edge.
  logic                   edge_lo_on, edge_hi_on;
  assign edge_lo_on = (sa0 != '0);
  assign edge_hi_on = sec_end_q != {1'b0, ni_q};
  // Delay-line lengths (explicitly sized wires: Yosys ignores a narrowing cast on a port).
  logic [RowLenW-1:0]     row_len;
  logic [SliceLenW-1:0]   slice_len;
  logic [LagW-1:0]        lag;
  assign row_len   = RowLenW'(nbr - DimW'(1));
  assign slice_len = SliceLenW'(nbs - NbsW'(1));
  assign lag       = LagW'(nbs) + LagW'(nbr) + LagW'(1);

  cube5_frame_interp #(
    .P       (P),
    .MaxDim  (MaxDim),
    .VoxelW  (VoxelW),
    .WeightW (WeightW),
    .FracW   (FracW),
    .DimW    (DimW),
    .TW      (TW),
    .DW      (DW),
    .MaxRow  (MaxSection),
    .Edges   (Source)
  ) u_interp (
    .clk_i        (clk_i),
    .rst_ni       (rst_ni),
    .start_i      (start),
    .nbr_i        (nbr),
    .nj_i         (nj_q),
    .s_first_i    (s_first_q),
    .s_last_i     (s_last_q),
    .tx0_i        (tx0_q),
    .ty0_i        (ty0_q),
    .dx_i         (dx_q),
    .dy_i         (dy_q),
    .row_len_i    (row_len),
    .slice_len_i  (slice_len),
    .lag_i        (lag),
    .edge_lo_on_i (edge_lo_on),
    .edge_hi_on_i (edge_hi_on),
    .beat_valid_i (beat_valid_q),
    .beat_i       (beat_in),
    .smp_valid_o  (smp_valid),
    .smp_o        (smp)
  );

  logic                   nb_valid;
  logic [7*P*SampleW-1:0] nb;

  cube5_frame_swin #(
    .P       (P),
    .MaxDim  (MaxDim),
    .SampleW (SampleW),
    .DimW    (DimW),
    .Edges   (Source)
  ) u_swin (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .start_i     (start),
    .nbr_i       (nbr),
    .nj_i        (nj_q),
    .nk_i        (nk_q),
    .row_len_i   (row_len),
    .smp_valid_i (smp_valid),
    .smp_i       (smp),
    .nb_valid_o  (nb_valid),
    .nb_o        (nb)
  );

  logic               rgba_valid;
  logic [P*RgbaW-1:0] rgba;

  if (Shade != 0) begin : gen_shade
    cube5_frame_shade #(
      .P          (P),
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
      .ShCfgAddrW (ShAddrW),
      .ShCfgDataW (ShDataW),
      .ShaderPipe (cube5_frame_pkg::ShaderPipe)
    ) u_shade (
      .clk_i         (clk_i),
      .rst_ni        (rst_ni),
      .start_i       (start),
      .shader_mode_i ({unlit, tf2d_q}),
      .nb_valid_i    (nb_valid),
      .nb_i          (nb),
      .cfg_valid_i   (cfg_shader),
      .cfg_addr_i    (cfg_off[ShAddrW-1:0]),
      .cfg_data_i    (cfg_data_i[ShDataW-1:0]),
      .rgba_valid_o  (rgba_valid),
      .rgba_o        (rgba)
    );
  end else begin : gen_class
    cube5_frame_class #(
      .P          (P),
      .VoxelW     (VoxelW),
      .FracW      (FracW),
      .ClassIdxW  (ClassIdxW),
      .ColorW     (ColorW),
      .AlphaW     (AlphaW),
      .ShCfgAddrW (ShAddrW),
      .ShCfgDataW (ShDataW)
    ) u_class (
      .clk_i        (clk_i),
      .rst_ni       (rst_ni),
      .nb_valid_i   (nb_valid),
      .nb_i         (nb),
      .cfg_valid_i  (cfg_shader),
      .cfg_addr_i   (cfg_off[ShAddrW-1:0]),
      .cfg_data_i   (cfg_data_i[ShDataW-1:0]),
      .rgba_valid_o (rgba_valid),
      .rgba_o       (rgba)
    );
  end

  // ---------------------------------------------------------------------------
  // Compositing buffer and the compositing units (one per bank)
  // ---------------------------------------------------------------------------
  logic               upd_valid, cb_out_valid, ro_busy, unused_ro_busy;
  logic [P*StoreW-1:0] upd_cox, upd_res;
  logic [P*RgbaW-1:0] upd_pay;
  logic [DimW-1:0]    upd_depth;
  logic [OutLanes*StoreW-1:0] cb_out_cox;
  logic [StoreW-1:0]  empty_cox;
  logic [P*CbGeoPW-1:0] cb_upd_geo;
  logic [CbGeoPW-1:0] cb_out_geo;
  logic               cb_out_ready;
  logic [P-1:0]       upd_past;
  logic [DimW-1:0]    cb_max_sx;   // max sx + A0: the section's anchors land A0 columns right
  logic               cb_rst_n;    // reset, or a wipe of a frame left without its last section
  assign cb_max_sx = max_sx_q + DimW'(sa0);
  assign cb_rst_n  = rst_ni && !wipe_q;
  logic [P-1:0]       co_ready, co_valid;
  logic [P*CoxelW-1:0] co_out;
  logic [P-1:0]       win_enter, win_restore;
  logic [StoreW-1:0]  win_rs_cox;
  logic [P*StoreW-1:0] win_wb_cox;
  // The window's words per bank row: MaxSection / P rounded up to a power of two. Its
  // descriptor, park and final FIFOs (more than the beats from admission to write-back: no stall
  // while the streams keep up) and its restore FIFO (restores requested ahead: more than a slice's
  // nj).
  localparam int unsigned WinCols  = 1 << $clog2(MaxSection / P);
  localparam int unsigned WinDepth = 32;
  localparam int unsigned RsDepth  = 2 * MaxDim;

  cube5_frame_cbuf #(
    .P      (P),
    .MaxDim (MaxDim),
    .PayW   (RgbaW),
    .CoxW   (StoreW),
    .DimW   (DimW),
    .TW     (TW),
    .DW     (DW),
    .GeoW   (CbGeoW),
    .GeoPW  (CbGeoPW),
    .OutLanes (OutLanes),
    .Window   (Window),
    .WinCols  (WinCols)
  ) u_cbuf (
    .clk_i        (clk_i),
    .rst_ni       (cb_rst_n),
    .clear_busy_o (cbuf_clear_busy),
    .empty_cox_i  (empty_cox),
    .start_i      (start),
    .nbr_i        (nbr),
    .nj_i         (nj_q),
    .far_x_i      (!edge_hi_on),
    .s_first_i    (s_first_q),
    .s_last_i     (s_last_q),
    .tx0_i        (tx0_q),
    .ty0_i        (ty0_q),
    .dx_i         (dx_q),
    .dy_i         (dy_q),
    .max_sx_i     (cb_max_sx),
    .max_sy_i     (max_sy_q),
    .in_valid_i   (rgba_valid),
    .in_pay_i     (rgba),
    .upd_valid_o  (upd_valid),
    .upd_cox_o    (upd_cox),
    .upd_pay_o    (upd_pay),
    .upd_depth_o  (upd_depth),
    .upd_past_o   (upd_past),
    .upd_geo_o    (cb_upd_geo),
    .upd_valid_i  (co_valid[0]),
    .upd_cox_i    (upd_res),
    .ro_start_i   (ro_start),
    .w_i          (w_q),
    .h_i          (h_q),
    .out_valid_o  (cb_out_valid),
    .out_ready_i  (cb_out_ready),
    .out_cox_o    (cb_out_cox),
    .out_geo_o    (cb_out_geo),
    .ro_busy_o    (ro_busy),
    .geo_we_i     (cfg_geo),
    .geo_r_i      (cfg_off[0 +: DimW]),
    .geo_q_i      (cfg_off[DimW +: DimW]),
    .geo_data_i   (cfg_data_i[CbGeoPW-1:0]),
    .win_enter_i  (win_enter),
    .win_restore_i (win_restore),
    .win_rs_cox_i (win_rs_cox),
    .wb_cox_o     (win_wb_cox)
  );
  assign unused_ro_busy = ro_busy;

  // The compositing window's control (Window = 1), or nothing.
  if (Window != 0) begin : gen_window
    cube5_frame_win #(
      .P       (P),
      .DimW    (DimW),
      .TW      (TW),
      .DW      (DW),
      .CoxW    (StoreW),
      .TrigW   (LagW + 1),
      .Depth   (WinDepth),
      .RsDepth (RsDepth),
      .DescDepth (WinDescDepth)
    ) u_win (
      .clk_i        (clk_i),
      .rst_ni       (rst_ni),
      .start_i      (start),
      .nbr_i        (nbr),
      .nj_i         (nj_q),
      .nk_i         (nk_q),
      .lo_edge_i    (!edge_lo_on),
      .hi_edge_i    (!edge_hi_on),
      .dx_i         (dx_q),
      .dy_i         (dy_q),
      .max_sx_i     (cb_max_sx),
      .max_sy_i     (max_sy_q),
      .trig_i       (flush_q),
      .adm_ok_o     (win_ok),
      .adm_i        (beat_valid),
      .rd_i         (rgba_valid),
      .rd_enter_o   (win_enter),
      .rd_restore_o (win_restore),
      .rd_rs_cox_o  (win_rs_cox),
      .wb_i         (co_valid[0]),
      .wb_cox_i     (win_wb_cox),
      .park_valid_o (park_valid_o),
      .park_ready_i (park_ready_i),
      .park_key_o   (park_key_o),
      .park_cox_o   (park_cox_o),
      .fin_valid_o  (fin_valid_o),
      .fin_ready_i  (fin_ready_i),
      .fin_key_o    (fin_key_o),
      .fin_mask_o   (fin_mask_o),
      .fin_cox_o    (fin_cox_o),
      .rq_valid_o   (rq_valid_o),
      .rq_ready_i   (rq_ready_i),
      .rq_key_o     (rq_key_o),
      .rs_valid_i   (rs_valid_i),
      .rs_ready_o   (rs_ready_o),
      .rs_cox_i     (rs_cox_i)
    );
  end else begin : gen_no_window
    assign win_ok       = 1'b1;
    assign win_enter    = '0;
    assign win_restore  = '0;
    assign win_rs_cox   = '0;
    assign park_valid_o = 1'b0;
    assign park_key_o   = '0;
    assign park_cox_o   = '0;
    assign fin_valid_o  = 1'b0;
    assign fin_key_o    = '0;
    assign fin_mask_o   = '0;
    assign fin_cox_o    = '0;
    assign rq_valid_o   = 1'b0;
    assign rq_key_o     = '0;
    assign rs_ready_o   = 1'b1;
    logic unused_win_in;
    assign unused_win_in = ^{park_ready_i, fin_ready_i, rq_ready_i, rs_valid_i, rs_cox_i,
                             win_wb_cox};
  end

  // "No geometry" depth, all ones (written out: Yosys 0.23 reads a '1 localparam as 1).
  localparam logic [ZW-1:0] ZNone = {ZW{1'b1}};
  // The coxel a ray starts from, stored fields {terminated, A, B, G, R}: all 0, or for MinIP
  // A = 2^(AccW+1) - 1 (compos.md, Min: "preloaded with A >= 2^F").
  assign empty_cox = minip ? {1'b0, {ChanW{1'b1}}, {3*ChanW{1'b0}}} : '0;

  // Stored coxel {terminated, A, B, G, R} and geometry {gB, gG, gR, Z} <-> compos coxel
  // {terminated, gB, gG, gR, Z, A, B, G, R}.
  function automatic logic [CoxelW-1:0] full_coxel(logic [StoreW-1:0] st, logic [GeoW-1:0] geo);
    full_coxel = {st[4*ChanW], geo, st[4*ChanW-1:0]};
  endfunction

  // Each bank's geometry: the table's word (DepthTest), or none (Znone, colour 0).
  logic [P*GeoW-1:0] upd_geo;
  logic [GeoW-1:0]   out_geo;
  if (DepthTest != 0) begin : gen_geo
    assign upd_geo = cb_upd_geo;
    assign out_geo = cb_out_geo;
  end else begin : gen_no_geo
    assign upd_geo = {P{{3*ColorW{1'b0}}, ZNone}};
    assign out_geo = {{3*ColorW{1'b0}}, ZNone};
    logic unused_cb_geo;
    assign unused_cb_geo = ^{cb_upd_geo, cb_out_geo};
  end

  for (genvar j = 0; j < P; j++) begin : gen_compos
    // MinIP leaves out the samples past a far face: at depth Znone the depth test passes them by.
    logic [ZW-1:0]   co_depth;
    logic [CInW-1:0] co_in;
    assign co_depth = (minip && upd_past[j]) ? ZNone : ZW'(upd_depth);
    assign co_in    = {co_mode, co_depth, upd_pay[j*RgbaW +: RgbaW],
                       full_coxel(upd_cox[j*StoreW +: StoreW], upd_geo[j*GeoW +: GeoW])};

    cube5_compos #(
      .ColorW (ColorW),
      .AlphaW (AlphaW),
      .ExtraW (ExtraW),
      .AccW   (AccW),
      .ZW     (ZW)
    ) u_compos (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (upd_valid),
      .in_ready_o  (co_ready[j]),
      .in_data_i   (co_in),
      .out_valid_o (co_valid[j]),
      .out_ready_i (1'b1),
      .out_data_o  (co_out[j*CoxelW +: CoxelW]),
      .cfg_valid_i (cfg_compos),
      .cfg_addr_i  (cfg_off[CoAddrW-1:0]),
      .cfg_data_i  (cfg_data_i[CoDataW-1:0])
    );

    // Back to the stored fields: R, G, B, A and terminated (Z and the geometry never change).
    assign upd_res[j*StoreW +: StoreW] = {co_out[j*CoxelW + CoxelW - 1],
                                          co_out[j*CoxelW +: 4*ChanW]};
  end

  assign upd_done = co_valid[0];

  // ---------------------------------------------------------------------------
  // Output: the base-plane image, or one error item
  // ---------------------------------------------------------------------------
  // The read-out's coxel: as the buffer holds it, or (DepthTest) after a Flush item through one
  // more compositing unit, which puts the geometry colour under the ray (compos.md, rule 2).
  logic                       ro_valid;
  logic [OutLanes*CoxelW-1:0] ro_cox, cb_full;
  always_comb begin
    for (int unsigned k = 0; k < OutLanes; k++) begin
      cb_full[k*CoxelW +: CoxelW] = full_coxel(cb_out_cox[k*StoreW +: StoreW], out_geo);
    end
  end
  if (DepthTest != 0) begin : gen_flush
    logic            fl_ready;
    logic [CInW-1:0] fl_in;
    assign fl_in        = {cube5_frame_pkg::ComposFlush, {ZW{1'b0}}, {RgbaW{1'b0}}, cb_full};
    assign cb_out_ready = fl_ready && state_q == StReadout;
    cube5_compos #(
      .ColorW (ColorW),
      .AlphaW (AlphaW),
      .ExtraW (ExtraW),
      .AccW   (AccW),
      .ZW     (ZW)
    ) u_flush (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (cb_out_valid && state_q == StReadout),
      .in_ready_o  (fl_ready),
      .in_data_i   (fl_in),
      .out_valid_o (ro_valid),
      .out_ready_i (out_ready_i),
      .out_data_o  (ro_cox),
      .cfg_valid_i (cfg_compos),
      .cfg_addr_i  (cfg_off[CoAddrW-1:0]),
      .cfg_data_i  (cfg_data_i[CoDataW-1:0])
    );
  end else begin : gen_no_flush
    assign cb_out_ready = out_ready_i && state_q == StReadout;
    assign ro_valid     = cb_out_valid;
    assign ro_cox       = cb_full;
  end

  logic error_item;
  assign error_item  = (state_q == StError);
  assign out_valid_o = error_item || (state_q == StReadout && ro_valid);
  logic [OutLanes*CoxelW-1:0] out_cox;
  assign out_cox     = error_item ? '0 : ro_cox;
  assign out_data_o  = {cycles_q, reads_q, error_item, out_cox};

  logic unused_top;
  assign unused_top = ^{co_ready, co_valid, co_out, cfg_data_i, cfg_off, unused_in};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_frame: output changed while stalled");
  ComposAlwaysReady: assert property (@(posedge clk_i) disable iff (!rst_ni)
      upd_valid |-> &co_ready)
    else $error("cube5_frame: a compositing unit was not ready");
  // The smallest-volume rule assumes the compositing unit's latency: check it on every item.
  logic [cube5_frame_pkg::ComposLatency-1:0] co_pipe_q;
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      co_pipe_q <= '0;
    end else begin
      co_pipe_q <= {co_pipe_q[cube5_frame_pkg::ComposLatency-2:0], upd_valid};
    end
  end
  ComposLatencyAsAssumed: assert property (@(posedge clk_i) disable iff (!rst_ni)
      co_valid[0] == co_pipe_q[cube5_frame_pkg::ComposLatency-1])
    else $error("cube5_frame: cube5_compos no longer has latency %0d; update ComposLatency in cube5_frame_pkg and the smallest-volume rule",
                cube5_frame_pkg::ComposLatency);
`endif

endmodule
