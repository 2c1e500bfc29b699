// cube5_section_buf: the accelerator's section buffer (issue 12; docs/numerics/section_buf.md,
// design in docs/accel.md; patent [37], [43], [54]-[57]). Takes cube5_vol_fetch's items of one
// section (slab by slab: B slices, block rows, block columns) and gives beams of P voxels along
// the frame's i axis in the frame's order (slice, row, beat), with the edge voxels A0 - 1,
// A0 + ns, A0 + ns + 1 beside each row's first and last beam. Two halves: slab t + 1 is written
// while slab t is read. P banks with voxel (ci, j, lk) in bank (ci + j + lk) mod P: an item
// writes every bank at most once, a beam reads every bank once (conflict-free, [37]). With
// ItemGroups = 2 an item is two P-groups and the banks are 2P: a group bit g beside the skew
// sends the two groups to different banks (docs/numerics/section_buf.md, "Storage").
//
//   in ─► accept: (i, j, k) of lane 0 ─► w1 ─► per lane: column, address ─► wb
//         present flags (a word per block row)      ─► per bank: rotate by (ci + j + lk) mod P ─► w2
//                                                              ▼ write     (edges: 3 x P banks)
//                                            P banks x 2 halves ──► read (slice, row, beat)
//   out ◄── FIFO (8) ◄── rotate back by (j + lk) mod P, zero absent blocks ◄── d2 ◄── d ◄── issue
module cube5_section_buf #(
  /// Voxels per item and per beam.
  parameter int unsigned P = 4,
  /// Voxel bits.
  parameter int unsigned VoxelW = 12,
  /// Largest volume edge (a power of two, 8..1024).
  parameter int unsigned MaxDim = 64,
  /// Block edge B: a power of two, max(2, P) <= B <= 16, B < MaxDim.
  parameter int unsigned BlockDim = 8,
  /// Section width S in anchors: a power of two, BlockDim <= S < MaxDim.
  parameter int unsigned Section = 16,
  /// P-groups per input item, G: 1, or 2 (P <= 4, Section >= 2 P): an item is G P voxels.
  parameter int unsigned ItemGroups = 1
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input valid.
  input  logic in_valid_i,
  /// The unit takes the input (low while the half being written is still full).
  output logic in_ready_o,
  /// op (1), then a fetch item {lanes, blk_x, blk_y, blk_z, word, skip, last, error, resp_err}
  /// or a section command {axis_k, reversed, ni, nj, nk, a0}, LSB first.
  input  logic [cube5_section_buf_pkg::in_w(ItemGroups * P, VoxelW, MaxDim, BlockDim)-1:0] in_data_i,

  /// Beam valid.
  output logic out_valid_o,
  /// Consumer takes the beam.
  input  logic out_ready_i,
  /// lanes (P x VoxelW), lo, hi0, hi1 (VoxelW each), row_first, row_last, slice_last, last,
  /// error, LSB first.
  output logic [cube5_section_buf_pkg::out_w(P, VoxelW)-1:0] out_data_o
);
  // ==============================================================================================
  // Derived sizes
  // ==============================================================================================

  localparam int unsigned M         = $clog2(MaxDim);
  localparam int unsigned DimW      = M + 1;
  localparam int unsigned NbW       = cube5_vol_fetch_pkg::nb_w(MaxDim, BlockDim);
  localparam int unsigned NbCW      = NbW + 1;
  localparam int unsigned G         = ItemGroups;
  localparam int unsigned Q         = G * P;                     // voxels per item
  localparam int unsigned LG        = G - 1;                     // log2 G
  localparam int unsigned WordW     = cube5_vol_fetch_pkg::word_w(Q, BlockDim);
  localparam int unsigned InW       = cube5_section_buf_pkg::in_w(Q, VoxelW, MaxDim, BlockDim);
  localparam int unsigned OutW      = cube5_section_buf_pkg::out_w(P, VoxelW);
  localparam int unsigned BW        = $clog2(BlockDim);
  localparam int unsigned PW        = (P > 1) ? $clog2(P) : 1;   // a lane or bank number
  localparam int unsigned NBank     = G * P;                     // banks (and banks per edge)
  localparam int unsigned GPW       = (NBank > 1) ? $clog2(NBank) : 1;
  localparam int unsigned SW        = $clog2(Section);
  localparam int unsigned Groups    = BlockDim * BlockDim * BlockDim / Q;   // items per block
  localparam int unsigned BPP       = BlockDim / P;              // P-groups per block row
  localparam int unsigned SP        = Section / P;               // beats per full row
  localparam int unsigned MW        = (SP > 1) ? $clog2(SP) : 1;
  localparam int unsigned BankDepth = 2 * BlockDim * MaxDim * SP / G;
  localparam int unsigned BAW       = $clog2(BankDepth);
  localparam int unsigned EdgeDepth = 2 * MaxDim * BPP / G;
  localparam int unsigned EAW       = $clog2(EdgeDepth);
  localparam int unsigned NBR       = MaxDim / BlockDim;         // block rows of a slab
  localparam int unsigned CB        = Section / BlockDim + 2;    // block columns of a slab
  localparam int unsigned PresW     = 1 + NbW;                   // a present-flag row
  // Every size is a power of two: products and quotients below are shifts (log2 of each).
  localparam int unsigned LP        = $clog2(P);
  localparam int unsigned LBPP      = $clog2(BPP);
  localparam int unsigned LSP       = $clog2(SP);
  localparam int unsigned LSQ       = LSP - LG;                  // log2(S / Q)
  localparam int unsigned LQ        = LP + LG;                   // log2 Q
  localparam int unsigned CiW       = M + 3;                     // signed column, -MaxDim..2 MaxDim
  localparam int unsigned KW        = BW + 1;                    // slices of a slab, 0..B
  localparam int unsigned FifoDepth = 8;
  localparam int unsigned FifoW     = $clog2(FifoDepth);

  if (P != 1 && P != 2 && P != 4 && P != 8) begin : gen_bad_p
    $fatal(1, "cube5_section_buf: P must be 1, 2, 4 or 8");
  end
  if (VoxelW < 4 || VoxelW > 16) begin : gen_bad_voxel_w
    $fatal(1, "cube5_section_buf: VoxelW must be in 4..16");
  end
  if (MaxDim < 8 || MaxDim > 1024 || (1 << M) != MaxDim) begin : gen_bad_max_dim
    $fatal(1, "cube5_section_buf: MaxDim must be a power of two in 8..1024");
  end
  if ((1 << BW) != BlockDim || BlockDim < 2 || BlockDim < P || BlockDim > 16
      || BlockDim >= MaxDim) begin : gen_bad_block
    $fatal(1, "cube5_section_buf: BlockDim must be a power of two, max(2, P) <= B <= 16, B < MaxDim");
  end
  if ((1 << SW) != Section || Section < BlockDim || Section >= MaxDim) begin : gen_bad_section
    $fatal(1, "cube5_section_buf: Section must be a power of two, BlockDim <= Section < MaxDim");
  end
  if (G != 1 && (G != 2 || P > 4 || Section < 2 * P)) begin : gen_bad_groups
    $fatal(1, "cube5_section_buf: ItemGroups must be 1, or 2 with P <= 4 and Section >= 2 P");
  end

  // ==============================================================================================
  // Input fields
  // ==============================================================================================

  localparam int unsigned ItBlk  = 1 + Q * VoxelW;
  localparam int unsigned ItWord = ItBlk + 3 * NbW;
  localparam int unsigned ItSkip = ItWord + WordW;
  localparam int unsigned CmdNi  = 4;
  localparam int unsigned CmdA0  = CmdNi + 3 * DimW;

  logic                op;
  logic [Q*VoxelW-1:0] it_lanes;
  logic [NbW-1:0]      it_bx, it_by, it_bz;
  logic [WordW-1:0]    it_word;
  logic                it_skip, it_error;
  logic [1:0]          cm_axis;
  logic                cm_rev;
  logic [DimW-1:0]     cm_ni, cm_nj, cm_nk;
  logic [M-1:0]        cm_a0;
  assign op       = in_data_i[0];
  assign it_lanes = in_data_i[1 +: Q * VoxelW];
  assign it_bx    = in_data_i[ItBlk +: NbW];
  assign it_by    = in_data_i[ItBlk + NbW +: NbW];
  assign it_bz    = in_data_i[ItBlk + 2 * NbW +: NbW];
  assign it_word  = in_data_i[ItWord +: WordW];
  assign it_skip  = in_data_i[ItSkip];
  assign it_error = in_data_i[ItSkip + 2];
  assign cm_axis  = in_data_i[1 +: 2];
  assign cm_rev   = in_data_i[3];
  assign cm_ni    = in_data_i[CmdNi +: DimW];
  assign cm_nj    = in_data_i[CmdNi + DimW +: DimW];
  assign cm_nk    = in_data_i[CmdNi + 2 * DimW +: DimW];
  assign cm_a0    = in_data_i[CmdA0 +: M];

  // `last` and `resp_err` of an item are not used (docs/numerics/section_buf.md, "Protocol"); the
  // bits above the longer payload are padding.
  logic unused_in;
  assign unused_in = ^{in_data_i[ItSkip + 1], in_data_i[ItSkip + 3 +: InW - ItSkip - 3],
                       in_data_i[CmdA0 + M +: InW - CmdA0 - M]};

  // ==============================================================================================
  // Writer: the section being written, its slab counter and the half it fills
  // ==============================================================================================

  logic            act_q, act_d;             // a section is being written
  logic            axx_q, axx_d, axz_q, axz_d;  // axis_k = 0 (slice axis x), axis_k = 2 (z)
  logic            rev_q, rev_d;
  logic [DimW-1:0] nj_q, nj_d, ns_q, ns_d;
  logic [M-1:0]    a0_q, a0_d;
  // Block counts minus one and the present-column offset a0 / B - 1, so the per-item compares
  // on the acceptance path need no adder.
  logic [NbCW-1:0] nbj1_q, nbj1_d, nbk1_q, nbk1_d, sechi1_q, sechi1_d, t_q, t_d;
  // The present-flag column c's block column a0 / B - 1 + c (CB of them): the item's column
  // test is an equality, no subtraction.
  logic [CB*NbCW-1:0] pofs_q, pofs_d;
  logic            wh_q, wh_d;                // the half being filled
  // The row's high edge columns a0 + ns and a0 + ns + 1 lie past the volume (a0 + ns = min(a0 + S,
  // ni), so a0 + ns >= ni is ni - a0 <= S): kept per section.
  logic            hi00_q, hi00_d, hi10_q, hi10_d;

  logic [1:0] full_q, full_d;                 // half h holds a slab (or an error) to read
  logic [1:0] held_q, held_d;                 // half h is closed (full, or its last write in flight)

  logic in_fire, cmd_fire, item_fire;
  assign in_ready_o = !held_q[wh_q];
  assign in_fire    = in_valid_i && in_ready_o;
  assign cmd_fire   = in_fire && op && !act_q;
  assign item_fire  = in_fire && !op && act_q && !it_error;

  // The command's checks and derived sizes.
  logic            cm_refused;
  logic [DimW-1:0] cm_ns, cm_rest, cm_n;
  logic [NbCW-1:0] cm_nbi, cm_sechi_cap;
  always_comb begin
    cm_refused = (cm_axis == 2'd3) || (cm_a0[SW-1:0] != '0) || (DimW'(cm_a0) >= cm_ni);
    for (int unsigned d = 0; d < 3; d++) begin
      cm_n = (d == 0) ? cm_ni : ((d == 1) ? cm_nj : cm_nk);
      if (cm_n == '0 || cm_n > DimW'(MaxDim) || (cm_n & DimW'(P - 1)) != '0) cm_refused = 1'b1;
    end
    cm_rest      = cm_ni - DimW'(cm_a0);
    cm_ns        = (cm_rest > DimW'(Section)) ? DimW'(Section) : cm_rest;
    cm_nbi       = NbCW'((cm_ni + DimW'(BlockDim - 1)) >> BW);
    cm_sechi_cap = NbCW'(((DimW'(cm_a0) + DimW'(Section)) >> BW) + DimW'(1));
  end

  // Lane 0 of each P-group of an item (group word w G + g) in volume and frame coordinates.
  logic [M-1:0]    x0, y0, z0;
  logic [G*M-1:0]  i0, j0, k0;                 // group g at g M
  logic [NbW-1:0]  bi0, bj0;
  logic            axx0;                       // slice axis x: the lanes run along k
  logic [31:0]     w;
  always_comb begin
    for (int unsigned g = 0; g < G; g++) begin
      w  = (32'(it_word) << LG) | g;
      x0 = M'((32'(it_bx) << BW) | ((w & (BPP - 1)) << LP));
      y0 = M'((32'(it_by) << BW) | ((w >> LBPP) & (BlockDim - 1)));
      z0 = M'((32'(it_bz) << BW) | (w >> (LBPP + BW)));
      // axis_k 0: (i, j, k) = (y, z, x); 1: (x, z, y); 2: (x, y, z). Two flags, so every field
      // is one 2:1 multiplexer (k: two).
      i0[g * M +: M] = axx_q ? y0 : x0;
      j0[g * M +: M] = axz_q ? y0 : z0;
      k0[g * M +: M] = axx_q ? x0 : (axz_q ? z0 : y0);
    end
    bi0  = axx_q ? it_by : it_bx;
    bj0  = axz_q ? it_by : it_bz;
    axx0 = axx_q;
  end

  // Only the slice inside the slab (k mod B) is stored; the slab is the writer's counter.
  logic unused_k;
  assign unused_k = ^k0;

  logic item_close;                           // the item closes its slab
  assign item_close = (NbCW'(bj0) == nbj1_q) && (NbCW'(bi0) == sechi1_q)
                   && (it_skip || it_word == WordW'(Groups - 1));

  // Slab t's slices: bk = reversed ? nbk - 1 - t : t, nkl = min(B, nk - B bk): B but for the
  // slab bk = nbk - 1 (t = 0 reversed, t = nbk - 1 forward), which holds ktail = (nk - 1) mod B + 1
  // slices (kept per section, so no adder on the slab-closing path).
  logic [KW-1:0] ktail_q, ktail_d;
  logic          tlast, kend;
  logic [KW-1:0] nkl_w;
  always_comb begin
    tlast = (t_q == nbk1_q);
    kend  = rev_q ? (t_q == '0) : tlast;
    nkl_w = kend ? ktail_q : KW'(BlockDim);
  end

  always_comb begin
    act_d     = act_q;
    axx_d     = axx_q;
    axz_d     = axz_q;
    rev_d     = rev_q;
    hi00_d    = hi00_q;
    hi10_d    = hi10_q;
    nj_d      = nj_q;
    ktail_d   = ktail_q;
    ns_d      = ns_q;
    a0_d      = a0_q;
    nbj1_d    = nbj1_q;
    nbk1_d    = nbk1_q;
    sechi1_d  = sechi1_q;
    pofs_d    = pofs_q;
    t_d       = t_q;
    wh_d      = wh_q;
    if (cmd_fire) begin
      act_d     = !cm_refused;
      axx_d     = (cm_axis == 2'd0);
      axz_d     = (cm_axis == 2'd2);
      rev_d     = cm_rev;
      hi00_d    = (cm_rest <= DimW'(Section));
      hi10_d    = (cm_rest <= DimW'(Section + 1));
      nj_d      = cm_nj;
      ktail_d   = KW'(32'(BW'(cm_nk - DimW'(1)))) + KW'(1);
      ns_d      = cm_ns;
      a0_d      = cm_a0;
      nbj1_d    = NbCW'((cm_nj + DimW'(BlockDim - 1)) >> BW) - NbCW'(1);
      nbk1_d    = NbCW'((cm_nk + DimW'(BlockDim - 1)) >> BW) - NbCW'(1);
      sechi1_d  = ((cm_sechi_cap < cm_nbi) ? cm_sechi_cap : cm_nbi) - NbCW'(1);
      for (int unsigned c = 0; c < CB; c++) begin
        pofs_d[c * NbCW +: NbCW] = NbCW'(cm_a0 >> BW) + NbCW'(c) - NbCW'(1);
      end
      t_d       = '0;
      if (cm_refused) wh_d = !wh_q;            // the error takes a half
    end
    if (item_fire) begin
      if (item_close) begin
        wh_d = !wh_q;
        t_d  = t_q + NbCW'(1);
        if (t_q == nbk1_q) act_d = 1'b0;
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      act_q     <= 1'b0;
      wh_q      <= 1'b0;
      t_q       <= '0;
    end else begin
      act_q     <= act_d;
      wh_q      <= wh_d;
      t_q       <= t_d;
    end
  end
  // Section registers: qualified by act_q.
  always_ff @(posedge clk_i) begin
    axx_q   <= axx_d;
    axz_q   <= axz_d;
    rev_q   <= rev_d;
    hi00_q  <= hi00_d;
    hi10_q  <= hi10_d;
    nj_q    <= nj_d;
    ktail_q <= ktail_d;
    ns_q    <= ns_d;
    a0_q    <= a0_d;
    nbj1_q   <= nbj1_d;
    nbk1_q   <= nbk1_d;
    sechi1_q <= sechi1_d;
    pofs_q   <= pofs_d;
  end

  // ==============================================================================================
  // Per-half descriptors (written with the slab's closing input, read while the half is full)
  // ==============================================================================================

  logic [1:0]      de_err_q, de_last_q, de_rev_q, de_lo0_q, de_hi00_q, de_hi10_q;
  logic [1:0]      de_axx_q, de_axz_q;        // the slice axis (the group bits, G = 2)
  // The reader's last beat, row and slice, minus one (its compares need no adder).
  logic [MW-1:0]   de_m1_q [2];
  logic [M-1:0]    de_nj1_q [2];
  logic [KW-1:0]   de_nkl1_q [2];
  // The present-flag columns of the high edge voxels a0 + ns and a0 + ns + 1.
  localparam int unsigned CBW = $clog2(CB);
  logic [CBW-1:0]  de_c0_q [2], de_c1_q [2];

  logic desc_we, desc_err;
  assign desc_we  = (cmd_fire && cm_refused) || (item_fire && item_close);
  assign desc_err = cmd_fire;

  // Constant indices (a loop over the halves): Yosys makes a bit-select write with a variable
  // index a 32-bit offset adder in front of a decoder.
  always_ff @(posedge clk_i) begin
    for (int unsigned h = 0; h < 2; h++) begin
      if (desc_we && wh_q == 1'(h)) begin
        de_err_q[h]  <= desc_err;
        de_last_q[h] <= tlast;
        de_rev_q[h]  <= rev_q;
        de_axx_q[h]  <= axx_q;
        de_axz_q[h]  <= axz_q;
        de_lo0_q[h]  <= (a0_q == '0);
        de_hi00_q[h] <= hi00_q;
        de_hi10_q[h] <= hi10_q;
        de_m1_q[h]   <= MW'((ns_q >> LP) - DimW'(1));
        de_nj1_q[h]  <= M'(nj_q - DimW'(1));
        de_nkl1_q[h] <= nkl_w - KW'(1);
        de_c0_q[h]   <= CBW'((32'(ns_q) >> BW) + 1);
        de_c1_q[h]   <= CBW'(((32'(ns_q) + 1) >> BW) + 1);
      end
    end
  end

  // ==============================================================================================
  // Present flags: a word of CB flags per block row of each half (LUT RAM). The items of a block
  // row arrive together (block columns in order), so the row's flags gather in a register and
  // are written once, with the row's closing item; every row of a slab is rewritten.
  // ==============================================================================================

  logic [CB-1:0]    pacc_q, pacc_d, pacc_next;
  logic             popen_q, popen_d;         // a block row has begun
  logic             row_close, pres_we_q;
  logic [PresW-1:0] pres_waddr_q;
  logic [CB-1:0]    pres_wdata_q;
  assign row_close = (NbCW'(bi0) == sechi1_q)
                  && (it_skip || it_word == WordW'(Groups - 1));

  always_comb begin
    pacc_next = popen_q ? pacc_q : '0;
    for (int unsigned c = 0; c < CB; c++) begin
      if (!it_skip && NbCW'(bi0) == pofs_q[c * NbCW +: NbCW]) pacc_next[c] = 1'b1;
    end
    pacc_d  = pacc_q;
    popen_d = popen_q;
    if (item_fire) begin
      pacc_d  = pacc_next;
      popen_d = !row_close;
    end
    if (cmd_fire) popen_d = 1'b0;
  end
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      popen_q   <= 1'b0;
      pres_we_q <= 1'b0;
    end else begin
      popen_q   <= popen_d;
      pres_we_q <= item_fire && row_close;
    end
  end
  always_ff @(posedge clk_i) begin
    pacc_q       <= pacc_d;
    pres_waddr_q <= {wh_q, bj0};
    pres_wdata_q <= pacc_next;
  end

  // Written in the cycle after the row's closing item (before its half is handed to the reader).
  logic [CB-1:0] pres_mem [2 * NBR];
  always_ff @(posedge clk_i) begin
    if (pres_we_q) pres_mem[pres_waddr_q] <= pres_wdata_q;
  end

  // ==============================================================================================
  // Write stage 1: each P-group's column, row and slice
  // ==============================================================================================

  logic                 w1_q, w1close_q, w1half_q, w1axx_q;
  logic signed [CiW-1:0] w1ci_q [G];
  logic [M-1:0]         w1j_q [G];
  logic [BW-1:0]        w1lk_q [G];
  logic [DimW-1:0]      w1ns_q, w1ns1_q;            // ns and ns + 1
  logic [Q*VoxelW-1:0]  w1lanes_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      w1_q      <= 1'b0;
      w1close_q <= 1'b0;
    end else begin
      w1_q      <= item_fire && !it_skip;
      w1close_q <= desc_we;
    end
  end
  always_ff @(posedge clk_i) begin
    w1half_q  <= wh_q;
    w1axx_q   <= axx0;
    for (int unsigned g = 0; g < G; g++) begin
      w1ci_q[g] <= $signed(CiW'(i0[g * M +: M])) - $signed(CiW'(a0_q));
      w1j_q[g]  <= j0[g * M +: M];
      w1lk_q[g] <= BW'(k0[g * M +: M]);
    end
    w1ns_q    <= ns_q;
    w1ns1_q   <= ns_q + DimW'(1);
    w1lanes_q <= it_lanes;
  end

  // Per lane: column, slice, which store it goes to, its address there. A P-group whose lanes
  // run along i (slice axis y or z) starts at a column ci0 that is a multiple of P, and ns is a
  // multiple of P (a0 a multiple of S, ni of P), so its lanes are all in 0..ns - 1 or all out,
  // their main-bank word is ci0 / Q, and edge column c goes to lane c mod P when
  // ci0 = c - (c mod P). A group of slice axis x has one column for all lanes. So every compare
  // is one of ci0 (no per-lane adder in front of the compares). Lane q = g P + l is lane l of
  // group g.
  localparam int unsigned Lane1 = 1 % P;          // the lane of column ns + 1 (along i)
  logic signed [CiW-1:0] ns_s, ns1_s, ns2_s;
  logic                  c_main, c_m1, c_mp, c_ns, c_ns1, c_ns2;
  logic [BW-1:0]         lk_l;
  logic [31:0]           ev;                       // an edge voxel's word before the group split
  logic [Q-1:0]          l_main;
  logic [3*Q-1:0]        l_edge;                   // lane q, edge column c at q 3 + c
  logic [G*BAW-1:0]      l_maddr;                  // per group, at its lane 0's slice
  logic [G*EAW-1:0]      l_eaddr;                  // per group (its lanes share the word)
  logic [Q*GPW-1:0]      l_ebank;
  logic [G*PW-1:0]       w1rot;
  logic                  w1swap;                   // group 0's bank group g (1: the groups swap)
  always_comb begin
    ns_s   = $signed(CiW'(w1ns_q));
    ns1_s  = $signed(CiW'(w1ns1_q));
    ns2_s  = (P == 1) ? ns1_s : ns_s;             // ns + 1 - (1 mod P)
    for (int unsigned g = 0; g < G; g++) begin
      c_main = !w1ci_q[g][CiW-1] && (w1ci_q[g] < ns_s);
      c_m1   = (w1ci_q[g] == -$signed(CiW'(1)));
      c_mp   = (w1ci_q[g] == -$signed(CiW'(P)));
      c_ns   = (w1ci_q[g] == ns_s);
      c_ns1  = (w1ci_q[g] == ns1_s);
      c_ns2  = (w1ci_q[g] == ns2_s);
      for (int unsigned l = 0; l < P; l++) begin
        lk_l = w1axx_q ? w1lk_q[g] + BW'(l) : w1lk_q[g];
        l_main[g * P + l] = c_main;
        if (w1axx_q) begin
          l_edge[(g * P + l) * 3 +: 3] = {c_ns1, c_ns, c_m1};
        end else begin
          l_edge[(g * P + l) * 3 +: 3] = {(l == Lane1) && c_ns2, (l == 0) && c_ns,
                                          (l == P - 1) && c_mp};
        end
        if (l == 0) begin
          l_maddr[g * BAW +: BAW] = BAW'((((((32'(w1half_q) << BW) | 32'(lk_l)) << M)
                                          | 32'(w1j_q[g])) << LSQ)
                                          | (32'(w1ci_q[g][CiW-2:0]) >> LQ));
        end
        // Edge word v = (h MaxDim + j) (B / P) + lk / P; with two groups its parity picks the
        // bank group and the word is v / 2.
        ev = (((32'(w1half_q) << M) | 32'(w1j_q[g])) << LBPP) | (32'(lk_l) >> LP);
        l_eaddr[g * EAW +: EAW] = EAW'(ev >> LG);
        l_ebank[(g * P + l) * GPW +: GPW] = GPW'((32'(lk_l) & (P - 1))
                                                 | (((G == 2) ? (ev & 1) : 0) << LP));
      end
      w1rot[g * PW +: PW] = PW'((32'(w1ci_q[g][CiW-2:0]) + 32'(w1j_q[g]) + 32'(w1lk_q[g]))
                                & (P - 1));
    end
    // A group's g: its word parity (the group's index) xor bit 0 of ci / P, but the parity alone
    // when the lanes run along i and B >= 2P (then the two agree). The other group has the other g.
    if (G == 1 || (BPP >= 2 && !w1axx_q)) begin
      w1swap = 1'b0;
    end else begin
      w1swap = 1'((32'(w1ci_q[0][CiW-2:0]) >> LP) & 1);
    end
  end

  // ==============================================================================================
  // Write stage b: the lanes' decisions and addresses registered (the column compares and the
  // address adders are one cycle, the rotation into the banks the next)
  // ==============================================================================================

  logic                wb_q, wbclose_q, wbhalf_q;
  logic [Q-1:0]        wbmain_q;
  logic [3*Q-1:0]      wbedge_q;
  logic [G*BAW-1:0]    wbmaddr_q;
  logic [G*EAW-1:0]    wbeaddr_q;
  logic                wbaxx_q;
  logic [Q*GPW-1:0]    wbebank_q;
  logic [G*PW-1:0]     wbrot_q;
  logic [Q*VoxelW-1:0] wblanes_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      wb_q      <= 1'b0;
      wbclose_q <= 1'b0;
    end else begin
      wb_q      <= w1_q;
      wbclose_q <= w1close_q;
    end
  end
  always_ff @(posedge clk_i) begin
    wbhalf_q  <= w1half_q;
    wbaxx_q   <= w1axx_q;
    // Slot s holds the group whose g is s (with two groups their g differ): a swap when group 0
    // has g = 1, so that the banks below take from a fixed slot (loops over constant indices).
    for (int unsigned s = 0; s < G; s++) begin
      for (int unsigned g = 0; g < G; g++) begin
        if ((g == s) != w1swap) begin
          wbmain_q[s * P +: P]                     <= l_main[g * P +: P];
          wbedge_q[s * 3 * P +: 3 * P]             <= l_edge[g * 3 * P +: 3 * P];
          wbmaddr_q[s * BAW +: BAW]                <= l_maddr[g * BAW +: BAW];
          wbeaddr_q[s * EAW +: EAW]                <= l_eaddr[g * EAW +: EAW];
          wbebank_q[s * P * GPW +: P * GPW]        <= l_ebank[g * P * GPW +: P * GPW];
          wbrot_q[s * PW +: PW]                    <= w1rot[g * PW +: PW];
          wblanes_q[s * P * VoxelW +: P * VoxelW]  <= w1lanes_q[g * P * VoxelW +: P * VoxelW];
        end
      end
    end

  end

  // ==============================================================================================
  // Write stage 2: per bank, the lane it takes (registered in front of the RAMs)
  // ==============================================================================================

  logic [NBank-1:0]          w2we_q, w2we_d;
  logic [NBank*BAW-1:0]      w2addr_q, w2addr_d;
  logic [NBank*VoxelW-1:0]   w2data_q, w2data_d;
  logic [3*NBank-1:0]        e2we_q, e2we_d;      // edge column c, bank e at c G P + e
  logic [3*NBank*EAW-1:0]    e2addr_q, e2addr_d;
  logic [3*NBank*VoxelW-1:0] e2data_q, e2data_d;
  logic                      w2close_q, w2half_q;

  always_comb begin
    // Bank s P + b takes lane (b - rot) mod P of slot s (loops over constant indices: no index
    // arithmetic).
    w2we_d   = '0;
    w2addr_d = '0;
    w2data_d = '0;
    for (int unsigned s = 0; s < G; s++) begin
      for (int unsigned b = 0; b < P; b++) begin
        for (int unsigned l = 0; l < P; l++) begin
          if (((l + 32'(wbrot_q[s * PW +: PW])) & (P - 1)) == b) begin
            w2we_d[s * P + b] = wb_q && wbmain_q[s * P + l];
            // The lanes of a group share its word but for slice axis x, where lane l's slice
            // is lane 0's (a multiple of P) plus l: a field of the word, set without an adder.
            w2addr_d[(s * P + b) * BAW +: BAW]       = wbmaddr_q[s * BAW +: BAW]
                | (wbaxx_q ? BAW'(l << (LSQ + M)) : BAW'(0));
            w2data_d[(s * P + b) * VoxelW +: VoxelW] = wblanes_q[(s * P + l) * VoxelW +: VoxelW];
          end
        end
      end
    end
    // Edge bank e = b + P ee of column c: from each slot only one lane can reach it, lane b
    // with slice axis x (lane l's slice is lk0 + l, lk0 a multiple of P), else the column's lane
    // (P - 1 for lo, 0 for hi0, 1 mod P for hi1).
    for (int unsigned c = 0; c < 3; c++) begin
      for (int unsigned e = 0; e < NBank; e++) begin
        e2we_d[c * NBank + e] = 1'b0;
        e2addr_d[(c * NBank + e) * EAW +: EAW]       = wbeaddr_q[0 +: EAW];
        e2data_d[(c * NBank + e) * VoxelW +: VoxelW] = wblanes_q[0 +: VoxelW];
        for (int unsigned s = 0; s < G; s++) begin
          for (int unsigned l = 0; l < P; l++) begin
            if (((wbaxx_q && l == e % P) || (!wbaxx_q && l == ((c == 0) ? P - 1 : ((c == 1) ? 0 : Lane1))))
                && wb_q && wbedge_q[(s * P + l) * 3 + c]
                && wbebank_q[(s * P + l) * GPW +: GPW] == GPW'(e)) begin
              e2we_d[c * NBank + e] = 1'b1;
              e2addr_d[(c * NBank + e) * EAW +: EAW]       = wbeaddr_q[s * EAW +: EAW];
              e2data_d[(c * NBank + e) * VoxelW +: VoxelW] = wblanes_q[(s * P + l) * VoxelW +: VoxelW];
            end
          end
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      w2we_q    <= '0;
      e2we_q    <= '0;
      w2close_q <= 1'b0;
    end else begin
      w2we_q    <= w2we_d;
      e2we_q    <= e2we_d;
      w2close_q <= wbclose_q;
    end
  end
  always_ff @(posedge clk_i) begin
    w2addr_q <= w2addr_d;
    w2data_q <= w2data_d;
    e2addr_q <= e2addr_d;
    e2data_q <= e2data_d;
    w2half_q <= wbhalf_q;
  end

  // ==============================================================================================
  // Reader: slices in sweep order, rows, beats; one beam read per clock
  // ==============================================================================================

  logic          rh_q, rh_d;
  logic [KW-1:0] rn_q, rn_d;                      // slice of the slab, in sweep order
  logic [M-1:0]  rj_q, rj_d;
  logic [MW-1:0] rm_q, rm_d;

  logic [FifoW:0] fcnt_q;
  logic [FifoW:0] cred_q;                         // beams issued and not yet taken
  logic           dv_q, dv2_q, pop;
  logic       issue, r_err, r_last_slab, r_rev, m_last, j_last, n_last, slab_done;
  logic [MW-1:0]   r_m1;
  logic [M-1:0]    r_nj1;
  logic [KW-1:0]   r_nkl1;
  logic [BW-1:0]   r_lk;
  always_comb begin
    r_err       = de_err_q[rh_q];
    r_last_slab = de_last_q[rh_q];
    r_rev       = de_rev_q[rh_q];
    r_m1        = de_m1_q[rh_q];
    r_nj1       = de_nj1_q[rh_q];
    r_nkl1      = de_nkl1_q[rh_q];
    r_lk        = r_rev ? BW'(r_nkl1 - rn_q) : BW'(rn_q);
    m_last      = (rm_q == r_m1);
    j_last      = (rj_q == r_nj1);
    n_last      = (rn_q == r_nkl1);
    slab_done   = r_err || (m_last && j_last && n_last);
    issue       = full_q[rh_q] && !cred_q[FifoW];   // fewer than FifoDepth in flight or stored
  end

  always_comb begin
    rh_d = rh_q;
    rn_d = rn_q;
    rj_d = rj_q;
    rm_d = rm_q;
    if (issue) begin
      if (slab_done) begin
        rh_d = !rh_q;
        rn_d = '0;
        rj_d = '0;
        rm_d = '0;
      end else if (m_last) begin
        rm_d = '0;
        if (j_last) begin
          rj_d = '0;
          rn_d = rn_q + KW'(1);
        end else begin
          rj_d = rj_q + M'(1);
        end
      end else begin
        rm_d = rm_q + MW'(1);
      end
    end
  end

  // A half becomes full when the write of its slab's last item lands (w2), free at its last issue.
  // The writer moves on when it closes a half (held); the reader sees it three cycles later (full).
  always_comb begin
    full_d = full_q;
    held_d = held_q;
    for (int unsigned h = 0; h < 2; h++) begin    // constant indices, as the descriptors
      if (issue && slab_done && rh_q == 1'(h)) begin
        full_d[h] = 1'b0;
        held_d[h] = 1'b0;
      end
      if (w2close_q && w2half_q == 1'(h)) full_d[h] = 1'b1;
      if (desc_we && wh_q == 1'(h)) held_d[h] = 1'b1;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      rh_q   <= 1'b0;
      rn_q   <= '0;
      rj_q   <= '0;
      rm_q   <= '0;
      full_q <= '0;
      held_q <= '0;
    end else begin
      rh_q   <= rh_d;
      rn_q   <= rn_d;
      rj_q   <= rj_d;
      rm_q   <= rm_d;
      full_q <= full_d;
      held_q <= held_d;
    end
  end

  // Read addresses, the rotation back, and the present flags of the beam and the row's edges.
  logic [BAW-1:0] r_addr;
  logic [EAW-1:0] r_eaddr;
  logic [PW-1:0]  r_rot;
  logic [GPW-1:0] r_ebank;
  logic [P-1:0]   r_grp;                          // lane l's bank group
  logic [31:0]    r_ev;
  logic           r_c, r_axx, r_axz;
  logic [CB-1:0]  r_pres;
  logic [CBW-1:0] r_col;
  always_comb begin
    r_addr  = BAW'((((((32'(rh_q) << BW) | 32'(r_lk)) << M) | 32'(rj_q)) << LSQ)
                   | ((32'(rm_q) & (SP - 1)) >> LG));
    r_ev    = (((32'(rh_q) << M) | 32'(rj_q)) << LBPP) | (32'(r_lk) >> LP);
    r_eaddr = EAW'(r_ev >> LG);
    r_rot   = PW'((32'(rj_q) + 32'(r_lk)) & (P - 1));
    r_ebank = GPW'((32'(r_lk) & (P - 1)) | (((G == 2) ? (r_ev & 1) : 0) << LP));
    // Lane l (column ci = P m + l): g = the P-group word's parity pi xor c = bit 0 of m, or pi
    // alone when the lanes run along i and B >= 2P (docs/numerics/section_buf.md, "Storage").
    // pi: slice axis x: (lk / P) mod 2 (B >= 2P) or l mod 2 (B = P); axis y (B = P): lk mod 2;
    // axis z (B = P): j mod 2; along i with B >= 2P: c.
    r_c   = rm_q[0];
    r_axx = de_axx_q[rh_q];
    r_axz = de_axz_q[rh_q];
    for (int unsigned l = 0; l < P; l++) begin
      if (G == 1) begin
        r_grp[l] = 1'b0;
      end else if (BPP >= 2) begin
        r_grp[l] = r_axx ? (r_c ^ 1'((32'(r_lk) >> LP) & 1)) : r_c;
      end else if (r_axx) begin
        r_grp[l] = r_c ^ 1'(l & 1);
      end else begin
        r_grp[l] = r_c ^ (r_axz ? rj_q[0] : r_lk[0]);
      end
    end
    r_pres  = pres_mem[{rh_q, rj_q[M-1:BW]}];
    r_col   = CBW'(((32'(rm_q) << LP) >> BW) + 1);
  end

  // ==============================================================================================
  // The banks
  // ==============================================================================================

  logic [NBank*VoxelW-1:0]   bank_rd;
  logic [3*NBank*VoxelW-1:0] edge_rd;

  for (genvar b = 0; b < NBank; b++) begin : gen_bank
    cube5_section_buf_ram #(                    // reads and writes are in different halves
      .Depth(BankDepth),
      .Width(VoxelW),
      .AddrW(BAW)
    ) u_bank (
      .clk_i  (clk_i),
      .we_i   (w2we_q[b]),
      .waddr_i(w2addr_q[b * BAW +: BAW]),
      .wdata_i(w2data_q[b * VoxelW +: VoxelW]),
      .re_i   (issue),
      .raddr_i(r_addr),
      .rdata_o(bank_rd[b * VoxelW +: VoxelW])
    );
  end

  if (G == 1) begin : gen_edges
    for (genvar e = 0; e < 3 * NBank; e++) begin : gen_edge
      cube5_section_buf_ram #(                  // reads and writes are in different halves
        .Depth(EdgeDepth),
        .Width(VoxelW),
        .AddrW(EAW)
      ) u_edge (
        .clk_i  (clk_i),
        .we_i   (e2we_q[e]),
        .waddr_i(e2addr_q[e * EAW +: EAW]),
        .wdata_i(e2data_q[e * VoxelW +: VoxelW]),
        .re_i   (issue),
        .raddr_i(r_eaddr),
        .rdata_o(edge_rd[e * VoxelW +: VoxelW])
      );
    end
  end else begin : gen_edges
    // The group banks b and b + P of an edge column share a memory, one half each: an item that
    // writes both writes them at one word (docs/numerics/section_buf.md, "Storage").
    for (genvar c = 0; c < 3; c++) begin : gen_col
      for (genvar b = 0; b < P; b++) begin : gen_edge
        localparam int unsigned E0 = c * NBank + b;
        localparam int unsigned E1 = c * NBank + P + b;
        logic [2*VoxelW-1:0] rd;
        cube5_section_buf_eram #(               // reads and writes are in different halves
          .Depth(EdgeDepth),
          .Width(VoxelW),
          .PartW((VoxelW > 9) ? 18 : 9),
          .AddrW(EAW)
        ) u_edge (
          .clk_i  (clk_i),
          .we_i   ({e2we_q[E1], e2we_q[E0]}),
          .waddr_i(e2we_q[E0] ? e2addr_q[E0 * EAW +: EAW] : e2addr_q[E1 * EAW +: EAW]),
          .wdata_i({e2data_q[E1 * VoxelW +: VoxelW], e2data_q[E0 * VoxelW +: VoxelW]}),
          .re_i   (issue),
          .raddr_i(r_eaddr),
          .rdata_o(rd)
        );
        assign edge_rd[E0 * VoxelW +: VoxelW] = rd[0 +: VoxelW];
        assign edge_rd[E1 * VoxelW +: VoxelW] = rd[VoxelW +: VoxelW];
`ifndef SYNTHESIS
        a_edge_one_word: assert property (@(posedge clk_i) disable iff (!rst_ni)
            e2we_q[E0] && e2we_q[E1] |-> e2addr_q[E0 * EAW +: EAW] == e2addr_q[E1 * EAW +: EAW])
          else $error("cube5_section_buf: an item wrote an edge memory's halves at two words");
`endif
      end
    end
  end

  // ==============================================================================================
  // Data stage: rotate back, zero what is not present, into the output FIFO
  // ==============================================================================================

  // Stage d: the banks' (unregistered) outputs; stage d2: them registered (the block RAMs'
  // clock-to-output and the routing from them is a cycle of its own), then rotation and masks.
  logic [PW-1:0]  drot_q, drot_q2;
  logic [GPW-1:0] debank_q, debank_q2;
  logic [P-1:0]   dgrp_q, dgrp_q2;
  logic          dlane_q2, dlo_q2, dhi0_q2, dhi1_q2;
  // Stage d also holds the beam's present-flag word and which of its flags each voxel reads:
  // the flag selection is stage d's logic (not the issue cycle's, behind the LUT-RAM read).
  logic [CB-1:0]  dpres_q;
  logic [CBW-1:0] dcol_q, dc0_q, dc1_q;
  logic           dlane_ok_q, dlo_ok_q, dhi0_ok_q, dhi1_ok_q;
  logic           d_lane_ok, d_lo_ok, d_hi0_ok, d_hi1_ok;
  always_comb begin
    d_lane_ok = dlane_ok_q && dpres_q[dcol_q];
    d_lo_ok   = dlo_ok_q && dpres_q[0];
    d_hi0_ok  = dhi0_ok_q && dpres_q[dc0_q];
    d_hi1_ok  = dhi1_ok_q && dpres_q[dc1_q];
  end
  logic [4:0]    dflags_q, dflags_q2;               // row_first, row_last, slice_last, last, error
  logic [NBank*VoxelW-1:0]   bank_q2;
  logic [3*NBank*VoxelW-1:0] edge_q2;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      dv_q  <= 1'b0;
      dv2_q <= 1'b0;
    end else begin
      dv_q  <= issue;
      dv2_q <= dv_q;
    end
  end
  always_ff @(posedge clk_i) begin
    drot_q   <= r_rot;
    debank_q <= r_ebank;
    dgrp_q   <= r_grp;
    dpres_q    <= r_pres;
    dcol_q     <= r_col;
    dc0_q      <= de_c0_q[rh_q];
    dc1_q      <= de_c1_q[rh_q];
    dlane_ok_q <= !r_err;
    dlo_ok_q   <= !r_err && (rm_q == '0) && !de_lo0_q[rh_q];
    dhi0_ok_q  <= !r_err && m_last && !de_hi00_q[rh_q];
    dhi1_ok_q  <= !r_err && m_last && !de_hi10_q[rh_q];
    drot_q2   <= drot_q;
    debank_q2 <= debank_q;
    dgrp_q2   <= dgrp_q;
    dlane_q2  <= d_lane_ok;
    dlo_q2    <= d_lo_ok;
    dhi0_q2   <= d_hi0_ok;
    dhi1_q2   <= d_hi1_ok;
    dflags_q2 <= dflags_q;
    bank_q2   <= bank_rd;
    edge_q2   <= edge_rd;
    dflags_q <= {r_err,
                 r_err || (slab_done && r_last_slab),
                 !r_err && m_last && j_last,
                 !r_err && m_last,
                 !r_err && (rm_q == '0)};
  end

  // At P = 1 the rotation is the identity; with one group there is no group bit.
  logic unused_rot;
  assign unused_rot = ^{drot_q2, dgrp_q2};

  logic [OutW-1:0] beam;
  always_comb begin
    // Lane l from bank (l + rot) mod P + P g_l; edges from bank lk mod P + P e (constant-index
    // loops).
    beam = '0;
    for (int unsigned l = 0; l < P; l++) begin
      for (int unsigned gg = 0; gg < G; gg++) begin
        for (int unsigned b = 0; b < P; b++) begin
          if (dlane_q2 && dgrp_q2[l] == 1'(gg) && ((l + 32'(drot_q2)) & (P - 1)) == b) begin
            beam[l * VoxelW +: VoxelW] = bank_q2[(gg * P + b) * VoxelW +: VoxelW];
          end
        end
      end
    end
    for (int unsigned e = 0; e < NBank; e++) begin
      if (32'(debank_q2) == e) begin
        if (dlo_q2)  beam[P * VoxelW +: VoxelW]       = edge_q2[e * VoxelW +: VoxelW];
        if (dhi0_q2) beam[(P + 1) * VoxelW +: VoxelW] = edge_q2[(NBank + e) * VoxelW +: VoxelW];
        if (dhi1_q2) beam[(P + 2) * VoxelW +: VoxelW] = edge_q2[(2 * NBank + e) * VoxelW +: VoxelW];
      end
    end
    beam[(P + 3) * VoxelW +: 5]      = dflags_q2;
  end

  // Output FIFO (FifoDepth entries); the issue credit keeps room for every beam in flight.
  logic [OutW-1:0] fifo_q [FifoDepth];
  logic [FifoW-1:0] fwr_q, frd_q;
  assign out_valid_o = (fcnt_q != '0);
  assign out_data_o  = fifo_q[frd_q];
  assign pop         = out_valid_o && out_ready_i;

  always_ff @(posedge clk_i) begin
    if (dv2_q) fifo_q[fwr_q] <= beam;
  end
  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      fcnt_q <= '0;
      cred_q <= '0;
      fwr_q  <= '0;
      frd_q  <= '0;
    end else begin
      fcnt_q <= fcnt_q + (FifoW + 1)'(dv2_q) - (FifoW + 1)'(pop);
      cred_q <= cred_q + (FifoW + 1)'(issue) - (FifoW + 1)'(pop);
      fwr_q  <= fwr_q + FifoW'(dv2_q);
      frd_q  <= frd_q + FifoW'(pop);
    end
  end

`ifndef SYNTHESIS
  a_out_stable: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_section_buf: a stalled beam changed or vanished");
  a_no_write_into_full: assert property (@(posedge clk_i) disable iff (!rst_ni)
      (|w2we_q || |e2we_q) |-> !full_q[w2half_q])
    else $error("cube5_section_buf: a write into a half that is being read");
  a_fifo_room: assert property (@(posedge clk_i) disable iff (!rst_ni)
      dv2_q |-> (fcnt_q < (FifoW + 1)'(FifoDepth)) || pop)
    else $error("cube5_section_buf: output FIFO overflow");
`endif

endmodule
