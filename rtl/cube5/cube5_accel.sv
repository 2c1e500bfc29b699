// cube5_accel: the Cube-5 accelerator top (issue 12; docs/accel.md). The volume in external memory,
// read over AXI4 as blocks; the base-plane image written back over AXI4; host control over
// AXI4-Lite with an interrupt.
//
//   host ── AXI4-Lite ──► cube5_accel_ctrl ── sweep ──► cube5_vol_fetch ── AR/R ──┐
//                              │ table port  ── section ─┐    │ items               │
//                              │ (Block: the fetch's LUT) ▼    ▼                     │
//                              │               cube5_section_buf (op 1, then op 0)   ├─ m_axi_*
//                              │ frame section ──► cube5_frame (Source = 1) ◄─ beams │
//                              │ (sec_first: frame registers through cfg first)      │
//                              │                     │ coxels ─► codes (RGBA, a byte each)
//                              └── row commands ──► cube5_axi_wr ── AW/W/B ──────────┘
//
// Three small sequencers join the control core's independent command ports to the units' single
// input streams: the fetch's input (a pending Block-table write, else the sweep), the buffer's
// input (a section command, then the fetch's items up to the sweep's last), and the frame's input
// (the frame registers through the configuration port on a frame's first section, the section
// command, then the buffer's beams up to the section's last). The frame's read-out (P pixels of a
// row per item, OutLanes = P) becomes 32-bit pixels, R, G, B, A each `min(2^ColorW - 1,
// (c (2^ColorW - 1) + 2^(AccW - 1)) >> AccW)` (docs/numerics/warp.md, "Base-plane codes", applied
// to all four channels), R in the lowest byte; P pixels per writer item where a bus beat holds
// them, else one beat's worth per item (each read-out item then takes 32 P / DataW writer items).
// Rows are written whole items at ImgBase + r ImgPitch (the core's row commands). The frame's done goes to the core with the first read-out item of a frame (once the
// last section's beams are in); the core ends the frame when every row's write has completed as
// well. After an error item of the frame (a section it refused) the writer is fed zero pixels.
`include "cube5_axi_ports.svh"

module cube5_accel #(
  /// Pipelines: voxels per beam (1, 2, 4, 8).
  parameter int unsigned P           = 4,
  /// Largest volume edge, a power of two.
  parameter int unsigned MaxDim      = 64,
  /// Voxel bits (the low bits of the 16-bit words in memory).
  parameter int unsigned VoxelW      = 12,
  /// Block edge of the volume's layout in memory.
  parameter int unsigned BlockDim    = 8,
  /// Section width in anchors (the section buffer's columns).
  parameter int unsigned Section     = 16,
  /// AXI4 byte address width and data width (one port: read channels for the volume, write
  /// channels for the image).
  parameter int unsigned AddrW       = 32,
  parameter int unsigned DataW       = 64,
  /// Longest burst in beats, reads and writes.
  parameter int unsigned MaxBurst    = 16,
  /// Read bursts in flight (the fetch's prefetch) and write bursts in flight.
  parameter int unsigned Outstanding = 8,
  parameter int unsigned WrOutstanding = 4,
  /// AXI4 ID width (the top issues ID 0 on both directions).
  parameter int unsigned IdW         = 4,
  /// The frame's widths (cube5_frame).
  parameter int unsigned WeightW     = 8,
  parameter int unsigned FracW       = 4,
  parameter int unsigned ClassIdxW   = 12,
  parameter int unsigned MagIdxW     = 4,
  parameter int unsigned MagShift    = 10,
  parameter int unsigned ColorW      = 8,
  parameter int unsigned AlphaW      = 12,
  parameter int unsigned RmLog2      = 3,
  parameter int unsigned RmFracW     = 4,
  parameter int unsigned DiffW       = 9,
  parameter int unsigned SpecW       = 8,
  parameter int unsigned ExtraW      = 4,
  parameter int unsigned AccW        = 20,
  parameter int unsigned ZW          = 12,
  /// 1: the frame's compositing window (cube5_frame Window = 1; docs/accel.md, *The compositing
  /// window in the top*): the frame keeps only a section's active rays, parks the others in a
  /// scratch area at ParkBase and restores them over this port (cube5_accel_win), and its final
  /// pixels are written during the sweep (no read-out); the image's rows are first written with
  /// the initial coxel's code. 0: the whole base plane on chip, read out after the sweep.
  parameter int unsigned Window      = 0,
  /// Window = 1: the window's write bursts in flight, and its restore reads in flight.
  parameter int unsigned WinOutstanding = 16,
  /// Window = 1: the depth of the window's AW and W FIFOs (cube5_accel_win), a power of two.
  parameter int unsigned WinWDepth   = 8,
  /// Window = 1: the frame's window descriptor FIFO depth (cube5_frame WinDescDepth).
  parameter int unsigned WinDescDepth = 32,
  /// Window = 1: the zero-park bit FIFO's depth (cube5_accel_win ZeroDepth; 0: MaxDim^2).
  parameter int unsigned WinZeroDepth = 0,
  /// Window = 1: 1 parks into a packed ring in park order, written and read in bursts of up to
  /// WinRingBurst beats (cube5_accel_win Ring; docs/numerics/compos_window.md, *The ring in
  /// park order*); 0: a slot per pixel, a burst per park and per restore.
  parameter int unsigned WinRing     = 0,
  parameter int unsigned WinRingBurst = 16,
  /// Window = 1: 0 writes each final pixel beat as a single-beat burst; else the final items'
  /// consecutive beats go out as bursts of up to WinFinBurst beats (cube5_accel_win FinBurst;
  /// docs/numerics/compos_window.md, *Final pixels in bursts*). The image is the same.
  parameter int unsigned WinFinBurst = 0,
  /// Window = 1: while the window's write beats wait, the fetch keeps at most FetchHold (+ 1)
  /// read bursts granted and not yet returned; 0: it starts none (docs/accel.md, *The
  /// compositing window in the top*).
  parameter int unsigned FetchHold   = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  // ---- AXI4-Lite subordinate: the host registers (docs/accel-regs.md) ----
  `CUBE5_AXIL_SUB_PORTS(s_axil_, 10),
  /// Level interrupt: |(IrqStatus & IrqEnable).
  output logic        irq_o,
  /// Sticky: some AXI4 response (R or B) since reset was not OKAY.
  output logic        err_o,

  // ---- AXI4 manager: the volume (AR, R) and the image (AW, W, B) ----
  `CUBE5_AXI4_MGR_PORTS(m_axi_, AddrW, DataW, IdW)
);

  // ---------------------------------------------------------------------------
  // Widths
  // ---------------------------------------------------------------------------
  localparam int unsigned M        = $clog2(MaxDim);
  localparam int unsigned DimW     = M + 1;
  localparam int unsigned NbW      = $clog2(MaxDim / BlockDim);
  // The fetch's items: two P-groups (the section buffer's ItemGroups = 2, its writer then keeps
  // up with the overlap columns) where a bus beat holds them and the fetch allows it, else one.
  localparam int unsigned SbG      = (DataW >= 32 * P && P <= 4) ? 2 : 1;
  localparam int unsigned Q        = SbG * P;             // voxels per fetch item
  localparam int unsigned WordW    = cube5_vol_fetch_pkg::word_w(Q, BlockDim);
  localparam int unsigned PixelBytes = 4;
  localparam int unsigned PixW     = 8 * PixelBytes;
  // The image writer's item: the read-out's P pixels, or a bus beat where that is narrower
  // (Pieces writer items per read-out item, L pixels each).
  localparam int unsigned FrPixW   = P * PixW;
  localparam int unsigned ItemW    = (FrPixW <= DataW) ? FrPixW : DataW;
  localparam int unsigned Pieces   = FrPixW / ItemW;
  localparam int unsigned PcW      = (Pieces > 1) ? $clog2(Pieces) : 1;
  localparam int unsigned LogL     = $clog2(ItemW / PixW);
  localparam int unsigned LenW     = 16;
  localparam int unsigned FeCmdW   = cube5_vol_fetch_pkg::cmd_w(AddrW, MaxDim, BlockDim);
  localparam int unsigned FeOutW   = cube5_vol_fetch_pkg::out_w(Q, VoxelW, MaxDim, BlockDim);
  localparam int unsigned SweepW   = AddrW + 5 * NbW + 7;
  localparam int unsigned LutW     = 6 * NbW + 2;
  localparam int unsigned SbInW    = cube5_section_buf_pkg::in_w(Q, VoxelW, MaxDim, BlockDim);
  localparam int unsigned SbOutW   = cube5_section_buf_pkg::out_w(P, VoxelW);
  localparam int unsigned SbCmdW   = 4 * M + 6;
  localparam int unsigned FrInW    = cube5_frame_pkg::in_w(1, P, VoxelW, M);
  localparam int unsigned FrLanes  = (Window != 0) ? 1 : P;   // the frame's read-out lanes
  localparam int unsigned FrOutW   = cube5_frame_pkg::out_lanes_w(FrLanes, AccW, ZW, ColorW);
  localparam int unsigned CoxelW   = cube5_frame_pkg::coxel_w(AccW, ZW, ColorW);
  localparam int unsigned FrSecW   = cube5_frame_pkg::sec_cmd_w(M);
  localparam int unsigned FrCmdW   = 7 * M + 51;
  localparam int unsigned BlkW     = cube5_skewmem_pkg::blk_w(M, BlockDim);
  localparam int unsigned ShAddrW  = cube5_shader_pkg::cfg_addr_w(ClassIdxW, RmLog2);
  localparam int unsigned ShDataW  = cube5_shader_pkg::cfg_data_w(ColorW, AlphaW, DiffW, SpecW);
  localparam int unsigned OffW     = cube5_frame_pkg::cfg_off_w(M, BlkW, ShAddrW, AlphaW);
  localparam int unsigned CfgAddrW = cube5_frame_pkg::CfgRegionW + OffW;
  localparam int unsigned CfgDataW = cube5_frame_pkg::cfg_data_w(M, VoxelW, BlkW, ShDataW, AccW);
  localparam int unsigned ChanW    = AccW + 1;
  // Fields of the streams (LSB first; docs/numerics/vol_fetch.md, section_buf.md).
  localparam int unsigned FeLastBit = Q * VoxelW + 3 * NbW + WordW + 1;
  localparam int unsigned SbLastBit = (P + 3) * VoxelW + 3;
  // Fields of the control core's frame command (docs/numerics/accel_ctrl.md).
  localparam int unsigned FcDims   = 0;
  localparam int unsigned FcView   = FcDims + 3 * DimW;
  localparam int unsigned FcDx     = FcView + 3;
  localparam int unsigned FcDy     = FcDx + 18;
  localparam int unsigned FcMode   = FcDy + 18;
  localparam int unsigned FcSkip   = FcMode + 4;
  localparam int unsigned FcA0     = FcSkip + 2 * DimW;
  localparam int unsigned FcNs     = FcA0 + M;
  localparam int unsigned FcFirst  = FcNs + DimW;
  localparam int unsigned FcLast   = FcFirst + 1;

  if (ColorW > 8) begin : gen_bad_color
    $fatal(1, "cube5_accel: ColorW must be at most 8 (a pixel is four byte codes)");
  end
  if (3 * NbW + 2 > 32) begin : gen_bad_lut
    $fatal(1, "cube5_accel: a block LUT entry must fit the 32-bit table window");
  end
  if (ShDataW > 64 || ChanW > 32 || 3 * DimW > 32) begin : gen_bad_cfg
    $fatal(1, "cube5_accel: a table entry must fit two words of the table window");
  end
  if (Section < 2 * P) begin : gen_bad_section
    $fatal(1, "cube5_accel: Section must be at least 2 P (the frame's rows hold two beats or more)");
  end
  if (Window > 1 || (Window != 0 && IdW < 2)) begin : gen_bad_window
    $fatal(1, "cube5_accel: Window must be 0 or 1, and Window = 1 needs IdW >= 2");
  end
  if (FcLast + 1 != FrCmdW) begin : gen_bad_fc
    $fatal(1, "cube5_accel: the frame command's fields do not add up");
  end

  // ---------------------------------------------------------------------------
  // The control core
  // ---------------------------------------------------------------------------
  logic              flush;        // the core's soft reset: drain the data path
  logic              drain_q;      // the AXI4 port is quiet: the units are reset this cycle
  logic              unit_rst_n;   // the units' reset: rst_ni, or the drain's one cycle
  assign unit_rst_n = rst_ni && !drain_q;

  logic              fc_valid, fc_ready;   // fetch sweep
  logic [SweepW-1:0] fc_data;
  logic              sc_valid, sc_ready;   // buffer section
  logic [SbCmdW-1:0] sc_data;
  logic              rc_valid, rc_ready;   // frame section (out of the slice below)
  logic [FrCmdW-1:0] rc_data;
  logic              cc_valid, cc_ready;   // frame section (the core's port)
  logic [FrCmdW-1:0] cc_data;
  logic              wc_valid, wc_ready;   // writer row
  logic [AddrW+LenW-1:0] wc_data;
  logic              done_valid, done_error;
  logic              cpl_valid;
  logic [17:0]       cpl_data;
  logic              tbl_valid;
  logic [3:0]        tbl_id;
  logic [15:0]       tbl_index;
  logic [31:0]       tbl_data;
  logic [AddrW-1:0]  img_base, row_step, park_base;
  logic [M+1:0]      row_pixels;

  cube5_accel_ctrl #(
    .P(P), .MaxDim(MaxDim), .BlockDim(BlockDim), .Section(Section), .AddrW(AddrW),
    .DataW(DataW), .PixelBytes(PixelBytes), .LenW(LenW), .Window(Window)
  ) u_ctrl (
    .clk_i, .rst_ni,
    .s_axil_awvalid_i, .s_axil_awready_o, .s_axil_awaddr_i, .s_axil_wvalid_i, .s_axil_wready_o,
    .s_axil_wdata_i, .s_axil_wstrb_i, .s_axil_bvalid_o, .s_axil_bready_i, .s_axil_bresp_o,
    .s_axil_arvalid_i, .s_axil_arready_o, .s_axil_araddr_i, .s_axil_rvalid_o, .s_axil_rready_i,
    .s_axil_rdata_o, .s_axil_rresp_o, .irq_o,
    .fetch_cmd_valid_o(fc_valid), .fetch_cmd_ready_i(fc_ready), .fetch_cmd_data_o(fc_data),
    .sbuf_cmd_valid_o(sc_valid), .sbuf_cmd_ready_i(sc_ready), .sbuf_cmd_data_o(sc_data),
    .frame_cmd_valid_o(cc_valid), .frame_cmd_ready_i(cc_ready), .frame_cmd_data_o(cc_data),
    .wr_cmd_valid_o(wc_valid), .wr_cmd_ready_i(wc_ready), .wr_cmd_data_o(wc_data),
    .frame_done_valid_i(done_valid), .frame_done_error_i(done_error),
    .wr_cpl_valid_i(cpl_valid), .wr_cpl_resp_i(cpl_data[1:0]),
    .flush_o(flush), .drained_i(drain_q),
    .table_valid_o(tbl_valid), .table_id_o(tbl_id), .table_index_o(tbl_index),
    .table_data_o(tbl_data),
    .img_base_o(img_base), .row_step_o(row_step), .park_base_o(park_base),
    .row_pixels_o(row_pixels)
  );

  // The frame's section commands pass a two-entry register slice (valid, data and ready from
  // flip-flops): the frame's input ready, which follows the compositing window's admission and
  // the section buffer's beams, reaches the core's hold and section count only through a
  // register (docs/accel.md, *Synthesis*). One cycle of latency per command, while the frame
  // still sweeps the section before. Reset with the units (a drain drops what it holds).
  cube5_axi_slice #(.Width(FrCmdW)) u_rc_slice (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(cc_valid), .in_ready_o(cc_ready), .in_data_i(cc_data),
    .out_valid_o(rc_valid), .out_ready_i(rc_ready), .out_data_o(rc_data)
  );

  // ---------------------------------------------------------------------------
  // Table writes: Block to the fetch's LUT; Class, Reflect, Opacity to the frame's
  // configuration port. Each waits in a one-entry register until its unit takes it (the host's
  // AXI4-Lite writes are several cycles apart).
  // ---------------------------------------------------------------------------
  logic             blk_pend_q;
  logic [LutW-1:0]  blk_q;          // {masked, empty, ptr, index}
  logic             tcfg_pend_q;
  logic [CfgAddrW-1:0] tcfg_addr_q;
  logic [CfgDataW-1:0] tcfg_data_q;
  logic [31:0]      class_lo_q;     // the low word of a classification entry
  logic             fe_in_ready;
  logic             seq_we;         // the frame-register sequencer writes this cycle

  // The shader's address of a table entry: Class entries at region 0 (two words each, low first),
  // Reflect's index i at the shader's address 2^(ShAddrW - 2) + i (its texels, then the
  // zero-gradient entry); Opacity's index is the compositing unit's address.
  logic [ShAddrW-1:0] sh_addr;
  always_comb begin
    if (tbl_id == cube5_accel_regs_pkg::TableClass) begin
      sh_addr = ShAddrW'(tbl_index[15:1]);
    end else begin
      sh_addr = ShAddrW'(32'(tbl_index) + (32'd1 << (ShAddrW - 2)));
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      blk_pend_q  <= 1'b0;
      tcfg_pend_q <= 1'b0;
    end else begin
      if (blk_pend_q && fe_in_ready) blk_pend_q <= 1'b0;
      if (tcfg_pend_q && !seq_we) tcfg_pend_q <= 1'b0;
      if (tbl_valid) begin
        unique case (tbl_id)
          cube5_accel_regs_pkg::TableBlock: begin
            blk_pend_q <= 1'b1;
            blk_q      <= {tbl_data[3*NbW+1:0], (3*NbW)'(tbl_index)};
          end
          cube5_accel_regs_pkg::TableClass: begin
            if (!tbl_index[0]) begin
              class_lo_q <= tbl_data;
            end else begin
              tcfg_pend_q <= 1'b1;
              tcfg_addr_q <= {cube5_frame_pkg::CfgRegionShader, OffW'(sh_addr)};
              tcfg_data_q <= CfgDataW'({tbl_data, class_lo_q});
            end
          end
          cube5_accel_regs_pkg::TableReflect: begin
            tcfg_pend_q <= 1'b1;
            tcfg_addr_q <= {cube5_frame_pkg::CfgRegionShader, OffW'(sh_addr)};
            tcfg_data_q <= CfgDataW'(tbl_data);
          end
          cube5_accel_regs_pkg::TableOpacity: begin
            tcfg_pend_q <= 1'b1;
            tcfg_addr_q <= {cube5_frame_pkg::CfgRegionCompos, OffW'(tbl_index)};
            tcfg_data_q <= CfgDataW'(tbl_data);
          end
          default: ;
        endcase
      end
    end
  end

  // ---------------------------------------------------------------------------
  // The fetch: a pending LUT write first, else the core's sweep.
  // ---------------------------------------------------------------------------
  logic              fe_arvalid, fe_arready;   // the fetch's AR handshake, before the drain's gate
  logic              wr_awvalid, wr_awready, wr_wvalid, wr_wready;  // the writer's AW and W
  // The fetch's AR and R, and the writer's AW, W and B, before the window's arbiters (Window = 1)
  // or wired straight to the port (Window = 0).
  logic [AddrW-1:0]   fe_araddr, wr_awaddr;
  logic [7:0]         fe_arlen, wr_awlen;
  logic [2:0]         fe_arsize, wr_awsize;
  logic [1:0]         fe_arburst, wr_awburst;
  logic [IdW-1:0]     fe_arid, wr_awid;
  logic               fe_rvalid, fe_rready, wr_bvalid, wr_bready, wr_wlast;
  logic [DataW-1:0]   wr_wdata;
  logic [DataW/8-1:0] wr_wstrb;
  logic              fe_in_valid;
  logic [FeCmdW-1:0] fe_in_data;
  logic              fe_out_valid, fe_out_ready;
  logic [FeOutW-1:0] fe_out_data;
  logic              fe_err;

  // The core's sweep commands pass a two-entry register slice: the core's section arithmetic
  // (the anchor, the section's block range) and the fetch's sweep checks meet at flip-flops
  // (docs/accel.md, *Synthesis*). One cycle of latency per command.
  logic              fs_valid, fs_ready;
  logic [SweepW-1:0] fs_data;
  cube5_axi_slice #(.Width(SweepW)) u_fc_slice (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(fc_valid), .in_ready_o(fc_ready), .in_data_i(fc_data),
    .out_valid_o(fs_valid), .out_ready_i(fs_ready), .out_data_o(fs_data)
  );

  assign fe_in_valid = blk_pend_q || fs_valid;
  assign fe_in_data  = blk_pend_q ? FeCmdW'({blk_q, 1'b0}) : FeCmdW'({fs_data, 1'b1});
  assign fs_ready    = fe_in_ready && !blk_pend_q;

  cube5_vol_fetch #(
    .AddrW(AddrW), .DataW(DataW), .P(Q), .VoxelW(VoxelW), .MaxDim(MaxDim), .BlockDim(BlockDim),
    .MaxBurst(MaxBurst), .Outstanding(Outstanding), .IdW(IdW)
  ) u_fetch (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(fe_in_valid), .in_ready_o(fe_in_ready), .in_data_i(fe_in_data),
    .out_valid_o(fe_out_valid), .out_ready_i(fe_out_ready), .out_data_o(fe_out_data),
    .err_o(fe_err),
    .m_axi_araddr_o(fe_araddr), .m_axi_arlen_o(fe_arlen), .m_axi_arsize_o(fe_arsize),
    .m_axi_arburst_o(fe_arburst), .m_axi_arid_o(fe_arid),
    .m_axi_arvalid_o(fe_arvalid), .m_axi_arready_i(fe_arready), .m_axi_rdata_i, .m_axi_rresp_i, .m_axi_rlast_i,
    .m_axi_rid_i, .m_axi_rvalid_i(fe_rvalid), .m_axi_rready_o(fe_rready)
  );

  // ---------------------------------------------------------------------------
  // The section buffer: a section command (op 1), then the fetch's items of its sweep (op 0) up
  // to the item marked last.
  // ---------------------------------------------------------------------------
  logic             sb_items_q;     // passing the fetch's items
  logic             sb_in_valid, sb_in_ready;
  logic [SbInW-1:0] sb_in_data;
  logic             sb_rs_valid, sb_rs_ready;   // the same items past the register slice
  logic [SbInW-1:0] sb_rs_data;
  logic             sb_out_valid, sb_out_ready;
  logic [SbOutW-1:0] sb_out_data;

  assign sb_in_valid  = sb_items_q ? fe_out_valid : sc_valid;
  assign sb_in_data   = sb_items_q ? SbInW'({fe_out_data, 1'b0}) : SbInW'({sc_data, 1'b1});
  assign fe_out_ready = sb_items_q && sb_in_ready;
  assign sc_ready     = !sb_items_q && sb_in_ready;

  always_ff @(posedge clk_i) begin
    if (!unit_rst_n) begin
      sb_items_q <= 1'b0;
    end else if (sb_in_valid && sb_in_ready) begin
      sb_items_q <= sb_items_q ? !fe_out_data[FeLastBit] : 1'b1;
    end
  end

  // The buffer's input passes a two-entry register slice: the fetch's items leave the AXI read
  // FIFO's block RAM (whose unregistered output takes 5.6 ns on the ECP5) and its word mux, and
  // the buffer's command arithmetic starts from flip-flops; the buffer's ready reaches the fetch
  // through a register (docs/accel.md, *Synthesis*). One cycle of latency, full throughput.
  cube5_axi_slice #(.Width(SbInW)) u_sb_slice (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(sb_in_valid), .in_ready_o(sb_in_ready), .in_data_i(sb_in_data),
    .out_valid_o(sb_rs_valid), .out_ready_i(sb_rs_ready), .out_data_o(sb_rs_data)
  );

  cube5_section_buf #(
    .P(P), .VoxelW(VoxelW), .MaxDim(MaxDim), .BlockDim(BlockDim), .Section(Section),
    .ItemGroups(SbG)
  ) u_sbuf (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(sb_rs_valid), .in_ready_o(sb_rs_ready), .in_data_i(sb_rs_data),
    .out_valid_o(sb_out_valid), .out_ready_i(sb_out_ready), .out_data_o(sb_out_data)
  );

  // ---------------------------------------------------------------------------
  // The frame: on a frame's first section its six registers through the configuration port,
  // then the section command, then the buffer's beams up to the section's last.
  // ---------------------------------------------------------------------------
  typedef enum logic [1:0] {FrIdle, FrRegs, FrCmd, FrBeams} fr_state_e;
  fr_state_e          fr_q;
  logic [2:0]         reg_q;        // the register being written
  logic               fr_in_valid, fr_in_ready;
  logic [FrInW-1:0]   fr_in_data;
  logic               fr_rs_valid, fr_rs_ready;   // the same items past the register slice
  logic [FrInW-1:0]   fr_rs_data;
  logic               fr_out_valid, fr_out_ready;
  logic [FrOutW-1:0]  fr_out_data;
  logic               fr_error;     // the frame's output item is its error item
  logic               cfg_valid;
  logic [CfgAddrW-1:0] cfg_addr;
  logic [CfgDataW-1:0] cfg_data;
  logic [CfgDataW-1:0] reg_word;
  logic [FrSecW-1:0]  sec_cmd;
  logic               readout_q;    // a frame started and its first pixel not yet out

  always_comb begin
    unique case (reg_q)
      3'd0:    reg_word = CfgDataW'(rc_data[FcDims +: 3*DimW]);
      3'd1:    reg_word = CfgDataW'(rc_data[FcView +: 3]);
      3'd2:    reg_word = CfgDataW'(rc_data[FcDx +: 18]);
      3'd3:    reg_word = CfgDataW'(rc_data[FcDy +: 18]);
      3'd4:    reg_word = CfgDataW'(rc_data[FcMode +: 4]);   // render, tf2d
      default: reg_word = CfgDataW'(rc_data[FcSkip +: 2*DimW]);
    endcase
  end

  assign seq_we    = fr_q == FrRegs;
  assign cfg_valid = seq_we || tcfg_pend_q;
  assign cfg_addr  = seq_we ? {cube5_frame_pkg::CfgRegionFrame, OffW'(reg_q)} : tcfg_addr_q;
  assign cfg_data  = seq_we ? reg_word : tcfg_data_q;

  // {op 0 (render), sec_a0, sec_ns, sec_first, sec_last}, LSB first.
  assign sec_cmd = {rc_data[FcLast], rc_data[FcFirst], rc_data[FcNs +: DimW],
                    rc_data[FcA0 +: M], 2'b00};

  assign fr_in_valid  = (fr_q == FrCmd && rc_valid) || (fr_q == FrBeams && sb_out_valid);
  assign fr_in_data   = fr_q == FrBeams ? FrInW'({sb_out_data, cube5_frame_pkg::InKindBeat})
                                        : FrInW'({sec_cmd, cube5_frame_pkg::InKindCmd});
  assign sb_out_ready = fr_q == FrBeams && fr_in_ready;
  assign rc_ready     = fr_q == FrCmd && fr_in_ready;

  always_ff @(posedge clk_i) begin
    if (!unit_rst_n) begin
      fr_q      <= FrIdle;
      reg_q     <= 3'd0;
      readout_q <= 1'b0;
    end else begin
      unique case (fr_q)
        FrIdle: begin
          if (rc_valid) begin
            reg_q <= 3'd0;
            fr_q  <= rc_data[FcFirst] ? FrRegs : FrCmd;
          end
        end
        FrRegs: begin
          reg_q <= reg_q + 3'd1;
          if (reg_q == 3'(cube5_frame_pkg::RegSkip)) fr_q <= FrCmd;
        end
        FrCmd: begin
          if (rc_valid && fr_in_ready) begin
            fr_q <= FrBeams;
            if (rc_data[FcFirst]) readout_q <= 1'b1;
          end
        end
        default: begin
          if (sb_out_valid && fr_in_ready && sb_out_data[SbLastBit]) fr_q <= FrIdle;
        end
      endcase
      if ((fr_out_valid && fr_out_ready) || win_end) readout_q <= 1'b0;
    end
  end

  localparam int unsigned WinKeyW = 2 * ($clog2(MaxDim) + 1);
  localparam int unsigned WinCoxW = 4 * (AccW + 1) + 1;
  logic                 win_park_valid, win_fin_valid, win_rq_valid, win_rs_ready;
  logic                 win_park_ready, win_fin_ready, win_rq_ready, win_rs_valid;
  logic [WinKeyW-1:0]   win_park_key, win_fin_key, win_rq_key;
  logic [WinCoxW-1:0]   win_park_cox, win_rs_cox;
  logic                 win_idle, win_err;     // Window = 1: cube5_accel_win drained; its errors
  logic                 win_end;               // Window = 1: the frame's window traffic is done
  logic [P-1:0]         win_fin_mask;
  logic [P*WinCoxW-1:0] win_fin_cox;

  // The frame's input passes a two-entry register slice: the section buffer's read-out and the
  // frame's admission (its ready follows the compositing window's flags and its state) meet only
  // at flip-flops, and the frame's beat take starts from a registered valid and beam
  // (docs/accel.md, *Synthesis*). One cycle of latency, full throughput.
  cube5_axi_slice #(.Width(FrInW)) u_fr_slice (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(fr_in_valid), .in_ready_o(fr_in_ready), .in_data_i(fr_in_data),
    .out_valid_o(fr_rs_valid), .out_ready_i(fr_rs_ready), .out_data_o(fr_rs_data)
  );

  cube5_frame #(
    .P(P), .MaxDim(MaxDim), .VoxelW(VoxelW), .WeightW(WeightW), .FracW(FracW),
    .BlockDim(BlockDim), .ClassIdxW(ClassIdxW), .MagIdxW(MagIdxW), .MagShift(MagShift),
    .ColorW(ColorW), .AlphaW(AlphaW), .RmLog2(RmLog2), .RmFracW(RmFracW), .DiffW(DiffW),
    .SpecW(SpecW), .ExtraW(ExtraW), .AccW(AccW), .ZW(ZW), .Shade(1), .Source(1),
    .OutLanes(FrLanes), .MaxSection(Section), .Window(Window), .WinDescDepth(WinDescDepth)
  ) u_frame (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(fr_rs_valid), .in_ready_o(fr_rs_ready), .in_data_i(fr_rs_data),
    .out_valid_o(fr_out_valid), .out_ready_i(fr_out_ready), .out_data_o(fr_out_data),
    .cfg_valid_i(cfg_valid), .cfg_addr_i(cfg_addr), .cfg_data_i(cfg_data),
    // The compositing-window streams: cube5_accel_win (Window = 1), else idle.
    .park_valid_o(win_park_valid), .park_ready_i(win_park_ready), .park_key_o(win_park_key),
    .park_cox_o(win_park_cox),
    .fin_valid_o(win_fin_valid), .fin_ready_i(win_fin_ready), .fin_key_o(win_fin_key),
    .fin_mask_o(win_fin_mask), .fin_cox_o(win_fin_cox),
    .rq_valid_o(win_rq_valid), .rq_ready_i(win_rq_ready), .rq_key_o(win_rq_key),
    .rs_valid_i(win_rs_valid), .rs_ready_o(win_rs_ready), .rs_cox_i(win_rs_cox)
  );

  // The frame's done: its first read-out item (or its error item), passed on once the beams of
  // the frame's last section are all in (at once for a read-out, which follows them; an error
  // item can come before them), so that the frame never ends while the data path still streams.
  logic cur_last_q;   // the section being passed is the frame's last
  logic last_in_q;    // the last section's beams are all in
  logic done_pend_q, done_err_q;
  logic done_ev;

  // Window = 1: no read-out; the frame is done once its last section's sweep is over (the frame
  // idle again), the window's streams are empty and their traffic has drained (every B and R in).
  // The frame is idle when the slice is empty and the frame is ready: with every beat of the
  // last section inside it, it is ready for a beat or a command only in its idle state.
  assign win_end    = Window != 0 && readout_q && last_in_q && fr_q == FrIdle && !fr_rs_valid
                      && fr_rs_ready && !win_park_valid && !win_fin_valid && win_idle;
  assign done_ev    = (fr_out_valid && fr_out_ready && readout_q) || win_end;
  assign done_valid = (done_ev || done_pend_q) && last_in_q && (Window == 0 || win_idle);
  assign done_error = done_pend_q ? done_err_q : fr_error && fr_out_valid;

  always_ff @(posedge clk_i) begin
    if (!unit_rst_n) begin
      cur_last_q  <= 1'b0;
      last_in_q   <= 1'b0;
      done_pend_q <= 1'b0;
      done_err_q  <= 1'b0;
    end else begin
      if (fr_q == FrCmd && rc_valid && fr_in_ready) begin
        cur_last_q <= rc_data[FcLast];
        if (rc_data[FcFirst]) last_in_q <= 1'b0;
      end
      if (fr_q == FrBeams && sb_out_valid && fr_in_ready && sb_out_data[SbLastBit] && cur_last_q) begin
        last_in_q <= 1'b1;
      end
      if (done_valid) begin
        done_pend_q <= 1'b0;
      end else if (done_ev) begin
        done_pend_q <= 1'b1;
        done_err_q  <= fr_error && fr_out_valid;
      end
    end
  end

  // ---------------------------------------------------------------------------
  // Coxels to pixels: four codes per lane, one register stage; then the register's P pixels to
  // the writer as Pieces items (one when they fit a bus beat).
  // ---------------------------------------------------------------------------
  logic              pix_valid_q;
  logic [FrPixW-1:0] pix_q, pix_d;
  logic              wr_dat_ready;
  logic [PcW-1:0]    piece_q;       // the writer item of pix_q that goes next
  logic              last_piece;
  logic [ItemW-1:0]  pix_piece;

  // The read-out's P coxels (Window = 0; with the window the frame's output carries error items
  // only and the final pixels take cube5_accel_win's conversion).
  logic [P*CoxelW-1:0] fr_cox;
  if (Window != 0) begin : gen_no_readout
    assign fr_cox = '0;
  end else begin : gen_readout
    assign fr_cox = fr_out_data[P*CoxelW-1:0];
  end

  for (genvar k = 0; k < P; k++) begin : gen_lane
    cube5_accel_pix #(.AccW(AccW), .ColorW(ColorW)) u_pix (
      .cox_i(fr_cox[k*CoxelW +: 4*ChanW]), .pix_o(pix_d[k*PixW +: PixW])
    );
  end

  if (Pieces > 1) begin : gen_pieces
    assign last_piece = piece_q == PcW'(Pieces - 1);
    always_comb begin
      pix_piece = pix_q[ItemW-1:0];
      for (int unsigned n = 1; n < Pieces; n++) begin
        if (piece_q == PcW'(n)) pix_piece = pix_q[n*ItemW +: ItemW];
      end
    end
  end else begin : gen_one_piece
    assign last_piece = 1'b1;
    assign pix_piece  = pix_q;
  end

  // After an error item of the frame (a section it refused) the frame's output is dropped and
  // the writer gets zero pixels for every pixel of the rows the core has commanded, so that the
  // frame ends (with IrqStatus.error, code Frame) instead of waiting for pixels that never come;
  // the next frame's first section ends it. `owed_q`: writer items commanded minus handed over.
  localparam int unsigned OwedW = 2 * DimW + 3;
  logic                    flush_q;
  logic signed [OwedW-1:0] owed_q;
  logic                    wr_dat_valid;
  logic [ItemW-1:0]        wr_dat;
  logic                    clear_ok_q;    // Window = 1: the frame's mode is known (init_pix_q)
  logic [PixW-1:0]         init_pix_q;    // Window = 1: the initial coxel's pixel
  logic [M+1:0]            rows_done_q;   // Window = 1: the clear's rows completed this frame

  // The initial coxel (cube5_frame: zeros, A = all ones for MinIP) as a pixel: its codes.
  always_ff @(posedge clk_i) begin
    if (!unit_rst_n) begin
      clear_ok_q  <= 1'b0;
      rows_done_q <= '0;
    end else if (fr_q == FrIdle && rc_valid && rc_data[FcFirst]) begin
      clear_ok_q  <= 1'b1;
      rows_done_q <= '0;
    end else begin
      rows_done_q <= rows_done_q + (M+2)'(cpl_valid);
    end
  end
  always_ff @(posedge clk_i) begin
    if (fr_q == FrIdle && rc_valid && rc_data[FcFirst]) begin
      init_pix_q <= (rc_data[FcMode +: 3] == 3'(cube5_frame_pkg::RenderMinip))
                    ? PixW'(((1 << ColorW) - 1) << 24) : '0;
    end
  end

  logic [LenW-1:0]         wc_items;  // a row command's writer items
  assign wc_items     = wc_data[AddrW +: LenW] >> LogL;
  assign fr_error     = fr_out_data[FrLanes*CoxelW];
  assign fr_out_ready = flush_q || !pix_valid_q || (wr_dat_ready && last_piece);
  // Window = 1: the writer's rows are the image's clear, every item the initial coxel's pixels.
  assign wr_dat_valid = (Window != 0) ? clear_ok_q && owed_q > 0
                                      : flush_q ? owed_q > 0 : pix_valid_q;
  assign wr_dat       = (Window != 0) ? {(ItemW/PixW){init_pix_q}}
                                      : flush_q ? '0 : pix_piece;

  always_ff @(posedge clk_i) begin
    if (!unit_rst_n) begin
      pix_valid_q <= 1'b0;
      piece_q     <= '0;
      flush_q     <= 1'b0;
      owed_q      <= '0;
    end else begin
      if (!flush_q && pix_valid_q && wr_dat_ready) piece_q <= last_piece ? '0 : piece_q + PcW'(1);
      if (fr_out_ready) begin
        pix_valid_q <= fr_out_valid && !flush_q && !fr_error;
        if (fr_out_valid) pix_q <= pix_d;
      end
      if (fr_out_valid && fr_out_ready && fr_error) begin
        flush_q     <= 1'b1;
        pix_valid_q <= 1'b0;
        piece_q     <= '0;
      end
      if (fr_q == FrCmd && rc_valid && fr_in_ready && rc_data[FcFirst]) flush_q <= 1'b0;
      owed_q <= owed_q + ((wc_valid && wc_ready) ? OwedW'(wc_items) : '0)
                       - OwedW'(wr_dat_valid && wr_dat_ready);
    end
  end

  // ---------------------------------------------------------------------------
  // The image writer: the core's row commands {addr, pixels} in writer items.
  // ---------------------------------------------------------------------------
  // Window = 0: a row goes to the writer only once the frame has taken the frame's last section.
  // The core's `gidx == nsec` counts the slice's takes (u_rc_slice), so the row waits while the
  // slice still holds a section: once the core has offered them all no command enters it again,
  // and the first cycle it is empty is the one the core saw before the slice. (Without this, a
  // frame of one or two sections commands its rows while the slice holds them and the frame has
  // not taken its first, so an error flush left over from a refused frame fills them with zeros.)
  logic wr_err;
  logic wc_open, wc_in_valid, wc_in_ready;
  logic [AddrW+LenW-1:0] wr_cmd;
  assign wr_cmd      = {wc_items, wc_data[AddrW-1:0]};
  assign wc_open     = Window != 0 || !rc_valid;
  assign wc_in_valid = wc_valid && wc_open;
  assign wc_ready    = wc_in_ready && wc_open;

  cube5_axi_wr #(
    .AddrW(AddrW), .DataW(DataW), .ItemW(ItemW), .LenW(LenW), .MaxBurst(MaxBurst),
    .Outstanding(WrOutstanding), .IdW(IdW)
  ) u_wr (
    .clk_i, .rst_ni(unit_rst_n),
    .in_valid_i(wc_in_valid), .in_ready_o(wc_in_ready), .in_data_i(wr_cmd),
    .dat_valid_i(wr_dat_valid), .dat_ready_o(wr_dat_ready), .dat_data_i(wr_dat),
    .out_valid_o(cpl_valid), .out_ready_i(1'b1), .out_data_o(cpl_data),
    .err_o(wr_err),
    .m_axi_awaddr_o(wr_awaddr), .m_axi_awlen_o(wr_awlen), .m_axi_awsize_o(wr_awsize),
    .m_axi_awburst_o(wr_awburst), .m_axi_awid_o(wr_awid),
    .m_axi_awvalid_o(wr_awvalid), .m_axi_awready_i(wr_awready), .m_axi_wdata_o(wr_wdata),
    .m_axi_wstrb_o(wr_wstrb), .m_axi_wlast_o(wr_wlast), .m_axi_wvalid_o(wr_wvalid),
    .m_axi_wready_i(wr_wready), .m_axi_bresp_i, .m_axi_bid_i, .m_axi_bvalid_i(wr_bvalid),
    .m_axi_bready_o(wr_bready)
  );

  assign err_o = fe_err || wr_err || win_err;

  // ---------------------------------------------------------------------------
  // The port's channels before the drain's gates. Window = 0: the fetch's AR and R, the writer's
  // AW, W and B. Window = 1: cube5_accel_win beside them: AR shared with the fetch (restores, ID
  // 1), AW shared with the writer (parks ID 1, final pixels ID 2), W in the order of the accepted
  // AWs, R and B returned by ID (0: the fetch's and the writer's).
  // ---------------------------------------------------------------------------
  logic ar_valid, ar_ready, aw_valid, aw_ready, w_valid, w_ready;

  if (Window != 0) begin : gen_win
    localparam int unsigned WinOrdDepth = 1 << $clog2(WrOutstanding + WinOutstanding + 2);
    logic [AddrW-1:0]   v_awaddr, v_araddr;
    logic [7:0]         v_awlen, v_arlen;
    logic [IdW-1:0]     v_awid;
    logic               v_awvalid, v_awready, v_wvalid, v_wready, v_wlast, v_bvalid;
    logic               v_arvalid, v_arready, v_rvalid, v_rready;
    logic [DataW-1:0]   v_wdata;
    logic [DataW/8-1:0] v_wstrb;
    logic               r_win, b_win;
    logic               v_wait;       // the window's write beats wait: no new volume read

    cube5_accel_win #(
      .P(P), .DimW(M + 1), .AddrW(AddrW), .DataW(DataW), .IdW(IdW), .AccW(AccW),
      .ColorW(ColorW), .Outstanding(WinOutstanding), .WDepth(WinWDepth),
      .ZeroDepth(WinZeroDepth), .Ring(WinRing), .RingBurst(WinRingBurst),
      .FinBurst(WinFinBurst)
    ) u_win (
      .clk_i, .rst_ni(unit_rst_n),
      .img_base_i(img_base), .row_step_i(row_step), .park_base_i(park_base),
      .row_pixels_i(row_pixels), .rows_done_i(rows_done_q),
      .frame_start_i(fr_q == FrIdle && rc_valid && rc_data[FcFirst]),
      // nj: the volume's z extent, y when the slices are along z (i, j ascending)
      .park_rows_i(rc_data[FcView +: 2] == 2'd2 ? rc_data[FcDims + DimW +: DimW]
                                                : rc_data[FcDims + 2*DimW +: DimW]),
      .park_valid_i(win_park_valid), .park_ready_o(win_park_ready), .park_key_i(win_park_key),
      .park_cox_i(win_park_cox),
      .fin_valid_i(win_fin_valid), .fin_ready_o(win_fin_ready), .fin_key_i(win_fin_key),
      .fin_mask_i(win_fin_mask), .fin_cox_i(win_fin_cox),
      .rq_valid_i(win_rq_valid), .rq_ready_o(win_rq_ready), .rq_key_i(win_rq_key),
      .rs_valid_o(win_rs_valid), .rs_ready_i(win_rs_ready), .rs_cox_o(win_rs_cox),
      .awaddr_o(v_awaddr), .awlen_o(v_awlen), .awid_o(v_awid), .awvalid_o(v_awvalid),
      .awready_i(v_awready), .wdata_o(v_wdata), .wstrb_o(v_wstrb), .wlast_o(v_wlast),
      .wvalid_o(v_wvalid), .wready_i(v_wready),
      .bvalid_i(v_bvalid), .bid_i(m_axi_bid_i), .bresp_i(m_axi_bresp_i),
      .araddr_o(v_araddr), .arlen_o(v_arlen), .arvalid_o(v_arvalid), .arready_i(v_arready),
      .rvalid_i(v_rvalid), .rdata_i(m_axi_rdata_i), .rresp_i(m_axi_rresp_i),
      .rlast_i(m_axi_rlast_i), .rready_o(v_rready),
      .wr_wait_o(v_wait), .idle_o(win_idle), .err_o(win_err)
    );

    // AR: the fetch (source 0) or a restore (source 1); AW: the writer (the clear, source 0) or
    // the window (source 1). A source keeps the channel while its address waits (no valid is
    // withdrawn), else they alternate (cube5_axi_arb). The fetch starts no new read while the
    // window's write beats wait (v_wait): the memory serves reads first, and a fetch that keeps
    // its bursts queued would starve the parks (docs/accel.md, *The compositing window in the
    // top*, What limits it). Each arbiter's grant goes into a two-entry register slice
    // (cube5_axi_slice), so the port's AR and AW leave from flip-flops and no source's ready
    // depends on the port's ready or on the other source's offer in the same cycle.
    localparam int unsigned ArbW = AddrW + 8 + 3 + 2 + IdW;
    localparam logic [2:0] BeatSize = 3'($clog2(DataW / 8));
    logic            ar_sel, aw_sel;   // 1: the window's (into the slice)
    logic            aw_sel_out;       // the source of the AW the slice offers on the port
    logic            ar_g_valid, ar_g_ready, aw_g_valid, aw_g_ready;
    logic [ArbW-1:0] ar_g_data, aw_g_data;
    logic fe_allow;   // the fetch may be granted while the window's write beats wait
    if (FetchHold != 0) begin : gen_fe_hold
      // The fetch's read bursts granted (into the AR slice) whose last beat is not in; the flag
      // from the count a cycle before (so at most FetchHold + 1 of them).
      localparam int unsigned FeHoldW = $clog2(Outstanding + FetchHold + 2) + 1;
      logic [FeHoldW-1:0] fe_out_q, fe_out_d;
      logic               fe_allow_q, fe_allow_d;
      assign fe_out_d   = fe_out_q + FeHoldW'(fe_arvalid && fe_arready)
                                   - FeHoldW'(fe_rvalid && fe_rready && m_axi_rlast_i);
      assign fe_allow_d = fe_out_q < FeHoldW'(FetchHold);
      always_ff @(posedge clk_i) begin
        if (!unit_rst_n) begin
          fe_out_q   <= '0;
          fe_allow_q <= 1'b0;
        end else begin
          fe_out_q   <= fe_out_d;
          fe_allow_q <= fe_allow_d;
        end
      end
      assign fe_allow = fe_allow_q;
    end else begin : gen_fe_stop
      assign fe_allow = 1'b0;
    end
    cube5_axi_arb #(.Width(ArbW)) u_ar_arb (
      .clk_i, .rst_ni(unit_rst_n),
      .s0_allow_i(!v_wait || fe_allow), .s0_valid_i(fe_arvalid), .s0_ready_o(fe_arready),
      .s0_data_i({fe_araddr, fe_arlen, fe_arsize, fe_arburst, fe_arid}),
      .s1_valid_i(v_arvalid), .s1_ready_o(v_arready),
      .s1_data_i({v_araddr, v_arlen, BeatSize, 2'b01, IdW'(1)}),
      .valid_o(ar_g_valid), .ready_i(ar_g_ready), .data_o(ar_g_data), .sel_o(ar_sel)
    );
    cube5_axi_slice #(.Width(ArbW)) u_ar_slice (
      .clk_i, .rst_ni(unit_rst_n),
      .in_valid_i(ar_g_valid), .in_ready_o(ar_g_ready), .in_data_i(ar_g_data),
      .out_valid_o(ar_valid), .out_ready_i(ar_ready),
      .out_data_o({m_axi_araddr_o, m_axi_arlen_o, m_axi_arsize_o, m_axi_arburst_o, m_axi_arid_o})
    );
    cube5_axi_arb #(.Width(ArbW)) u_aw_arb (
      .clk_i, .rst_ni(unit_rst_n),
      .s0_allow_i(1'b1), .s0_valid_i(wr_awvalid), .s0_ready_o(wr_awready),
      .s0_data_i({wr_awaddr, wr_awlen, wr_awsize, wr_awburst, wr_awid}),
      .s1_valid_i(v_awvalid), .s1_ready_o(v_awready),
      .s1_data_i({v_awaddr, v_awlen, BeatSize, 2'b01, v_awid}),
      .valid_o(aw_g_valid), .ready_i(aw_g_ready), .data_o(aw_g_data), .sel_o(aw_sel)
    );
    // The AW slice carries the source beside the address: W follows the port's accepted AWs.
    cube5_axi_slice #(.Width(ArbW + 1)) u_aw_slice (
      .clk_i, .rst_ni(unit_rst_n),
      .in_valid_i(aw_g_valid), .in_ready_o(aw_g_ready), .in_data_i({aw_sel, aw_g_data}),
      .out_valid_o(aw_valid), .out_ready_i(aw_ready),
      .out_data_o({aw_sel_out, m_axi_awaddr_o, m_axi_awlen_o, m_axi_awsize_o, m_axi_awburst_o,
                   m_axi_awid_o})
    );

    // W: the bursts' beats in the order their AWs were accepted (a FIFO of sources).
    logic ord_empty, ord_full, ord_head, w_fire_last;
    cube5_frame_fifo #(.Width(1), .Depth(WinOrdDepth)) u_ord (
      .clk_i, .rst_ni(unit_rst_n), .clear_i(1'b0),
      .push_i(m_axi_awvalid_o && m_axi_awready_i), .d_i(aw_sel_out),
      .pop_i(w_fire_last), .q_o(ord_head), .empty_o(ord_empty), .full_o(ord_full)
    );
    assign w_valid        = !ord_empty && (ord_head ? v_wvalid : wr_wvalid);
    assign wr_wready      = !ord_empty && !ord_head && w_ready;
    assign v_wready       = !ord_empty && ord_head && w_ready;
    assign m_axi_wdata_o  = ord_head ? v_wdata : wr_wdata;
    assign m_axi_wstrb_o  = ord_head ? v_wstrb : wr_wstrb;
    assign m_axi_wlast_o  = ord_head ? v_wlast : wr_wlast;
    assign w_fire_last    = m_axi_wvalid_o && m_axi_wready_i && m_axi_wlast_o;

    // R and B by ID.
    assign r_win          = m_axi_rid_i == IdW'(1);
    assign v_rvalid       = m_axi_rvalid_i && r_win;
    assign fe_rvalid      = m_axi_rvalid_i && !r_win;
    assign m_axi_rready_o = r_win ? v_rready : fe_rready;
    assign b_win          = m_axi_bid_i != '0;
    assign v_bvalid       = m_axi_bvalid_i && b_win;
    assign wr_bvalid      = m_axi_bvalid_i && !b_win;
    assign m_axi_bready_o = b_win || wr_bready;

    logic unused_win;
    assign unused_win = ^{ord_full, ar_sel};
  end else begin : gen_no_win
    assign ar_valid        = fe_arvalid;
    assign fe_arready      = ar_ready;
    assign m_axi_araddr_o  = fe_araddr;
    assign m_axi_arlen_o   = fe_arlen;
    assign m_axi_arsize_o  = fe_arsize;
    assign m_axi_arburst_o = fe_arburst;
    assign m_axi_arid_o    = fe_arid;
    assign fe_rvalid       = m_axi_rvalid_i;
    assign m_axi_rready_o  = fe_rready;
    assign aw_valid        = wr_awvalid;
    assign wr_awready      = aw_ready;
    assign m_axi_awaddr_o  = wr_awaddr;
    assign m_axi_awlen_o   = wr_awlen;
    assign m_axi_awsize_o  = wr_awsize;
    assign m_axi_awburst_o = wr_awburst;
    assign m_axi_awid_o    = wr_awid;
    assign w_valid         = wr_wvalid;
    assign wr_wready       = w_ready;
    assign m_axi_wdata_o   = wr_wdata;
    assign m_axi_wstrb_o   = wr_wstrb;
    assign m_axi_wlast_o   = wr_wlast;
    assign wr_bvalid       = m_axi_bvalid_i;
    assign m_axi_bready_o  = wr_bready;
    // The window's streams stay idle (the frame's Window = 0 ties them off).
    assign win_park_ready = 1'b1;
    assign win_fin_ready  = 1'b1;
    assign win_rq_ready   = 1'b1;
    assign win_rs_valid   = 1'b0;
    assign win_rs_cox     = '0;
    assign win_idle       = 1'b1;
    assign win_err        = 1'b0;
    logic unused_win;
    assign unused_win = ^{win_park_valid, win_park_key, win_park_cox, win_fin_valid, win_fin_key,
                          win_fin_mask, win_fin_cox, win_rq_valid, win_rq_key, clear_ok_q,
                          init_pix_q};
  end

  // ---------------------------------------------------------------------------
  // Soft reset (docs/accel.md, "Soft reset"): on the core's flush the AXI4 port stops starting
  // transactions: AR (and AW) is blocked from the first cycle no address is being offered, so no
  // valid is dropped; W passes only the beats of write bursts whose AW was accepted (a burst's
  // AWVALID never comes after its first WVALID in cube5_axi_wr). The port is quiet once no read
  // or write burst is outstanding and every accepted burst's W beats are out: then the units and
  // the sequencers are reset for one cycle (drain_q), which is the core's drained_i.
  // ---------------------------------------------------------------------------
  localparam int unsigned RdOutW = $clog2(Outstanding) + 2;
  localparam int unsigned WrOutW = $clog2(WrOutstanding) + 2;
  localparam int unsigned WOwedW = $clog2((WrOutstanding + 2) * MaxBurst) + 3;
  logic                     ar_block_q, aw_block_q, w_open, quiet;
  logic [RdOutW-1:0]        rd_out_q;   // read bursts accepted, last beat not yet in
  logic [WrOutW-1:0]        wr_out_q;   // write bursts accepted, B not yet in
  logic signed [WOwedW-1:0] w_owed_q, w_owed_d;   // beats of accepted write bursts not yet sent
  // w_owed_q > 0 in a flip-flop (for clock rate: the W channel's ready starts from a register,
  // not from the count's compare; the routed line's critical path at 30d3a1b). The count after
  // this cycle's AW (w_owed_aw) and both its compares are formed beside the W beat's handshake,
  // which then only selects (the W valid comes late, through the window's W FIFO and the
  // arbiter: the routed P = 1 and 2 lines' critical path at d5c8287).
  logic                     w_owed_pos_q, w_owed_pos_d, w_fire;
  logic signed [WOwedW-1:0] w_owed_aw;

  assign m_axi_arvalid_o = ar_valid && !ar_block_q;
  assign ar_ready        = m_axi_arready_i && !ar_block_q;
  assign m_axi_awvalid_o = aw_valid && !aw_block_q;
  assign aw_ready        = m_axi_awready_i && !aw_block_q;
  assign w_open          = !aw_block_q || w_owed_pos_q;
  assign m_axi_wvalid_o  = w_valid && w_open;
  assign w_ready         = m_axi_wready_i && w_open;
  assign quiet = ar_block_q && aw_block_q && rd_out_q == '0 && wr_out_q == '0 && w_owed_q == '0;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      drain_q      <= 1'b0;
      ar_block_q   <= 1'b0;
      aw_block_q   <= 1'b0;
      rd_out_q     <= '0;
      wr_out_q     <= '0;
      w_owed_q     <= '0;
      w_owed_pos_q <= 1'b0;
    end else begin
      drain_q <= flush && quiet && !drain_q;
      if (drain_q) begin
        ar_block_q <= 1'b0;
        aw_block_q <= 1'b0;
      end else if (flush) begin
        if (!m_axi_arvalid_o || m_axi_arready_i) ar_block_q <= 1'b1;
        if (!m_axi_awvalid_o || m_axi_awready_i) aw_block_q <= 1'b1;
      end
      rd_out_q <= rd_out_q + RdOutW'(m_axi_arvalid_o && m_axi_arready_i)
                           - RdOutW'(m_axi_rvalid_i && m_axi_rready_o && m_axi_rlast_i);
      wr_out_q <= wr_out_q + WrOutW'(m_axi_awvalid_o && m_axi_awready_i)
                           - WrOutW'(m_axi_bvalid_i && m_axi_bready_o);
      w_owed_q     <= w_owed_d;
      w_owed_pos_q <= w_owed_pos_d;
    end
  end
  assign w_fire       = m_axi_wvalid_o && m_axi_wready_i;
  assign w_owed_aw    = w_owed_q + ((m_axi_awvalid_o && m_axi_awready_i)
                                    ? WOwedW'(m_axi_awlen_o) + WOwedW'(1) : '0);
  assign w_owed_d     = w_fire ? w_owed_aw - WOwedW'(1) : w_owed_aw;
  assign w_owed_pos_d = w_fire ? w_owed_aw > 1 : w_owed_aw > 0;
`ifndef SYNTHESIS
  WOwedPosAsCount: assert property (@(posedge clk_i) disable iff (!rst_ni)
      w_owed_pos_q == (w_owed_q > 0))
    else $error("cube5_accel: the W channel's open flag is not the owed count's sign");
`endif

  // The rest of the frame's output item (counters) and of the completion (its count).
  logic unused;
  logic [P-1:0] unused_cox;
  for (genvar k = 0; k < P; k++) begin : gen_unused_cox
    assign unused_cox[k] = ^fr_cox[k*CoxelW + 4*ChanW +: CoxelW - 4*ChanW];
  end
  assign unused = ^{fr_out_data[FrOutW-1:FrLanes*CoxelW+1], unused_cox, cpl_data[17:2],
                    win_rs_ready, img_base, row_step, park_base, row_pixels, rows_done_q};

endmodule
