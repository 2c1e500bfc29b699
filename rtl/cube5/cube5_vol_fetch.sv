// cube5_vol_fetch: the accelerator's volume fetch (issue 12; docs/numerics/vol_fetch.md, design in
// docs/accel.md; patent [43], [54]-[57]). Walks the blocks of one sweep (slabs front to back, block
// rows, the section's block columns), looks each up in the block LUT, reads the present ones from
// external memory through cube5_axi_rd (one command of 2 B^3 bytes per block, blocked layout:
// base + ptr 2 B^3, x fastest inside a block) and delivers their voxels P at a time in walk order;
// an empty or masked block issues no read and yields one skip item.
//
//   command ─► LUT write ──────────────────────────► block LUT (RAM, NB^3 x {ptr, empty, masked})
//          └─► sweep registers ─► walker (t, bj, bi) ─► LUT read ─► stage 2 ─┬─► cube5_axi_rd ─ AXI4
//                                                                            └─► tag FIFO
//   out item ◄── gearbox (R items per bus beat) ◄── reader's beats + head tag (skip / error / data)
`include "cube5_axi_ports.svh"

module cube5_vol_fetch #(
  /// Byte address width of the AXI port (13..64).
  parameter int unsigned AddrW = 32,
  /// Bus width in bits: a power of two, 16 P .. 16 BlockDim^3.
  parameter int unsigned DataW = 64,
  /// Voxels per output item.
  parameter int unsigned P = 4,
  /// Bits of a delivered voxel (the low bits of the stored 16-bit word).
  parameter int unsigned VoxelW = 12,
  /// Largest volume edge (a power of two).
  parameter int unsigned MaxDim = 64,
  /// Block edge B: a power of two, max(2, P / 2) <= B <= 16, B < MaxDim.
  parameter int unsigned BlockDim = 8,
  /// The reader's longest burst in beats.
  parameter int unsigned MaxBurst = 16,
  /// The reader's bursts in flight.
  parameter int unsigned Outstanding = 8,
  /// ARID / RID width.
  parameter int unsigned IdW = 4
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Command valid.
  input  logic in_valid_i,
  /// The unit takes a command this cycle (low while a sweep is walked).
  output logic in_ready_o,
  /// op (1), then a LUT write {index, ptr, empty, masked} or a sweep {base, nb_x, nb_y, nb_z,
  /// axis_k, reversed, sec_lo, sec_hi}, LSB first (docs/numerics/vol_fetch.md).
  input  logic [cube5_vol_fetch_pkg::cmd_w(AddrW, MaxDim, BlockDim)-1:0] in_data_i,

  /// Item valid.
  output logic out_valid_o,
  /// Consumer takes the item.
  input  logic out_ready_i,
  /// lanes (P x VoxelW), blk_x, blk_y, blk_z, word, skip, last, error, resp_err, LSB first.
  output logic [cube5_vol_fetch_pkg::out_w(P, VoxelW, MaxDim, BlockDim)-1:0] out_data_o,

  /// Sticky: some beat since reset had RRESP != OKAY.
  output logic err_o,

  // AXI4 read channels (cube5_axi_rd's: ID 0, RREADY always 1 out of reset).
  `CUBE5_AXI4_RD_MGR_PORTS(m_axi_, AddrW, DataW, IdW)
);

  // ==============================================================================================
  // Derived sizes
  // ==============================================================================================

  localparam int unsigned NB            = MaxDim / BlockDim;
  localparam int unsigned NbW           = cube5_vol_fetch_pkg::nb_w(MaxDim, BlockDim);
  localparam int unsigned BlkW          = 3 * NbW;
  localparam int unsigned Bbus          = DataW / 8;
  localparam int unsigned SizeW         = $clog2(Bbus);
  localparam int unsigned BlockBytes    = 2 * BlockDim * BlockDim * BlockDim;
  localparam int unsigned BlkShift      = $clog2(BlockBytes);
  localparam int unsigned BeatsPerBlock = BlockBytes / Bbus;
  localparam int unsigned LenW          = $clog2(BeatsPerBlock) + 1;
  localparam int unsigned Groups        = BlockDim * BlockDim * BlockDim / P;
  localparam int unsigned WordW         = cube5_vol_fetch_pkg::word_w(P, BlockDim);
  localparam int unsigned R             = DataW / (16 * P);
  localparam int unsigned RW            = (R > 2) ? $clog2(R) : 1;
  localparam int unsigned TagDepth      = 1 << $clog2(Outstanding * MaxBurst / BeatsPerBlock + 4);
  localparam int unsigned TagW          = BlkW + 3;
  localparam int unsigned LutW          = BlkW + 2;
  localparam int unsigned NbCW          = NbW + 1;

  if (P != 1 && P != 2 && P != 4 && P != 8) begin : gen_bad_p
    $fatal(1, "cube5_vol_fetch: P must be 1, 2, 4 or 8");
  end
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_vol_fetch: VoxelW must be in 4..16");
  end
  if (MaxDim < 8 || MaxDim > 1024 || (1 << $clog2(MaxDim)) != MaxDim) begin : gen_bad_max_dim
    $fatal(1, "cube5_vol_fetch: MaxDim must be a power of two in 8..1024");
  end
  if ((1 << $clog2(BlockDim)) != BlockDim || BlockDim < 2 || 2 * BlockDim < P || BlockDim > 16
      || BlockDim >= MaxDim) begin : gen_bad_block
    $fatal(1, "cube5_vol_fetch: BlockDim must be a power of two, max(2, P / 2) <= B <= 16, B < MaxDim");
  end
  if ((1 << $clog2(DataW)) != DataW || DataW < 16 * P || DataW > 16 * BlockDim * BlockDim * BlockDim)
  begin : gen_bad_data_w
    $fatal(1, "cube5_vol_fetch: DataW must be a power of two in 16 P .. 16 B^3");
  end

  // ==============================================================================================
  // Commands: LUT writes and sweeps
  // ==============================================================================================

  logic in_fire, op_sweep;
  assign op_sweep = in_data_i[0];

  // LUT write fields.
  logic [BlkW-1:0] lw_index, lw_ptr;
  logic            lw_empty, lw_masked;
  assign lw_index  = in_data_i[1 +: BlkW];
  assign lw_ptr    = in_data_i[1 + BlkW +: BlkW];
  assign lw_empty  = in_data_i[1 + 2 * BlkW];
  assign lw_masked = in_data_i[2 + 2 * BlkW];

  // Sweep fields.
  localparam int unsigned SwNb  = 1 + AddrW;
  localparam int unsigned SwAx  = SwNb + 3 * NbCW;
  localparam int unsigned SwLo  = SwAx + 3;
  localparam int unsigned SwHi  = SwLo + NbW;
  logic [AddrW-1:0] sw_base;
  logic [NbCW-1:0]  sw_nbx, sw_nby, sw_nbz, sw_hi, sw_nbi, sw_nbj, sw_nbk;
  logic [1:0]       sw_axis;
  logic             sw_rev, sw_refused;
  logic [NbW-1:0]   sw_lo;
  assign sw_base = in_data_i[1 +: AddrW];
  assign sw_nbx  = in_data_i[SwNb +: NbCW];
  assign sw_nby  = in_data_i[SwNb + NbCW +: NbCW];
  assign sw_nbz  = in_data_i[SwNb + 2 * NbCW +: NbCW];
  assign sw_axis = in_data_i[SwAx +: 2];
  assign sw_rev  = in_data_i[SwAx + 2];
  assign sw_lo   = in_data_i[SwLo +: NbW];
  assign sw_hi   = in_data_i[SwHi +: NbCW];

  // Frame axes: i and j are the two axes other than k, ascending.
  always_comb begin
    unique case (sw_axis)
      2'd0:    begin sw_nbi = sw_nby; sw_nbj = sw_nbz; sw_nbk = sw_nbx; end
      2'd1:    begin sw_nbi = sw_nbx; sw_nbj = sw_nbz; sw_nbk = sw_nby; end
      default: begin sw_nbi = sw_nbx; sw_nbj = sw_nby; sw_nbk = sw_nbz; end
    endcase
    sw_refused = (sw_axis == 2'd3)
              || (sw_nbx == '0) || (sw_nbx > NbCW'(NB))
              || (sw_nby == '0) || (sw_nby > NbCW'(NB))
              || (sw_nbz == '0) || (sw_nbz > NbCW'(NB))
              || (NbCW'(sw_lo) >= sw_hi) || (sw_hi > sw_nbi)
              || (sw_base[SizeW-1:0] != '0);
  end

  // ==============================================================================================
  // Walker: one block per cycle, its LUT entry read into stage 2
  // ==============================================================================================

  logic             walk_q, walk_d;      // a sweep is being walked
  logic             refused_q, refused_d;
  logic [AddrW-1:0] base_q, base_d;
  // The walk's ends minus one (its compares need no adder), the slab's block bk counted itself
  // (no subtraction from t when reversed), the axis as two flags (every coordinate one 2:1
  // multiplexer, y two).
  logic [NbCW-1:0]  nbi_q, nbi_d, nbj1_q, nbj1_d, nbk1_q, nbk1_d, hi1_q, hi1_d;
  logic [NbW-1:0]   lo_q, lo_d;
  logic             ax0_q, ax0_d, ax2_q, ax2_d;
  logic             rev_q, rev_d;
  logic [NbW-1:0]   t_q, t_d, bj_q, bj_d, bi_q, bi_d, bk_q, bk_d;

  logic             s1_ready, s1_fire, s12;
  logic             v1_q, v1_d;        // the LUT's (registered) read port holds a block's entry
  logic             s2_ready;
  logic             v2_q, v2_d;        // stage 2 holds a block
  logic [NbW-1:0]   bk, bx, by, bz;
  logic             row_end, slab_end, walk_end;

  // Stage 2 must be empty too: its read command is formed from this sweep's base register.
  assign in_ready_o = !walk_q && !v1_q && !v2_q;
  assign in_fire    = in_valid_i && in_ready_o;
  assign s1_fire    = walk_q && s1_ready;

  always_comb begin
    // axis 0: (bx, by, bz) = (bk, bi, bj); 1: (bi, bk, bj); 2: (bi, bj, bk).
    bk = bk_q;
    bx = ax0_q ? bk : bi_q;
    by = ax0_q ? bi_q : (ax2_q ? bj_q : bk);
    bz = ax2_q ? bk : bj_q;
    row_end  = (NbCW'(bi_q) == hi1_q);
    slab_end = row_end && (NbCW'(bj_q) == nbj1_q);
    walk_end = refused_q || (slab_end && (NbCW'(t_q) == nbk1_q));
  end

  always_comb begin
    walk_d    = walk_q;
    refused_d = refused_q;
    base_d    = base_q;
    nbi_d     = nbi_q;
    nbj1_d    = nbj1_q;
    nbk1_d    = nbk1_q;
    hi1_d     = hi1_q;
    lo_d      = lo_q;
    ax0_d     = ax0_q;
    ax2_d     = ax2_q;
    rev_d     = rev_q;
    t_d       = t_q;
    bk_d      = bk_q;
    bj_d      = bj_q;
    bi_d      = bi_q;
    if (s1_fire) begin
      if (walk_end) begin
        walk_d = 1'b0;
      end else if (slab_end) begin
        bi_d = lo_q;
        bj_d = '0;
        t_d  = t_q + NbW'(1);
        bk_d = rev_q ? bk_q - NbW'(1) : bk_q + NbW'(1);
      end else if (row_end) begin
        bi_d = lo_q;
        bj_d = bj_q + NbW'(1);
      end else begin
        bi_d = bi_q + NbW'(1);
      end
    end
    if (in_fire && op_sweep) begin
      walk_d    = 1'b1;
      refused_d = sw_refused;
      base_d    = sw_base;
      nbi_d     = sw_nbi;
      nbj1_d    = sw_nbj - NbCW'(1);
      nbk1_d    = sw_nbk - NbCW'(1);
      hi1_d     = sw_hi - NbCW'(1);
      lo_d      = sw_lo;
      ax0_d     = (sw_axis == 2'd0);
      ax2_d     = (sw_axis == 2'd2);
      rev_d     = sw_rev;
      t_d       = '0;
      bk_d      = sw_rev ? NbW'(sw_nbk - NbCW'(1)) : '0;
      bj_d      = '0;
      bi_d      = sw_lo;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      walk_q <= 1'b0;
    end else begin
      walk_q <= walk_d;
    end
  end

  // Sweep registers and counters: qualified by walk_q.
  always_ff @(posedge clk_i) begin
    refused_q <= refused_d;
    base_q    <= base_d;
    nbi_q     <= nbi_d;
    nbj1_q    <= nbj1_d;
    nbk1_q    <= nbk1_d;
    hi1_q     <= hi1_d;
    lo_q      <= lo_d;
    ax0_q     <= ax0_d;
    ax2_q     <= ax2_d;
    rev_q     <= rev_d;
    t_q       <= t_d;
    bk_q      <= bk_d;
    bj_q      <= bj_d;
    bi_q      <= bi_d;
  end

  // The block LUT: one write port (commands), one registered read port (the walker). No reset.
  // Commands are taken only while the walker and its stages are empty, so no read meets a write
  // (no_rw_check: the ECP5 flow needs no collision logic around the block RAM).
  (* no_rw_check *)
  logic [LutW-1:0] lut_mem [NB * NB * NB];
  logic [LutW-1:0] lut_rd_q;
  logic            lut_we;
  assign lut_we = in_fire && !op_sweep;

  always_ff @(posedge clk_i) begin
    if (lut_we) lut_mem[lw_index] <= {lw_masked, lw_empty, lw_ptr};
  end
  always_ff @(posedge clk_i) begin
    if (s1_fire) lut_rd_q <= lut_mem[{bz, by, bx}];
  end

  // ==============================================================================================
  // Stage 2: skip, or a read command; a tag per block into the tag FIFO
  // ==============================================================================================

  // Stage 1 (the block beside its LUT entry in the read port) and stage 2 (both registered: the
  // block RAM's output goes straight into a register, the skip decision reads that register).
  logic [BlkW-1:0] blk1_q, blk1_d, blk2_q, blk2_d;   // {bz, by, bx}
  logic            last1_q, last1_d, err1_q, err1_d, last2_q, last2_d, err2_q, err2_d;
  logic [LutW-1:0] lut2_q, lut2_d;

  logic [BlkW-1:0] ptr2;
  logic            skip2, tag_space, s2_fire, rd_in_valid, rd_in_ready;
  assign ptr2  = lut2_q[BlkW-1:0];
  assign skip2 = !err2_q && (lut2_q[BlkW] || lut2_q[BlkW+1]);

  // A block to read hands its command to the command FIFO (cmd3, two entries) while it has room:
  // a registered condition, so the reader's acceptance (its splitter's last-burst compare) does
  // not reach back through stage 2 to the walker in the same cycle.
  logic [1:0] cmd3_cnt_q, cmd3_cnt_d;
  logic       cmd3_free, cmd3_pop, s2_read;
  assign cmd3_free   = (cmd3_cnt_q != 2'd2);
  assign s2_fire     = v2_q && tag_space && (skip2 || err2_q || cmd3_free);
  assign s2_read     = s2_fire && !skip2 && !err2_q;
  assign s2_ready    = !v2_q || s2_fire;
  assign s12         = v1_q && s2_ready;
  assign s1_ready    = !v1_q || s12;

  always_comb begin
    v1_d    = v1_q && !s12;
    blk1_d  = blk1_q;
    last1_d = last1_q;
    err1_d  = err1_q;
    if (s1_fire) begin
      v1_d    = 1'b1;
      blk1_d  = refused_q ? '0 : {bz, by, bx};
      last1_d = walk_end;
      err1_d  = refused_q;
    end
    v2_d    = v2_q && !s2_fire;
    blk2_d  = blk2_q;
    last2_d = last2_q;
    err2_d  = err2_q;
    lut2_d  = lut2_q;
    if (s12) begin
      v2_d    = 1'b1;
      blk2_d  = blk1_q;
      last2_d = last1_q;
      err2_d  = err1_q;
      lut2_d  = lut_rd_q;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      v1_q <= 1'b0;
      v2_q <= 1'b0;
    end else begin
      v1_q <= v1_d;
      v2_q <= v2_d;
    end
  end
  always_ff @(posedge clk_i) begin
    blk1_q  <= blk1_d;
    last1_q <= last1_d;
    err1_q  <= err1_d;
    blk2_q  <= blk2_d;
    last2_q <= last2_d;
    err2_q  <= err2_d;
    lut2_q  <= lut2_d;
  end

  // The block's read command: base + ptr * 2 B^3, BeatsPerBlock beats, into the command FIFO
  // (head cmd3_addr_q, then cmd3_next_q), so the address adder is not one path with the reader's
  // splitter.
  logic [AddrW-1:0]      cmd3_addr_q, cmd3_addr_d, cmd3_next_q, cmd3_next_d, s2_addr;
  logic [AddrW+LenW-1:0] rd_cmd;
  assign cmd3_pop = rd_in_valid && rd_in_ready;
  always_comb begin
    s2_addr     = base_q + (AddrW'(ptr2) << BlkShift);
    cmd3_cnt_d  = cmd3_cnt_q + 2'(s2_read) - 2'(cmd3_pop);
    cmd3_addr_d = cmd3_addr_q;
    cmd3_next_d = cmd3_next_q;
    if (cmd3_pop) cmd3_addr_d = cmd3_next_q;
    if (s2_read) begin
      // The new command is the head when the FIFO is empty after this cycle's pop.
      if (cmd3_cnt_q == 2'd0 || (cmd3_cnt_q == 2'd1 && cmd3_pop)) begin
        cmd3_addr_d = s2_addr;
      end else begin
        cmd3_next_d = s2_addr;
      end
    end
  end
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      cmd3_cnt_q <= '0;
    end else begin
      cmd3_cnt_q <= cmd3_cnt_d;
    end
  end
  always_ff @(posedge clk_i) begin
    cmd3_addr_q <= cmd3_addr_d;
    cmd3_next_q <= cmd3_next_d;
  end
  assign rd_in_valid = (cmd3_cnt_q != 2'd0);
  assign rd_cmd      = {LenW'(BeatsPerBlock), cmd3_addr_q};

  // ==============================================================================================
  // The reader
  // ==============================================================================================

  logic             rd_out_valid, rd_out_ready;
  logic [DataW+2:0] rd_out_data;

  cube5_axi_rd #(
    .AddrW      (AddrW),
    .DataW      (DataW),
    .LenW       (LenW),
    .MaxBurst   (MaxBurst),
    .Outstanding(Outstanding),
    .IdW        (IdW)
  ) u_rd (
    .clk_i          (clk_i),
    .rst_ni         (rst_ni),
    .in_valid_i     (rd_in_valid),
    .in_ready_o     (rd_in_ready),
    .in_data_i      (rd_cmd),
    .out_valid_o    (rd_out_valid),
    .out_ready_i    (rd_out_ready),
    .out_data_o     (rd_out_data),
    .err_o          (err_o),
    .m_axi_araddr_o (m_axi_araddr_o),
    .m_axi_arlen_o  (m_axi_arlen_o),
    .m_axi_arsize_o (m_axi_arsize_o),
    .m_axi_arburst_o(m_axi_arburst_o),
    .m_axi_arid_o   (m_axi_arid_o),
    .m_axi_arvalid_o(m_axi_arvalid_o),
    .m_axi_arready_i(m_axi_arready_i),
    .m_axi_rdata_i  (m_axi_rdata_i),
    .m_axi_rresp_i  (m_axi_rresp_i),
    .m_axi_rlast_i  (m_axi_rlast_i),
    .m_axi_rid_i    (m_axi_rid_i),
    .m_axi_rvalid_i (m_axi_rvalid_i),
    .m_axi_rready_o (m_axi_rready_o)
  );

  // ==============================================================================================
  // Tag FIFO (blocks in walk order) and the output gearbox
  // ==============================================================================================

  logic [TagW-1:0] head, tag_word;
  logic            head_valid, head_skip, head_last, head_err, head_data, tag_empty, tag_full;
  logic [BlkW-1:0] head_blk;
  assign tag_word   = {err2_q, last2_q, skip2, blk2_q};
  assign head_valid = !tag_empty;
  assign tag_space  = !tag_full;
  assign head_blk   = head[BlkW-1:0];
  assign head_skip  = head[BlkW];
  assign head_last  = head[BlkW+1];
  assign head_err   = head[BlkW+2];
  assign head_data  = !head_skip && !head_err;

  logic [WordW-1:0] word_q, word_d;
  logic [RW-1:0]    sub_q, sub_d;
  logic             out_fire, word_end, sub_end, pop;
  assign word_end = (word_q == WordW'(Groups - 1));
  assign sub_end  = (sub_q == RW'(R - 1));

  assign out_valid_o  = head_valid && (!head_data || rd_out_valid);
  assign out_fire     = out_valid_o && out_ready_i;
  assign rd_out_ready = out_fire && head_data && sub_end;
  assign pop          = out_fire && (!head_data || word_end);

  always_comb begin
    word_d = word_q;
    sub_d  = sub_q;
    if (out_fire && head_data) begin
      word_d = word_end ? '0 : word_q + WordW'(1);
      sub_d  = sub_end ? '0 : sub_q + RW'(1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      word_q <= '0;
      sub_q  <= '0;
    end else begin
      word_q <= word_d;
      sub_q  <= sub_d;
    end
  end

  // The head in a register (OutReg = 1, for clock rate: the gearbox's pop and the reader's ready
  // start from a flip-flop, not from the tag RAM's read mux).
  cube5_frame_fifo #(.Width(TagW), .Depth(TagDepth), .OutReg(1)) u_tags (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (s2_fire),
    .d_i     (tag_word),
    .pop_i   (pop),
    .q_o     (head),
    .empty_o (tag_empty),
    .full_o  (tag_full)
  );

  // The item: the sub-th group of P voxels of the reader's beat (low VoxelW bits of each 16-bit
  // word), or zeros for a skip or error item.
  logic [16*P-1:0]     group;
  logic [P*VoxelW-1:0] lanes;
  logic                resp_err;
  if (R == 1) begin : gen_one_group
    assign group = rd_out_data[16*P-1:0];
    logic unused_sub;
    assign unused_sub = ^sub_q;
  end else begin : gen_groups
    assign group = rd_out_data[sub_q * 16 * P +: 16 * P];
  end
  assign resp_err = head_data && (rd_out_data[DataW+2:DataW+1] != 2'b00);
  always_comb begin
    for (int l = 0; l < P; l++) begin
      lanes[l*VoxelW +: VoxelW] = head_data ? group[l*16 +: VoxelW] : '0;
    end
  end

  assign out_data_o = {resp_err, head_err, head_last && (!head_data || word_end),
                       head_skip, head_data ? word_q : WordW'(0), head_blk, lanes};

  // Bits of the reader's word this unit does not use: the upper voxel bits (VoxelW < 16) and the
  // reader's last flag (checked by an assertion below).
  logic unused_rd;
  assign unused_rd = ^{rd_out_data[DataW], group};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_vol_fetch: output changed while stalled");
  // The reader's command ends exactly where the block's last group is taken.
  BlockEndsWithCommand: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rd_out_ready |-> rd_out_data[DataW] == word_end)
    else $error("cube5_vol_fetch: a block's beats and the reader's command are out of step");
  // Data beats only for a data block at the head.
  NoBeatWithoutBlock: assert property (@(posedge clk_i) disable iff (!rst_ni)
      rd_out_valid |-> head_valid)
    else $error("cube5_vol_fetch: a beat arrived with no block tag waiting");
`endif

endmodule
