// cube5_skewmem: skewed memory controller with hierarchical blocks (patent [37], [43], [54]-[57];
// docs/numerics/skewmem.md).
//
// P single-port modules hold the volume skewed: voxel (x, y, z) in module (x + y + z) mod P, so an
// aligned beam of P voxels along x, y or z touches every module exactly once and is fetched in one
// cycle. The volume is kept in BlockDim^3 blocks through a block LUT (pointer, empty, masked per block)
// loaded on the configuration port; reads of empty or masked blocks, and of beams outside the
// volume, are skipped (no module access, zeros returned, flags set).
//
// Pipeline: accept (command and its LUT entry registered) -> issue (each module k addresses the
// voxel of lane (k - s) mod P, s = module of the beam start) -> MemLatency cycles in the modules
// beside a tag pipe (access counters updated in its first stage) -> rotate by s (de-skew) ->
// output FIFO of MemLatency + 3 entries. The modules never stall: a command is accepted only
// while the FIFO has room for everything in flight, which keeps one command per clock at full
// speed. Latency MemLatency + 2.
module cube5_skewmem #(
  /// Memory modules = lanes of a beam: 1, 2, 4, 8 or 16.
  parameter int unsigned P           = 4,
  /// Voxel width, U(VoxelW.0).
  parameter int unsigned VoxelW      = 12,
  /// Largest volume edge, a power of two in 4..1024 (coordinates are log2(MaxDim) bits).
  parameter int unsigned MaxDim      = 16,
  /// Block edge: a power of two, P <= BlockDim < MaxDim, at most 64.
  parameter int unsigned BlockDim    = 8,
  /// Module read latency in cycles (1 = SRAM; more = DRAM-like), 1..8.
  parameter int unsigned MemLatency  = 1,
  /// Access counter width (counters wrap), 8..32.
  parameter int unsigned CntW        = 32
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Configuration write this cycle (only while the stream is idle).
  input  logic cfg_valid_i,
  /// Top bit 0: register (0 = dimensions); top bit 1: LUT entry at the low bits.
  input  logic [cube5_skewmem_pkg::cfg_addr_w($clog2(MaxDim), BlockDim)-1:0] cfg_addr_i,
  /// Dimensions nx, ny, nz ($clog2(MaxDim)+1 bits each), or a LUT entry: ptr, empty, masked. LSB first.
  input  logic [cube5_skewmem_pkg::cfg_data_w($clog2(MaxDim), BlockDim)-1:0] cfg_data_i,

  /// Command valid.
  input  logic in_valid_i,
  /// Controller takes a command this cycle.
  output logic in_ready_o,
  /// op (1), axis (2), x, y, z ($clog2(MaxDim) each), data (VoxelW), probe (max(1, log2 P)), LSB first.
  input  logic [cube5_skewmem_pkg::in_w(P, VoxelW, $clog2(MaxDim))-1:0] in_data_i,

  /// Response valid.
  output logic out_valid_o,
  /// Consumer takes the response this cycle.
  input  logic out_ready_i,
  /// lanes 0..P-1 (VoxelW each), is_beam, outside, empty, masked, conflict, rd (CntW), wr (CntW).
  output logic [cube5_skewmem_pkg::out_w(P, VoxelW, CntW)-1:0] out_data_o
);

  localparam int unsigned LogP      = $clog2(P);
  localparam int unsigned ModW      = cube5_skewmem_pkg::mod_w(P);
  localparam int unsigned LogB      = $clog2(BlockDim);
  localparam int unsigned M         = $clog2(MaxDim);
  localparam int unsigned BlkW      = cube5_skewmem_pkg::blk_w($clog2(MaxDim), BlockDim);
  localparam int unsigned WordW     = 3 * M - LogP;
  localparam int unsigned DimW      = M + 1;
  localparam int unsigned SumW      = M + 2;  // x + y + z without overflow
  localparam int unsigned LutW      = BlkW + 2;
  localparam int unsigned InW       = cube5_skewmem_pkg::in_w(P, VoxelW, $clog2(MaxDim));
  localparam int unsigned OutW      = cube5_skewmem_pkg::out_w(P, VoxelW, CntW);
  localparam int unsigned FifoDepth = MemLatency + 3;
  localparam int unsigned FifoPtrW  = $clog2(FifoDepth);
  localparam int unsigned CountW    = $clog2(FifoDepth + 1);

  // Elaboration checks mirror SkewConfig::validate in the model.
  if (P != 1 && P != 2 && P != 4 && P != 8 && P != 16) begin : gen_bad_p
    $fatal(1, "cube5_skewmem: P must be 1, 2, 4, 8 or 16");
  end
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_skewmem: VoxelW must be 4..16");
  end
  if (MaxDim < 4 || MaxDim > 1024 || (MaxDim & (MaxDim - 1)) != 0) begin : gen_bad_max_dim
    $fatal(1, "cube5_skewmem: MaxDim must be a power of two in 4..1024");
  end
  if (BlockDim < 2 || BlockDim > 64 || (BlockDim & (BlockDim - 1)) != 0 || BlockDim < P || BlockDim >= MaxDim)
  begin : gen_bad_block
    $fatal(1, "cube5_skewmem: BlockDim must be a power of two in 2..64 with P <= BlockDim < MaxDim");
  end
  if (MemLatency < 1 || MemLatency > 8) begin : gen_bad_latency
    $fatal(1, "cube5_skewmem: MemLatency must be 1..8");
  end
  if (CntW < 8 || CntW > 32) begin : gen_bad_cnt_w
    $fatal(1, "cube5_skewmem: CntW must be 8..32");
  end

  // Command fields, LSB first.
  localparam int unsigned XLsb     = 3;
  localparam int unsigned YLsb     = XLsb + M;
  localparam int unsigned ZLsb     = YLsb + M;
  localparam int unsigned DataLsb  = ZLsb + M;
  localparam int unsigned ProbeLsb = DataLsb + VoxelW;

  // Tag fields, LSB first: what the response needs besides the module data.
  localparam int unsigned TagBeam     = 0;
  localparam int unsigned TagOutside  = 1;
  localparam int unsigned TagEmpty    = 2;
  localparam int unsigned TagMasked   = 3;
  localparam int unsigned TagConflict = 4;
  localparam int unsigned TagZero     = 5;
  localparam int unsigned TagRotLsb   = 6;
  localparam int unsigned TagW        = TagRotLsb + ModW;

  // ---------------------------------------------------------------------------
  // Configuration: dimensions register and block LUT (not reset: configuration state)
  // ---------------------------------------------------------------------------
  logic            lut_we, dims_we;
  logic [3*DimW-1:0] dims_q;
  logic [LutW-1:0] lut_mem_q [2**BlkW];

  assign lut_we  = cfg_valid_i && cfg_addr_i[BlkW];
  assign dims_we = cfg_valid_i && !cfg_addr_i[BlkW] && (cfg_addr_i[BlkW-1:0] == '0);

  always_ff @(posedge clk_i) begin
    if (dims_we) begin
      dims_q <= cfg_data_i[3*DimW-1:0];
    end
  end

  always_ff @(posedge clk_i) begin
    if (lut_we) begin
      lut_mem_q[cfg_addr_i[BlkW-1:0]] <= cfg_data_i[LutW-1:0];
    end
  end

  logic unused_cfg_data;
  assign unused_cfg_data = ^cfg_data_i;

  // ---------------------------------------------------------------------------
  // Flow control: credits for everything in flight (accepted, not yet taken)
  // ---------------------------------------------------------------------------
  logic              in_fire, out_fire, push;
  logic [CountW-1:0] inflight_d, inflight_q;

  assign in_ready_o = (inflight_q < CountW'(FifoDepth));
  assign in_fire    = in_valid_i && in_ready_o;
  assign inflight_d = inflight_q + CountW'(in_fire) - CountW'(out_fire);

  // ---------------------------------------------------------------------------
  // Accept: register the command and read its block's LUT entry
  // ---------------------------------------------------------------------------
  logic [BlkW-1:0] blk_idx;
  logic            s0_valid_q;
  logic [InW-1:0]  cmd_q;
  logic [LutW-1:0] lut_q;

  // Block index {bz, by, bx}: the low LogB bits of a coordinate are inside the block.
  assign blk_idx = {in_data_i[ZLsb+LogB +: M-LogB], in_data_i[YLsb+LogB +: M-LogB],
                    in_data_i[XLsb+LogB +: M-LogB]};

  always_ff @(posedge clk_i) begin
    cmd_q <= in_data_i;
    lut_q <= lut_mem_q[blk_idx];
  end

  // ---------------------------------------------------------------------------
  // Issue: inside test, skip, per-module addresses, conflict self-check
  // ---------------------------------------------------------------------------
  logic              op_read, axis_y, axis_z, axis_x;
  logic [M-1:0]      x, y, z, ax, ay, az;
  logic [VoxelW-1:0] wdata;
  logic [ModW-1:0]   probe;
  logic [BlkW-1:0]   lut_ptr;
  logic              lut_empty, lut_masked;
  logic [DimW-1:0]   nx, ny, nz;
  logic              in_vol, do_read, do_write;
  logic [SumW-1:0]   start_sum;
  logic [ModW-1:0]   s;

  always_comb begin
    op_read    = cmd_q[0] == cube5_skewmem_pkg::OpRead;
    axis_y     = cmd_q[2:1] == cube5_skewmem_pkg::AxisY;
    axis_z     = cmd_q[2:1] == cube5_skewmem_pkg::AxisZ;
    axis_x     = !axis_y && !axis_z;  // AxisX and the reserved code
    x          = cmd_q[XLsb +: M];
    y          = cmd_q[YLsb +: M];
    z          = cmd_q[ZLsb +: M];
    wdata      = cmd_q[DataLsb +: VoxelW];
    probe      = cmd_q[ProbeLsb +: ModW] & ModW'(P - 1);
    lut_ptr    = lut_q[0 +: BlkW];
    lut_empty  = lut_q[BlkW];
    lut_masked = lut_q[BlkW+1];
    nx         = dims_q[0 +: DimW];
    ny         = dims_q[DimW +: DimW];
    nz         = dims_q[2*DimW +: DimW];
    // A read beam is aligned along its axis: the low log2 P bits there are ignored. (The cast is
    // in parentheses: Yosys 0.23 parses `~N'(v)` as `(~N)'(v)` and silently drops the `~`.)
    ax         = (op_read && axis_x) ? (x & ~(M'(P - 1))) : x;
    ay         = (op_read && axis_y) ? (y & ~(M'(P - 1))) : y;
    az         = (op_read && axis_z) ? (z & ~(M'(P - 1))) : z;
    // Dimensions are multiples of P, so the beam is in_vol exactly when its start is.
    in_vol     = ({1'b0, x} < nx) && ({1'b0, y} < ny) && ({1'b0, z} < nz);
    do_read    = op_read && in_vol && !lut_empty && !lut_masked;
    do_write   = !op_read && in_vol;
    start_sum  = SumW'(ax) + SumW'(ay) + SumW'(az);
    s          = ModW'(start_sum & SumW'(P - 1));
  end

  logic [P*VoxelW-1:0] rdata;          // module k at [k*VoxelW +: VoxelW]
  logic [P*P-1:0]      lane_onehot;    // module k's lane at [k*P +: P]
  logic [P-1:0]        module_ok;
  logic [P-1:0]        rd_inc, wr_inc;     // accesses issued to module k this cycle

  for (genvar k = 0; k < P; k++) begin : gen_module
    logic [ModW-1:0]  lane, lane_mod;
    logic [M-1:0]     cx, cy, cz;
    logic [SumW-1:0]  csum;
    logic [WordW-1:0] word;
    logic             req, we;

    // Module k holds lane (k - s) mod P of the beam: put that lane into the axis coordinate's low
    // bits (they are zero after alignment). Writes use the command's own coordinates.
    assign lane     = ModW'(k) - s;
    assign lane_mod = lane & ModW'(P - 1);  // P = 1: the single lane 0
    assign cx       = ax | ((op_read && axis_x) ? M'(lane_mod) : '0);
    assign cy       = ay | ((op_read && axis_y) ? M'(lane_mod) : '0);
    assign cz       = az | ((op_read && axis_z) ? M'(lane_mod) : '0);

    // Word {ptr, lz, ly, lx >> log2 P}.
    assign word = (WordW'(lut_ptr) << (3 * LogB - LogP))
                | (WordW'(cz[LogB-1:0]) << (2 * LogB - LogP))
                | (WordW'(cy[LogB-1:0]) << (LogB - LogP))
                | (WordW'(cx[LogB-1:0]) >> LogP);

    assign we  = do_write && (s == ModW'(k));
    assign req = s0_valid_q && (do_read || we);

    // Self-check: the voxel this module serves does live here, and each lane is served once.
    assign csum                     = SumW'(cx) + SumW'(cy) + SumW'(cz);
    assign module_ok[k]             = (csum & SumW'(P - 1)) == SumW'(k);
    assign lane_onehot[k*P +: P]    = P'(1) << lane_mod;

    cube5_skewmem_bank #(
      .Width   (VoxelW),
      .AddrW   (WordW),
      .Latency (MemLatency)
    ) u_bank (
      .clk_i   (clk_i),
      .req_i   (req),
      .we_i    (we),
      .addr_i  (word),
      .wdata_i (wdata),
      .rdata_o (rdata[k*VoxelW +: VoxelW])
    );

    assign rd_inc[k] = req && !we;
    assign wr_inc[k] = req && we;
  end

  logic [P-1:0]    served;
  logic            conflict;
  logic [TagW-1:0] tag_d;

  always_comb begin
    served = '0;
    for (int unsigned k = 0; k < P; k++) begin
      served = served | lane_onehot[k*P +: P];
    end
    conflict = do_read && !((&served) && (&module_ok));

    tag_d                        = '0;
    tag_d[TagBeam]               = op_read;
    tag_d[TagOutside]            = !in_vol;
    tag_d[TagEmpty]              = in_vol && lut_empty;
    tag_d[TagMasked]             = in_vol && lut_masked;
    tag_d[TagConflict]           = conflict;
    tag_d[TagZero]               = !do_read;
    tag_d[TagRotLsb +: ModW]     = s;
  end

  // ---------------------------------------------------------------------------
  // Access counters, one stage after issue (off the address path): the increments and the probe
  // are registered, the counters and the probed module's snapshot follow in commands' order
  // ---------------------------------------------------------------------------
  logic [P-1:0]      rd_inc_q, wr_inc_q;
  logic [ModW-1:0]   probe_q;
  logic [P*CntW-1:0] rd_cnt_d, rd_cnt_q, wr_cnt_d, wr_cnt_q;
  logic [2*CntW-1:0] snap_d, snap_l;   // {wr, rd} of the probed module after the command

  always_ff @(posedge clk_i) begin
    rd_inc_q <= rd_inc;
    wr_inc_q <= wr_inc;
    probe_q  <= probe;
  end

  always_comb begin
    snap_d = '0;
    for (int unsigned k = 0; k < P; k++) begin
      rd_cnt_d[k*CntW +: CntW] = rd_cnt_q[k*CntW +: CntW] + CntW'(rd_inc_q[k]);
      wr_cnt_d[k*CntW +: CntW] = wr_cnt_q[k*CntW +: CntW] + CntW'(wr_inc_q[k]);
      if (probe_q == ModW'(k)) begin
        snap_d = {wr_cnt_d[k*CntW +: CntW], rd_cnt_d[k*CntW +: CntW]};
      end
    end
  end

  // The snapshot joins its tag after the remaining MemLatency - 1 stages.
  if (MemLatency == 1) begin : gen_snap_direct
    assign snap_l = snap_d;
  end else begin : gen_snap_pipe
    logic [2*CntW-1:0] snap_q [MemLatency-1];
    always_ff @(posedge clk_i) begin
      snap_q[0] <= snap_d;
    end
    for (genvar i = 1; i < MemLatency - 1; i++) begin : gen_stage
      always_ff @(posedge clk_i) begin
        snap_q[i] <= snap_q[i-1];
      end
    end
    assign snap_l = snap_q[MemLatency-2];
  end

  // ---------------------------------------------------------------------------
  // Tag pipe beside the modules' read latency (never stalls)
  // ---------------------------------------------------------------------------
  logic [TagW-1:0]        tag_q [MemLatency];
  logic [MemLatency-1:0] tag_valid_d, tag_valid_q;

  always_ff @(posedge clk_i) begin
    tag_q[0] <= tag_d;
  end
  for (genvar i = 1; i < MemLatency; i++) begin : gen_tag_pipe
    always_ff @(posedge clk_i) begin
      tag_q[i] <= tag_q[i-1];
    end
  end

  always_comb begin
    tag_valid_d[0] = s0_valid_q;
    for (int unsigned i = 1; i < MemLatency; i++) begin
      tag_valid_d[i] = tag_valid_q[i-1];
    end
  end

  // ---------------------------------------------------------------------------
  // De-skew: lane i = module (s + i) mod P; zeros for acks and skipped beams
  // ---------------------------------------------------------------------------
  logic [TagW-1:0]     tag_l;
  logic [ModW-1:0]     rot;
  logic [P*VoxelW-1:0] lanes;
  logic [OutW-1:0]     resp;

  always_comb begin
    tag_l = tag_q[MemLatency-1];
    rot   = tag_l[TagRotLsb +: ModW];
    lanes = '0;
    for (int unsigned i = 0; i < P; i++) begin
      for (int unsigned k = 0; k < P; k++) begin
        if (ModW'(rot + ModW'(i)) == ModW'(k) && !tag_l[TagZero]) begin
          lanes[i*VoxelW +: VoxelW] = rdata[k*VoxelW +: VoxelW];
        end
      end
    end
    resp = {snap_l, tag_l[TagConflict],
            tag_l[TagMasked], tag_l[TagEmpty], tag_l[TagOutside], tag_l[TagBeam], lanes};
  end

  assign push = tag_valid_q[MemLatency-1];

  // ---------------------------------------------------------------------------
  // Output FIFO (room for everything in flight, so a returning beam is never lost)
  // ---------------------------------------------------------------------------
  logic [OutW-1:0]     fifo_q [FifoDepth];
  logic [FifoPtrW-1:0] wr_ptr_d, wr_ptr_q, rd_ptr_d, rd_ptr_q;
  logic [CountW-1:0]   fifo_cnt_d, fifo_cnt_q;

  assign out_valid_o = (fifo_cnt_q != '0);
  assign out_data_o  = fifo_q[rd_ptr_q];
  assign out_fire    = out_valid_o && out_ready_i;

  always_comb begin
    wr_ptr_d = wr_ptr_q;
    rd_ptr_d = rd_ptr_q;
    if (push) begin
      wr_ptr_d = (wr_ptr_q == FifoPtrW'(FifoDepth - 1)) ? '0 : wr_ptr_q + 1'b1;
    end
    if (out_fire) begin
      rd_ptr_d = (rd_ptr_q == FifoPtrW'(FifoDepth - 1)) ? '0 : rd_ptr_q + 1'b1;
    end
    fifo_cnt_d = fifo_cnt_q + CountW'(push) - CountW'(out_fire);
  end

  always_ff @(posedge clk_i) begin
    if (push) begin
      fifo_q[wr_ptr_q] <= resp;
    end
  end

  // ---------------------------------------------------------------------------
  // Control state (reset); the memory, LUT and dimensions are not reset
  // ---------------------------------------------------------------------------
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      s0_valid_q  <= 1'b0;
      tag_valid_q <= '0;
      inflight_q  <= '0;
      fifo_cnt_q  <= '0;
      wr_ptr_q    <= '0;
      rd_ptr_q    <= '0;
      rd_cnt_q    <= '0;
      wr_cnt_q    <= '0;
    end else begin
      s0_valid_q  <= in_fire;
      tag_valid_q <= tag_valid_d;
      inflight_q  <= inflight_d;
      fifo_cnt_q  <= fifo_cnt_d;
      wr_ptr_q    <= wr_ptr_d;
      rd_ptr_q    <= rd_ptr_d;
      rd_cnt_q    <= rd_cnt_d;
      wr_cnt_q    <= wr_cnt_d;
    end
  end

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_skewmem: output changed while stalled");

  // Every beam issued touches each module exactly once (the skew's promise, [37]).
  NoModuleConflict: assert property (@(posedge clk_i) disable iff (!rst_ni)
      s0_valid_q |-> !conflict)
    else $error("cube5_skewmem: beam with a module conflict");

  // The credit count keeps the FIFO from overflowing.
  FifoNeverOverflows: assert property (@(posedge clk_i) disable iff (!rst_ni)
      fifo_cnt_q <= CountW'(FifoDepth) && inflight_q <= CountW'(FifoDepth)
      && fifo_cnt_q <= inflight_q)
    else $error("cube5_skewmem: more items in flight than FIFO entries");
`endif

endmodule
