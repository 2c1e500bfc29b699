// gicube_cache: the GI-Cube block processor's volume cache and miss scheduler (parts F, G, H of
// docs/gicube-rtl.md; patent [376]-[378]; contract docs/numerics/gicube_cache.md). A request is a
// sample's cell (x, y, z); its eight corners lie in eight banks by parity (x & 1, y & 1, z & 1),
// each bank a direct-mapped cache of Sets lines of LineVox voxel words with its own tags, so the
// eight tags are checked in one clock ([376]). Up to eight misses are queued and read as one
// INCR burst per line through cube5_axi_rd, in ascending bank order; a fill counter (the banks
// still to fill) holds the request until its lines are in ([377]); then the eight voxels are read
// again and leave in corner order with the bank hit mask, the running hit and miss counts and the
// request's stall cycles.
//
//   in (x, y, z) ─► bank decode ─► 8 tag RAMs + 8 data RAMs (cube5_shader_ram, registered read)
//                                     │ check (valid flops, tags)        ▲ fills (one beat a clock)
//                                     ▼                                  │
//                       hit: output register ◄── all hit      miss queue ─► cube5_axi_rd ─► AXI4 AR/R
//
// Blocking: the request at the tag check holds the unit until its fills are written, so the tags
// change in request order and hit/miss is a function of the request sequence alone. One request
// per clock while they hit, latency 2 (contract, "Cycles").
//
// Splat = 1 (part M's side of the cache, contract "Splatting"): an item is a read, a deposit (eight
// corner energies added, saturating, into the irradiance fields of the cell's corners, the words'
// top min(WordW, 16) bits, in the cached lines, which become dirty) or a flush. A miss whose set
// holds a dirty line writes that line back first (one INCR burst through cube5_axi_wr, its beats
// read from the bank's RAM), waits for the write-backs' B responses, then reads its lines; a
// flush writes back every dirty line, bank by bank, set by set, and leaves when all are answered.
// Splat = 0 ties the write channels off (AWVALID, WVALID low, BREADY high).
`include "cube5_axi_ports.svh"

module gicube_cache #(
  /// The volume's edge in memory, M: a power of two, 4..1024.
  parameter int unsigned MaxDim      = 64,
  /// Bits of a voxel word: 8, 16 or 32.
  parameter int unsigned WordW       = 16,
  /// AXI4 data bus bits: a power of two, 32..256, at least 2 WordW.
  parameter int unsigned DataW       = 64,
  /// Voxels of a cache line: a power of two of 2..256 beats, at most 4096 bytes.
  parameter int unsigned LineVox     = 16,
  /// Lines per bank (direct-mapped): a power of two, 2..4096.
  parameter int unsigned Sets        = 32,
  /// Line reads in flight at most: a power of two, 2..8.
  parameter int unsigned Outstanding = 8,
  /// Byte address width of the AXI port (13..64; the volume's M^3 WordW/8 bytes sit at 0).
  parameter int unsigned AddrW       = 32,
  /// 1: deposits, dirty lines, write-back and flush (contract, "Splatting"); 0: read-only.
  parameter int unsigned Splat       = 0,
  /// Requests checked ahead of the data read (contract, "Prefetch"): 0 blocking, 1..8 the
  /// prefetch queue's entries (with Splat: contract "Prefetch with splatting").
  parameter int unsigned Prefetch    = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Request valid.
  input  logic in_valid_i,
  /// The unit takes a request this cycle.
  output logic in_ready_o,
  /// x, y, z (log2 MaxDim bits each): the cell's lowest voxel, LSB first; with Splat, then op
  /// (2: 0 read, 1 deposit, 2 or 3 flush) and the energies e[0..8] (min(WordW, 16) bits each).
  input  logic [3*$clog2(MaxDim)+(Splat != 0 ? 2 + 8 * ((WordW < 16) ? WordW : 16) : 0)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// vox[0..8] (WordW each, corner c = cx + 2 cy + 4 cz), hit (8, by bank), hits (32),
  /// misses (32), stall (16), LSB first.
  output logic [8*WordW+8+32+32+16-1:0] out_data_o,

  /// Sticky: some fill beat since reset came back with RRESP != OKAY, or some write-back's BRESP.
  output logic err_o,

  // AXI4 read channels (ID 0; RREADY always 1 out of reset: cube5_axi_rd's credit rule) and
  // write channels (the write-back of dirty lines, whole lines, all strobes set; idle
  // without Splat).
  `CUBE5_AXI4_MGR_PORTS(m_axi_, AddrW, DataW, 4)
);

  // ==============================================================================================
  // Derived sizes (contract, "Parameters")
  // ==============================================================================================

  localparam int unsigned CoordW  = $clog2(MaxDim);
  localparam int unsigned HalfW   = CoordW - 1;               // bank coordinate bits
  localparam int unsigned IdxW    = 3 * HalfW;                // bank index bits
  localparam int unsigned LineLog = $clog2(LineVox);
  localparam int unsigned LineW   = IdxW - LineLog;           // line number bits
  localparam int unsigned SetW    = $clog2(Sets);
  localparam int unsigned TagW    = (LineW > SetW) ? LineW - SetW : 1;
  localparam int unsigned PerBeat = DataW / WordW;            // V
  localparam int unsigned VLog    = $clog2(PerBeat);
  localparam int unsigned Bpl     = LineVox / PerBeat;        // beats per line
  localparam int unsigned BplW    = $clog2(Bpl);
  localparam int unsigned DAddrW  = SetW + BplW;
  localparam int unsigned WbLog   = $clog2(WordW / 8);        // log2 bytes per word
  localparam int unsigned LenW    = BplW + 1;
  localparam int unsigned CountW  = 32;
  localparam int unsigned StallW  = 16;
  localparam int unsigned XyzW    = 3 * CoordW;
  localparam int unsigned IrrW    = (WordW < 16) ? WordW : 16; // the irradiance field's bits
  localparam int unsigned IrrSh   = WordW - IrrW;             // ... and its lowest bit
  localparam int unsigned InW     = XyzW + (Splat != 0 ? 2 + 8 * IrrW : 0);
  localparam int unsigned OutW    = 8 * WordW + 8 + 2 * CountW + StallW;
  localparam int unsigned LAddrW  = 3 + IdxW + WbLog;         // bytes of the volume
  localparam int unsigned ZeroW   = LineLog + WbLog;          // a line's byte offset bits

  // Elaboration checks mirror CacheConfig::validate in the model.
  if (MaxDim < 4 || MaxDim > 1024 || (1 << CoordW) != MaxDim) begin : gen_bad_max_dim
    $fatal(1, "gicube_cache: MaxDim must be a power of two in 4..1024");
  end
  if (WordW != 8 && WordW != 16 && WordW != 32) begin : gen_bad_word_w
    $fatal(1, "gicube_cache: WordW must be 8, 16 or 32");
  end
  if (DataW < 32 || DataW > 256 || (1 << $clog2(DataW)) != DataW || DataW < 2 * WordW)
  begin : gen_bad_data_w
    $fatal(1, "gicube_cache: DataW must be a power of two in 32..256, at least 2 WordW");
  end
  if ((1 << LineLog) != LineVox || LineVox < PerBeat || Bpl < 2 || Bpl > 256
      || LineVox * WordW / 8 > 4096) begin : gen_bad_line_vox
    $fatal(1, "gicube_cache: LineVox must be a power of two of 2..256 beats, at most 4096 bytes");
  end
  if (Sets < 2 || Sets > 4096 || (1 << SetW) != Sets || SetW + LineLog > IdxW)
  begin : gen_bad_sets
    $fatal(1, "gicube_cache: Sets must be a power of two in 2..4096, Sets LineVox <= (M/2)^3");
  end
  if (Outstanding < 2 || Outstanding > 8 || (1 << $clog2(Outstanding)) != Outstanding)
  begin : gen_bad_outstanding
    $fatal(1, "gicube_cache: Outstanding must be a power of two in 2..8");
  end
  if (AddrW < 13 || AddrW > 64 || AddrW < LAddrW) begin : gen_bad_addr_w
    $fatal(1, "gicube_cache: AddrW must be in 13..64 and hold the volume's bytes");
  end
  if (Splat > 1) begin : gen_bad_splat
    $fatal(1, "gicube_cache: Splat must be 0 or 1");
  end
  if (Prefetch > 8) begin : gen_bad_prefetch
    $fatal(1, "gicube_cache: Prefetch must be in 0..8");
  end

  // ==============================================================================================
  // Bank decode: the corner of the cell in bank p along each axis (contract, "Tags")
  // ==============================================================================================

  // Bank index of the corner in bank p of the cell at xyz: per axis the corner a or a + 1 whose
  // parity is p's, wrapped modulo M, halved, which is (a >> 1) + (a odd and p's parity even)
  // modulo M/2; x fastest.
  function automatic logic [IdxW-1:0] bank_index(input logic [InW-1:0] xyz, input int unsigned p);
    logic [CoordW-1:0] a;
    logic              pa;
    logic [IdxW-1:0]   idx;
    idx = '0;
    for (int unsigned ax = 0; ax < 3; ax++) begin
      a  = xyz[ax*CoordW +: CoordW];
      pa = ((p >> ax) & 1) != 0;
      idx[ax*HalfW +: HalfW] = a[CoordW-1:1] + HalfW'(a[0] && !pa);
    end
    bank_index = idx;
  endfunction

  // The set of a line: its low SetW bits XOR the next SetW (the tag's low bits), so that the
  // rows of neighbouring z planes, Sets lines apart, fall into different sets.
  function automatic logic [SetW-1:0] set_of_line(input logic [LineW-1:0] l);
    set_of_line = SetW'(l ^ (l >> SetW));
  endfunction

  // The lowest set bit of an eight-bit mask, as a bank number (0 for an empty mask).
  function automatic logic [2:0] lowest(input logic [7:0] m);
    logic [2:0] p;
    p = '0;
    for (int i = 7; i >= 0; i--) begin
      if (m[i]) p = 3'(i);
    end
    lowest = p;
  endfunction

  // ==============================================================================================
  // Request register and state
  // ==============================================================================================

  typedef enum logic [0:0] {
    StCheck,  // the RAMs' outputs hold this request's tags and words
    StMiss    // issuing the miss queue and writing the fills (Splat: or the phases below)
  } state_e;

  logic             in_fire, in_ready_b;
  logic             busy_q, busy_d;      // a request is held
  state_e           state_q, state_d;
  logic             replay_q, replay_d;  // this check follows the request's fills
  logic [InW-1:0]   req_q, req_d;
  logic [7:0]       hitm_q, hitm_d;      // the first check's hit mask
  logic [7:0]       issue_q, issue_d;    // misses not yet offered to cube5_axi_rd
  logic [7:0]       fill_q, fill_d;      // misses not yet filled (the fill counter)
  logic [BplW-1:0]  beat_q, beat_d;      // beat within the line being filled
  logic [CountW-1:0] hits_q, hits_d, misses_q, misses_d;
  logic [StallW-1:0] stall_q, stall_d;
  logic [8*Sets-1:0] valid_q, valid_d;   // per bank and set: the line is allocated
  logic             out_valid_q, out_valid_d;
  logic [OutW-1:0]  out_data_q, out_data_d;

  // Splat: the held item's kind, dirty lines, the evicted lines to write back, the flush's walk,
  // and the write-back engine (one line at a time: its command, then its beats from the RAM).
  localparam int unsigned SlotW = 3 + SetW;                   // a (bank, set) of the flush walk
  localparam int unsigned PendW = SlotW + 2;                  // write-backs not yet answered
  logic              is_dep, is_flush;
  // Splat's phases within StMiss (flags, so that the read-only state machine stays as it was):
  // writing back the lines the request evicts (before its reads), and a flush's walk.
  logic              wbst_q, wbst_d, flst_q, flst_d;
  logic              in_wb, in_fl, in_miss;
  logic [8*Sets-1:0] dirty_q, dirty_d;   // per bank and set: the line holds deposits
  logic [7:0]        wb_q, wb_d;         // evicted dirty lines not yet written back
  logic [8*TagW-1:0] vtag_q, vtag_d;     // their tags (read at the check)
  logic [SlotW:0]    fl_idx_q, fl_idx_d; // the flush's next slot, bank-major (8 Sets = done)
  logic              fl_tag_q, fl_tag_d; // the slot's tag is being read
  logic              fl_rd;              // read the tag of slot fl_idx
  logic              fl_done, fleave;
  logic [PendW-1:0]  pend_q, pend_d;     // write-back commands without their completion
  logic              eng_q, eng_d;       // the engine holds a line
  logic [2:0]        eng_p_q, eng_p_d;
  logic [SetW-1:0]   eng_set_q, eng_set_d;
  logic [TagW-1:0]   eng_tag_q, eng_tag_d;
  logic              eng_cmd_q, eng_cmd_d; // its command was taken
  logic [BplW:0]     eng_rd_q, eng_rd_d;   // beats read from the RAM
  logic [BplW:0]     eng_tk_q, eng_tk_d;   // beats taken by cube5_axi_wr
  logic              rd_pend_q, rd_pend_d; // the RAM's output register holds a beat not taken
  logic              rd_go;                // read the engine's next beat
  logic              wr_cmd_valid, wr_cmd_ready, wr_dat_ready, wr_done, wr_err;
  logic [AddrW+LenW-1:0] wr_cmd_data;
  logic [DataW-1:0]  wr_dat_data;
  logic [8*WordW-1:0] dep_word;          // each bank's word after the deposit's addition
  logic [8*DataW-1:0] dep_beat;          // ... in its beat
  logic              dep_we;             // the deposit's words are written this cycle

  // Prefetch with Splat: what the prefetching side drives into the shared splatting state (0
  // for the blocking unit): the data stage's item into the request register (whose fields, the
  // deposit's words and the write-back engine then serve it), dirty bits set and cleared, an
  // evicted line for the engine, the flush's walk.
  logic              pf_req_load;
  logic [InW-1:0]    pf_req_data;
  logic [8*Sets-1:0] pf_dirty_set, pf_dirty_clr;
  logic              pf_wb_start;
  logic [2:0]        pf_wb_p;
  logic [SetW-1:0]   pf_wb_set;
  logic [TagW-1:0]   pf_wb_tag;
  logic              pf_fl, pf_fl_start;
  logic              pf_eng_hold;        // the engine may not read the RAMs (data stage full)
  // The data RAMs' write: a deposit's words (set and beat per bank) or a fill beat.
  logic              dwr_dep;

  // RAM ports, per bank, and cube5_axi_rd's command: the blocking unit's or the prefetching
  // one's (the _r wires).
  logic [7:0]             tag_we_r, tag_re_r, dat_we_r, dat_re_r;
  logic [8*SetW-1:0]      tag_waddr_r, tag_raddr_r, fill_set_r;
  logic [8*TagW-1:0]      tag_wdata_r;
  logic [8*DAddrW-1:0]    dat_raddr_r;
  logic [BplW-1:0]        fill_beat_r;
  logic                   cmd_valid_r;
  logic [AddrW+LenW-1:0]  cmd_data_r;
  logic [7:0]             ram_re;
  logic [InW-1:0]         rd_xyz;          // the request whose words the RAMs read
  logic [8*SetW-1:0]      tag_raddr;
  logic [8*DAddrW-1:0]    dat_raddr;
  logic [8*TagW-1:0]      tag_rdata;
  logic [8*DataW-1:0]     dat_rdata;
  logic [7:0]             tag_we;
  logic [7:0]             dat_we;

  // This request's fields per bank (from the request register).
  logic [8*SetW-1:0]  set_of;
  logic [8*TagW-1:0]  tag_of;
  logic [8*VLog-1:0]  wsel_of;   // word within the beat
  logic [8*BplW-1:0]  idx_req_beat; // beat within the line
  logic [8*WordW-1:0] bank_word; // each bank's word of the request (after a read)
  logic [8*LineW-1:0] line_of;
  logic [7:0]         hit;
  logic               all_hit;
  logic               out_free;
  logic               reread;    // the fills are in: read the request's tags and words again
  logic               leave;     // the held request's voxels go to the output register

  // cube5_axi_rd's command and beat ports.
  logic                   cmd_valid, cmd_ready;
  logic [AddrW+LenW-1:0]  cmd_data;
  logic                   beat_valid;
  logic [DataW+2:0]       beat_data;
  logic [2:0]             issue_p, fill_p;

  // The blocking state machine takes nothing with Prefetch (it is idle but for the flush walk).
  assign in_fire  = in_valid_i && in_ready_b && Prefetch == 0;
  assign out_free = !out_valid_q || out_ready_i;
  // The held item with its op and energies (zero without Splat).
  logic [XyzW+2+8*IrrW-1:0] req_e;
  assign req_e    = (XyzW+2+8*IrrW)'(req_q);
  assign is_dep   = Splat != 0 && req_e[XyzW +: 2] == 2'd1;
  assign is_flush = Splat != 0 && req_e[XyzW + 1];

  for (genvar p = 0; p < 8; p++) begin : gen_fields
    logic [IdxW-1:0] idx_rd, idx_req;
    assign idx_rd  = bank_index(rd_xyz, p);
    assign idx_req = bank_index(req_q, p);
    // The flush reads a slot's tag, the write-back engine its line's beats.
    assign tag_raddr[p*SetW +: SetW]     = fl_rd ? fl_idx_q[SetW-1:0]
                                                 : set_of_line(idx_rd[IdxW-1:LineLog]);
    assign dat_raddr[p*DAddrW +: DAddrW] = rd_go ? {eng_set_q, eng_rd_q[BplW-1:0]}
                                                 : {set_of_line(idx_rd[IdxW-1:LineLog]),
                                                    idx_rd[VLog +: BplW]};
    assign line_of[p*LineW +: LineW]     = idx_req[IdxW-1:LineLog];
    assign set_of[p*SetW +: SetW]        = set_of_line(idx_req[IdxW-1:LineLog]);
    if (LineW > SetW) begin : gen_tag
      assign tag_of[p*TagW +: TagW] = idx_req[IdxW-1:LineLog+SetW];
    end else begin : gen_no_tag
      assign tag_of[p*TagW +: TagW] = '0;
    end
    assign wsel_of[p*VLog +: VLog] = idx_req[0 +: VLog];
    assign idx_req_beat[p*BplW +: BplW] = idx_req[VLog +: BplW];
    // The bank's word of this request: selected within the beat before the corner crossbar.
    logic [DataW-1:0] beat_word;
    assign beat_word = dat_rdata[p*DataW +: DataW];
    assign bank_word[p*WordW +: WordW] = beat_word[wsel_of[p*VLog +: VLog]*WordW +: WordW];
    logic [Sets-1:0] valid_bank;
    assign valid_bank = valid_q[p*Sets +: Sets];
    assign hit[p] = valid_bank[set_of[p*SetW +: SetW]]
        && (tag_rdata[p*TagW +: TagW] == tag_of[p*TagW +: TagW]);
    // A deposit adds the energy of its corner in this bank (corner p ^ parity) to the word's
    // irradiance field, saturating, and writes the word back into its beat.
    logic [2:0]      dep_c;
    logic [IrrW:0]   dep_sum;
    logic [IrrW-1:0] dep_e;
    assign dep_c = 3'(p) ^ {req_q[2*CoordW], req_q[CoordW], req_q[0]};
    always_comb begin
      dep_e = '0;
      for (int unsigned c = 0; c < 8; c++) begin
        if (dep_c == 3'(c)) dep_e = req_e[XyzW + 2 + c*IrrW +: IrrW];
      end
    end
    assign dep_sum = {1'b0, bank_word[p*WordW + IrrSh +: IrrW]} + {1'b0, dep_e};
    if (IrrSh > 0) begin : gen_low
      assign dep_word[p*WordW +: WordW] = {dep_sum[IrrW] ? {IrrW{1'b1}} : dep_sum[IrrW-1:0],
                                           bank_word[p*WordW +: IrrSh]};
    end else begin : gen_whole
      assign dep_word[p*WordW +: WordW] = dep_sum[IrrW] ? {IrrW{1'b1}} : dep_sum[IrrW-1:0];
    end
    always_comb begin
      dep_beat[p*DataW +: DataW] = beat_word;
      for (int unsigned k = 0; k < PerBeat; k++) begin
        if (wsel_of[p*VLog +: VLog] == VLog'(k)) dep_beat[p*DataW + k*WordW +: WordW]
            = dep_word[p*WordW +: WordW];
      end
    end
    // The read address takes the set and the beat; the word within the beat is the request's.
    logic unused_rd;
    assign unused_rd = ^{idx_rd[VLog-1:0], idx_req[LineLog-1:VLog]};
  end

  assign all_hit = &hit;
  // A check that hits everywhere (always, after the fills) leaves when the output has room; a
  // deposit writes its words as it leaves, so the next item is taken a cycle later (its read
  // then sees them). A flush leaves when its walk is done and every write-back is answered.
  assign leave      = busy_q && state_q == StCheck && !is_flush && all_hit && out_free;
  assign dep_we     = leave && is_dep;
  assign fl_done    = fl_idx_q[SlotW] && !eng_q && pend_q == '0;
  assign in_wb      = busy_q && state_q == StMiss && wbst_q;
  assign in_fl      = (busy_q && state_q == StMiss && flst_q) || pf_fl;
  assign in_miss    = busy_q && state_q == StMiss && !wbst_q && !flst_q;
  assign fleave     = in_fl && fl_done && out_free;
  assign in_ready_b = !busy_q || (leave && !is_dep) || fleave;
  assign reread     = in_miss && issue_q == '0 && fill_q == '0;
  assign rd_xyz     = reread ? req_q : in_data_i;
  assign ram_re     = {8{in_fire || reread}};
  assign fl_rd      = in_fl && !eng_q && !fl_tag_q && !fl_idx_q[SlotW]
                      && dirty_q[fl_idx_q[SlotW-1:0]];

  // ==============================================================================================
  // Miss queue (issue in ascending bank order) and fills
  // ==============================================================================================

  assign issue_p   = lowest(issue_q);
  assign fill_p    = lowest(fill_q);
  assign cmd_valid = in_miss && issue_q != '0;
  always_comb begin
    logic [LineW-1:0] line_sel;
    // Constant indices: a variable index times LineW (not a power of two) is a multiplier.
    line_sel = '0;
    for (int unsigned p = 0; p < 8; p++) begin
      if (issue_p == 3'(p)) line_sel = line_of[p*LineW +: LineW];
    end
    cmd_data = {LenW'(Bpl), AddrW'({issue_p, line_sel, ZeroW'(0)})};
  end

  // ==============================================================================================
  // Next state
  // ==============================================================================================

  always_comb begin
    logic [3:0]       n_hit, n_miss;
    logic [7:0]       m;
    logic [2:0]       cp;
    busy_d      = busy_q;
    state_d     = state_q;
    replay_d    = replay_q;
    req_d       = req_q;
    hitm_d      = hitm_q;
    issue_d     = issue_q;
    fill_d      = fill_q;
    beat_d      = beat_q;
    hits_d      = hits_q;
    misses_d    = misses_q;
    stall_d     = stall_q;
    valid_d     = valid_q;
    dirty_d     = dirty_q;
    wb_d        = wb_q;
    vtag_d      = vtag_q;
    fl_idx_d    = fl_idx_q;
    fl_tag_d    = 1'b0;
    wbst_d      = wbst_q;
    flst_d      = flst_q;
    out_valid_d = out_valid_q && !out_ready_i;
    out_data_d  = out_data_q;
    tag_we      = '0;
    n_hit       = '0;
    for (int unsigned p = 0; p < 8; p++) n_hit = n_hit + 4'(hit[p]);
    n_miss      = 4'd8 - n_hit;

    // Leaving: the voxels (corner c from bank c ^ parity), the mask, the counts, the stall.
    m  = '0;
    cp = '0;
    if (leave) begin
      m = replay_q ? hitm_q : 8'hff;
      if (!replay_q) hits_d = hits_q + CountW'(8);
      for (int unsigned c = 0; c < 8; c++) begin
        cp = 3'(c) ^ {req_q[2*CoordW], req_q[CoordW], req_q[0]};
        out_data_d[c*WordW +: WordW] = is_dep ? dep_word[cp*WordW +: WordW]
                                              : bank_word[cp*WordW +: WordW];
      end
      out_data_d[8*WordW +: 8 + 2*CountW + StallW] = {stall_q, misses_d, hits_d, m};
      out_valid_d = 1'b1;
      busy_d = 1'b0;
      // A deposit's eight lines are dirty now.
      if (is_dep) begin
        for (int unsigned p = 0; p < 8; p++) begin
          for (int unsigned s = 0; s < Sets; s++) begin
            if (set_of[p*SetW +: SetW] == SetW'(s)) dirty_d[p*Sets + s] = 1'b1;
          end
        end
      end
    end

    // A flush: its walk starts at the check; it leaves with no voxels and the counts.
    if (busy_q && state_q == StCheck && is_flush) begin
      state_d  = StMiss;
      flst_d   = 1'b1;
      fl_idx_d = '0;
    end
    if (pf_fl_start) fl_idx_d = '0;
    if (in_fl) begin
      if (stall_q != '1) stall_d = stall_q + StallW'(1);
      if (fl_rd) begin
        fl_tag_d = 1'b1;
        dirty_d[fl_idx_q[SlotW-1:0]] = 1'b0;
      end else if (!eng_q && !fl_tag_q && !fl_idx_q[SlotW]) begin
        fl_idx_d = fl_idx_q + (SlotW+1)'(1);  // a clean slot
      end
      if (fl_tag_q) fl_idx_d = fl_idx_q + (SlotW+1)'(1);
      if (fleave) begin
        out_data_d  = '0;
        out_data_d[8*WordW +: 8 + 2*CountW + StallW] = {stall_q, misses_q, hits_q, 8'h00};
        out_valid_d = 1'b1;
        busy_d      = 1'b0;
        flst_d      = 1'b0;
      end
    end

    // The first check with misses: allocate (tags written, sets valid), queue the misses; the
    // dirty lines they evict are written back first.
    if (busy_q && state_q == StCheck && !is_flush && !all_hit) begin
      tag_we   = ~hit;
      vtag_d   = tag_rdata;
      wb_d     = '0;
      hitm_d   = hit;
      issue_d  = ~hit;
      fill_d   = ~hit;
      beat_d   = '0;
      hits_d   = hits_q + CountW'(n_hit);
      misses_d = misses_q + CountW'(n_miss);
      state_d  = StMiss;
      for (int unsigned p = 0; p < 8; p++) begin
        for (int unsigned s = 0; s < Sets; s++) begin
          if (!hit[p] && set_of[p*SetW +: SetW] == SetW'(s)) begin
            valid_d[p*Sets + s] = 1'b1;
            wb_d[p]             = dirty_q[p*Sets + s];
            dirty_d[p*Sets + s] = 1'b0;
          end
        end
      end
      wbst_d   = wb_d != '0;
    end

    // The evicted dirty lines go to the engine in bank order; the reads wait for their B.
    if (in_wb) begin
      if (stall_q != '1) stall_d = stall_q + StallW'(1);
      if (!eng_q && wb_q != '0) wb_d[lowest(wb_q)] = 1'b0;
      if (!eng_q && wb_q == '0 && pend_q == '0) wbst_d = 1'b0;
    end

    if (in_miss) begin
      if (stall_q != '1) stall_d = stall_q + StallW'(1);
      if (cmd_valid && cmd_ready) issue_d[issue_p] = 1'b0;
      if (beat_valid) begin
        beat_d = beat_q + BplW'(1);
        if (beat_data[DataW]) fill_d[fill_p] = 1'b0;  // the command's last beat
      end
      if (reread) begin
        state_d  = StCheck;
        replay_d = 1'b1;
      end
    end

    if (in_fire) begin
      busy_d   = 1'b1;
      state_d  = StCheck;
      replay_d = 1'b0;
      req_d    = in_data_i;
      stall_d  = '0;
    end
    if (pf_req_load) req_d = pf_req_data;
    dirty_d = (dirty_d & ~pf_dirty_clr) | pf_dirty_set;
  end

  always_comb begin
    dat_we = '0;
    if (beat_valid) dat_we[fill_p] = 1'b1;
    if (dep_we) dat_we = '1;
  end

  // ==============================================================================================
  // Splat: the write-back engine (one line: its command, its beats read from the bank's RAM)
  // ==============================================================================================

  always_comb begin
    logic             start;
    logic [2:0]       sp;
    logic [SetW-1:0]  low;
    logic [LineW-1:0] line;
    eng_d     = eng_q;
    eng_p_d   = eng_p_q;
    eng_set_d = eng_set_q;
    eng_tag_d = eng_tag_q;
    eng_cmd_d = eng_cmd_q;
    eng_rd_d  = eng_rd_q;
    eng_tk_d  = eng_tk_q;
    start     = 1'b0;
    sp        = '0;
    // An evicted line (the lowest bank first) or the flush's slot whose tag was just read.
    if (in_wb && !eng_q && wb_q != '0) begin
      start = 1'b1;
      sp    = lowest(wb_q);
      for (int unsigned p = 0; p < 8; p++) begin
        if (sp == 3'(p)) begin
          eng_set_d = set_of[p*SetW +: SetW];
          eng_tag_d = vtag_q[p*TagW +: TagW];
        end
      end
    end
    if (pf_wb_start) begin
      start     = 1'b1;
      sp        = pf_wb_p;
      eng_set_d = pf_wb_set;
      eng_tag_d = pf_wb_tag;
    end
    if (fl_tag_q) begin
      start     = 1'b1;
      sp        = fl_idx_q[SlotW-1:SetW];
      eng_set_d = fl_idx_q[SetW-1:0];
      for (int unsigned p = 0; p < 8; p++) begin
        if (sp == 3'(p)) eng_tag_d = tag_rdata[p*TagW +: TagW];
      end
    end
    if (start) begin
      eng_d     = 1'b1;
      eng_p_d   = sp;
      eng_cmd_d = 1'b0;
      eng_rd_d  = '0;
      eng_tk_d  = '0;
    end
    if (eng_q) begin
      if (wr_cmd_valid && wr_cmd_ready) eng_cmd_d = 1'b1;
      if (rd_go) eng_rd_d = eng_rd_q + (BplW+1)'(1);
      if (rd_pend_q && wr_dat_ready) eng_tk_d = eng_tk_q + (BplW+1)'(1);
      if (eng_cmd_q && eng_tk_q == (BplW+1)'(Bpl)) eng_d = 1'b0;
    end
    // The line held under the tag in the set: l mod Sets = set xor (tag mod Sets). (The low
    // bits go through a variable of their width: Yosys 0.23 sized `set ^ SetW'(tag)` inside the
    // concatenation as the tag's width, and the gate-level netlist wrote the wrong line.)
    low = SetW'(eng_tag_q);
    low = eng_set_q ^ low;
    if (LineW > SetW) begin
      line = LineW'({eng_tag_q, low});
    end else begin
      line = LineW'(eng_set_q);
    end
    wr_cmd_data = {LenW'(Bpl), AddrW'({eng_p_q, line, ZeroW'(0)})};
  end

  assign wr_cmd_valid = eng_q && !eng_cmd_q;
  // A beat is read when the RAM's output register is free or being taken.
  assign rd_go        = eng_q && eng_rd_q != (BplW+1)'(Bpl) && (!rd_pend_q || wr_dat_ready)
                        && !pf_eng_hold;
  assign rd_pend_d    = rd_go || (rd_pend_q && !wr_dat_ready);
  always_comb begin
    wr_dat_data = '0;
    for (int unsigned p = 0; p < 8; p++) begin
      if (eng_p_q == 3'(p)) wr_dat_data = dat_rdata[p*DataW +: DataW];
    end
  end
  // Commands taken minus completions.
  always_comb begin
    pend_d = pend_q;
    if (wr_cmd_valid && wr_cmd_ready) pend_d = pend_d + PendW'(1);
    if (wr_done) pend_d = pend_d - PendW'(1);
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      busy_q      <= 1'b0;
      state_q     <= StCheck;
      replay_q    <= 1'b0;
      issue_q     <= '0;
      fill_q      <= '0;
      beat_q      <= '0;
      hits_q      <= '0;
      misses_q    <= '0;
      stall_q     <= '0;
      valid_q     <= '0;
      out_valid_q <= 1'b0;
    end else begin
      busy_q      <= busy_d;
      state_q     <= state_d;
      replay_q    <= replay_d;
      issue_q     <= issue_d;
      fill_q      <= fill_d;
      beat_q      <= beat_d;
      hits_q      <= hits_d;
      misses_q    <= misses_d;
      stall_q     <= stall_d;
      valid_q     <= valid_d;
      out_valid_q <= out_valid_d;
    end
  end

  always_ff @(posedge clk_i) begin
    req_q      <= req_d;
    hitm_q     <= hitm_d;
    out_data_q <= out_data_d;
  end

  // The splatting side's state exists only with Splat: without it, constants (nothing is dirty,
  // the engine idle), so the read-only netlist is the one it was.
  if (Splat != 0) begin : gen_splat_state
    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        dirty_q   <= '0;
        wbst_q    <= 1'b0;
        flst_q    <= 1'b0;
        wb_q      <= '0;
        fl_idx_q  <= '0;
        fl_tag_q  <= 1'b0;
        pend_q    <= '0;
        eng_q     <= 1'b0;
        rd_pend_q <= 1'b0;
      end else begin
        dirty_q   <= dirty_d;
        wbst_q    <= wbst_d;
        flst_q    <= flst_d;
        wb_q      <= wb_d;
        fl_idx_q  <= fl_idx_d;
        fl_tag_q  <= fl_tag_d;
        pend_q    <= pend_d;
        eng_q     <= eng_d;
        rd_pend_q <= rd_pend_d;
      end
    end

    always_ff @(posedge clk_i) begin
      vtag_q    <= vtag_d;
      eng_p_q   <= eng_p_d;
      eng_set_q <= eng_set_d;
      eng_tag_q <= eng_tag_d;
      eng_cmd_q <= eng_cmd_d;
      eng_rd_q  <= eng_rd_d;
      eng_tk_q  <= eng_tk_d;
    end
  end else begin : gen_no_splat_state
    logic unused_splat_state;
    assign dirty_q   = '0;
    assign wbst_q    = 1'b0;
    assign flst_q    = 1'b0;
    assign wb_q      = '0;
    assign fl_idx_q  = '0;
    assign fl_tag_q  = 1'b0;
    assign pend_q    = '0;
    assign eng_q     = 1'b0;
    assign rd_pend_q = 1'b0;
    assign vtag_q    = '0;
    assign eng_p_q   = '0;
    assign eng_set_q = '0;
    assign eng_tag_q = '0;
    assign eng_cmd_q = 1'b0;
    assign eng_rd_q  = '0;
    assign eng_tk_q  = '0;
    assign unused_splat_state = ^{dirty_d, wbst_d, flst_d, wb_d, fl_idx_d, fl_tag_d, pend_d, eng_d, rd_pend_d,
                                  vtag_d, eng_p_d, eng_set_d, eng_tag_d, eng_cmd_d, eng_rd_d,
                                  eng_tk_d};
  end

  // The blocking unit's ports, or the prefetching one's (gen_prefetch below).
  if (Prefetch == 0) begin : gen_blocking_ports
    assign in_ready_o  = in_ready_b;
    assign out_valid_o = out_valid_q;
    assign out_data_o  = out_data_q;
    assign tag_we_r    = tag_we;
    assign tag_waddr_r = set_of;
    assign tag_wdata_r = tag_of;
    assign tag_re_r    = ram_re | {8{fl_rd}};
    assign tag_raddr_r = tag_raddr;
    assign dat_we_r    = dat_we;
    assign dat_re_r    = ram_re;
    assign dat_raddr_r = dat_raddr;
    assign fill_set_r  = set_of;
    assign fill_beat_r = beat_q;
    assign cmd_valid_r = cmd_valid;
    assign cmd_data_r  = cmd_data;
    assign dwr_dep     = dep_we;
    assign pf_req_load  = 1'b0;
    assign pf_req_data  = '0;
    assign pf_dirty_set = '0;
    assign pf_dirty_clr = '0;
    assign pf_wb_start  = 1'b0;
    assign pf_wb_p      = '0;
    assign pf_wb_set    = '0;
    assign pf_wb_tag    = '0;
    assign pf_fl        = 1'b0;
    assign pf_fl_start  = 1'b0;
    assign pf_eng_hold  = 1'b0;
  end


  // ==============================================================================================
  // Prefetch > 0 (contract, "Prefetch"): the tags are checked ahead of the data read. An item
  // is taken (its tags read), checked in item order (its misses allocated and queued for
  // cube5_axi_rd at once), and waits in the prefetch queue until every line allocated up to its
  // check is filled; then its words are read and it leaves. A check whose miss would evict a
  // line that a queued item still reads waits until that item has read it.
  // With Splat ("Prefetch with splatting"): the evicted dirty lines of a check are written back
  // and answered before its misses are offered; a deposit adds and writes its words (and dirty
  // bits) as it leaves the data stage, in a clock without a fill beat, and the next item's words
  // are read the clock after; the write-back engine reads the banks while the data stage is
  // empty; a flush waits until everything before it is done, walks, and leaves through the queue.
  // ==============================================================================================

  if (Prefetch != 0) begin : gen_prefetch
    localparam int unsigned SeqW = 8;                 // lines allocated / filled, modulo 2^8
    localparam int unsigned PfW  = $clog2(Prefetch + 1);
    localparam int unsigned FqD  = 16;                // lines offered and not yet filled
    localparam int unsigned FqW  = $clog2(FqD);
    localparam int unsigned EntW = InW + 8 + SeqW;    // a queued item: item, hit mask, need

    // The check stage (the item whose tags the RAMs' outputs hold).
    logic             c_v_q;
    logic [InW-1:0]   c_item_q;
    logic [XyzW-1:0]  c_xyz_q;
    // The prefetch queue, entry 0 the oldest.
    logic [EntW-1:0]  q_q [Prefetch];
    logic [PfW-1:0]   q_n_q;
    // The data stage (the item whose words the RAMs' outputs hold; Splat: its item also in the
    // request register) and the output.
    logic             d_v_q;
    logic [XyzW+7:0]  d_q;
    logic             o_v_q;
    logic [OutW-1:0]  o_q;
    logic [CountW-1:0] p_hits_q, p_misses_q;
    logic [StallW-1:0] ost_q;
    // Allocation and fills.
    logic [8*Sets-1:0] p_valid_q;
    logic [SeqW-1:0]  alloc_q, filled_q;
    logic [7:0]       iss_q;                           // the last check's misses not yet offered
    logic [7:0]       iss_wb_q;                        // ... its evicted dirty lines not yet
    logic [8*TagW-1:0] iss_vtag_q;                     //     written back, and their tags
    logic [XyzW-1:0]  iss_xyz_q;
    logic [3+SetW-1:0] fq_q [FqD];                    // bank and set of each line in flight
    logic [FqW:0]     fq_n_q;
    logic [FqW-1:0]   fq_rd_q, fq_wr_q;
    logic [BplW-1:0]  p_beat_q;
    logic             fl_q;                            // Splat: the check's flush walks

    assign c_xyz_q = c_item_q[XyzW-1:0];

    // The check.
    logic [7:0]       c_hit, c_conf, c_wb;
    logic [8*SetW-1:0] c_set;
    logic [8*TagW-1:0] c_tag;
    logic             c_go, c_alloc, c_flush, q_room, q_pop, q_push, d_go, o_free, take;
    logic             d_dep, d_flush, drained;
    logic [3:0]       c_nhit;
    logic [SeqW-1:0]  c_need;

    // The data stage's kind (Splat: the request register holds its item).
    assign d_dep   = d_v_q && is_dep;
    assign d_flush = d_v_q && is_flush;
    logic [XyzW+2+8*IrrW-1:0] c_item_e;           // with its op (zero without Splat)
    assign c_item_e = (XyzW+2+8*IrrW)'(c_item_q);
    assign c_flush  = Splat != 0 && c_item_e[XyzW + 1];

    for (genvar p = 0; p < 8; p++) begin : gen_pf_bank
      logic [IdxW-1:0] idx_c, idx_in, idx_h;
      logic [Sets-1:0] vb, db;
      assign idx_c  = bank_index(InW'(c_xyz_q), p);
      assign idx_in = bank_index(in_data_i, p);
      assign idx_h  = bank_index(InW'(q_q[0][0 +: XyzW]), p);
      assign c_set[p*SetW +: SetW] = set_of_line(idx_c[IdxW-1:LineLog]);
      // The tag: the line's bits above the set's (0 when there are none).
      assign c_tag[p*TagW +: TagW] = TagW'({1'b0, idx_c[IdxW-1:LineLog]} >> SetW);
      assign vb = p_valid_q[p*Sets +: Sets];
      assign db = dirty_q[p*Sets +: Sets];
      assign c_hit[p] = vb[c_set[p*SetW +: SetW]]
          && (tag_rdata[p*TagW +: TagW] == c_tag[p*TagW +: TagW]);
      // Splat: a miss whose set holds a dirty line evicts it (written back before the reads).
      assign c_wb[p] = !c_hit[p] && db[c_set[p*SetW +: SetW]];
      // A miss here evicts the set's line: held while a queued item has the same set, or (Splat)
      // while the data stage's deposit into it has not written its words.
      always_comb begin
        logic [LineW-1:0] ln_e;
        c_conf[p] = 1'b0;
        for (int unsigned e = 0; e < Prefetch; e++) begin
          ln_e = LineW'(bank_index(InW'(q_q[e][0 +: XyzW]), p) >> LineLog);
          if (PfW'(e) < q_n_q && set_of_line(ln_e) == c_set[p*SetW +: SetW])
            c_conf[p] = 1'b1;
        end
        if (d_dep && set_of[p*SetW +: SetW] == c_set[p*SetW +: SetW]) c_conf[p] = 1'b1;
        c_conf[p] = c_conf[p] && !c_hit[p];
      end
      assign tag_raddr_r[p*SetW +: SetW] = fl_rd ? fl_idx_q[SetW-1:0]
                                                 : set_of_line(idx_in[IdxW-1:LineLog]);
      // The write-back engine reads its line's beats while the data stage is empty.
      assign dat_raddr_r[p*DAddrW +: DAddrW] = rd_go ? {eng_set_q, eng_rd_q[BplW-1:0]}
                                                     : {set_of_line(idx_h[IdxW-1:LineLog]),
                                                        idx_h[VLog +: BplW]};
      // Splat: a deposit leaving the data stage dirties its eight lines; an allocation cleans
      // the sets it takes.
      for (genvar s = 0; s < Sets; s++) begin : gen_pf_dirty
        assign pf_dirty_set[p*Sets + s] = dwr_dep && set_of[p*SetW +: SetW] == SetW'(s);
        assign pf_dirty_clr[p*Sets + s] = c_go && c_alloc && !c_hit[p]
                                          && c_set[p*SetW +: SetW] == SetW'(s);
      end
      logic unused_idx;
      assign unused_idx = ^{idx_in[LineLog-1:0], idx_h[VLog-1:0], idx_c[LineLog-1:0]};
    end

    always_comb begin
      c_nhit = '0;
      for (int unsigned p = 0; p < 8; p++) c_nhit = c_nhit + 4'(c_hit[p]);
    end
    // The head is ready when every line allocated up to its check is filled.
    logic [SeqW-1:0] h_need;
    logic            h_ready;
    assign h_need  = q_q[0][InW + 8 +: SeqW];
    assign h_ready = q_n_q != '0 && SeqW'(alloc_q - h_need) >= SeqW'(alloc_q - filled_q);
    assign o_free  = !o_v_q || out_ready_i;
    // A deposit writes its words as it leaves the data stage, not in a cycle with a fill beat
    // (one write port); the next item's words are read the cycle after (it sees them). The
    // queue does not pop while the engine holds a line (it reads the RAMs).
    assign d_go    = d_v_q && o_free && !(d_dep && beat_valid);
    assign q_pop   = h_ready && !eng_q && (!d_v_q || (d_go && !d_dep));
    assign q_room  = q_n_q != PfW'(Prefetch) || q_pop;
    assign c_alloc = !c_flush && c_hit != '1;
    // Splat: a flush walks once everything before it is done, and is queued when its walk is.
    assign drained = q_n_q == '0 && !d_v_q && iss_q == '0 && iss_wb_q == '0 && !eng_q
                     && pend_q == '0 && fq_n_q == '0;
    assign c_go    = c_v_q && q_room
                     && (c_flush ? fl_q && fl_done
                                 : (!c_alloc || (iss_q == '0 && iss_wb_q == '0 && c_conf == '0)));
    assign q_push  = c_go;
    assign c_need  = alloc_q + (c_flush ? '0 : SeqW'(4'd8) - SeqW'(c_nhit));
    // Taken while the check is empty or leaves without writing tags (the next take reads them).
    assign take    = in_valid_i && (!c_v_q || (c_go && !c_alloc));
    assign in_ready_o = !c_v_q || (c_go && !c_alloc);
    assign pf_fl_start = c_v_q && c_flush && !fl_q && drained;
    assign pf_fl       = fl_q;

    assign tag_re_r    = {8{take || fl_rd}};
    assign tag_we_r    = (c_go && c_alloc) ? ~c_hit : 8'h00;
    assign tag_waddr_r = c_set;
    assign tag_wdata_r = c_tag;
    assign dat_re_r    = {8{q_pop}};
    assign pf_eng_hold = d_v_q;
    assign pf_req_load = q_pop;
    assign pf_req_data = q_q[0][InW-1:0];

    // The last allocating check's evicted dirty lines go to the write-back engine in bank order;
    // its misses are offered (in bank order) once every write-back is answered. Fills in
    // command order.
    logic [2:0]       iss_p;
    logic [IdxW-1:0]  iss_idx [8];
    logic [LineW-1:0] iss_line;
    logic [3+SetW-1:0] fq_head;
    logic             fill_last;
    for (genvar p = 0; p < 8; p++) begin : gen_pf_iss
      assign iss_idx[p] = bank_index(InW'(iss_xyz_q), p);
    end
    assign iss_p = lowest(iss_q);
    assign pf_wb_start = iss_wb_q != '0 && !eng_q;
    assign pf_wb_p     = lowest(iss_wb_q);
    always_comb begin
      iss_line  = '0;
      pf_wb_set = '0;
      pf_wb_tag = '0;
      for (int unsigned p = 0; p < 8; p++) begin
        if (iss_p == 3'(p)) iss_line = iss_idx[p][IdxW-1:LineLog];
        if (pf_wb_p == 3'(p)) begin
          pf_wb_set = set_of_line(iss_idx[p][IdxW-1:LineLog]);
          pf_wb_tag = iss_vtag_q[p*TagW +: TagW];
        end
      end
    end
    assign cmd_valid_r = iss_q != '0 && fq_n_q != (FqW+1)'(FqD)
                         && iss_wb_q == '0 && !eng_q && pend_q == '0;
    assign cmd_data_r  = {LenW'(Bpl), AddrW'({iss_p, iss_line, ZeroW'(0)})};
    assign fq_head     = fq_q[fq_rd_q];
    assign fill_last   = beat_valid && beat_data[DataW];
    always_comb begin
      dat_we_r = '0;
      if (beat_valid) dat_we_r[fq_head[SetW +: 3]] = 1'b1;
      if (dwr_dep) dat_we_r = '1;
    end
    assign dwr_dep     = d_go && d_dep;
    assign fill_set_r  = {8{fq_head[SetW-1:0]}};
    assign fill_beat_r = p_beat_q;

    // The output: the data stage's voxels (corner c from bank c ^ parity; a deposit's after its
    // addition; a flush's 0), mask, counts, stall.
    logic [8*WordW-1:0] d_word;
    logic [3:0]         d_nhit, d_nmiss;
    for (genvar p = 0; p < 8; p++) begin : gen_pf_word
      logic [IdxW-1:0]  idx_d;
      logic [DataW-1:0] bw;
      logic [VLog-1:0]  ws;
      assign idx_d = bank_index(InW'(d_q[0 +: XyzW]), p);
      assign ws    = idx_d[0 +: VLog];
      assign bw    = dat_rdata[p*DataW +: DataW];
      assign d_word[p*WordW +: WordW] = d_flush ? '0
                                      : d_dep ? dep_word[p*WordW +: WordW] : bw[ws*WordW +: WordW];
      logic unused_d;
      assign unused_d = ^idx_d[IdxW-1:VLog];
    end
    always_comb begin
      d_nhit = '0;
      for (int unsigned p = 0; p < 8; p++) d_nhit = d_nhit + 4'(d_q[XyzW + p]);
      d_nmiss = d_flush ? 4'd0 : 4'd8 - d_nhit;
    end

    always_ff @(posedge clk_i) begin
      logic [2:0] cp;
      if (!rst_ni) begin
        c_v_q      <= 1'b0;
        q_n_q      <= '0;
        d_v_q      <= 1'b0;
        o_v_q      <= 1'b0;
        p_hits_q   <= '0;
        p_misses_q <= '0;
        ost_q      <= '0;
        p_valid_q  <= '0;
        alloc_q    <= '0;
        filled_q   <= '0;
        iss_q      <= '0;
        iss_wb_q   <= '0;
        fq_n_q     <= '0;
        fq_rd_q    <= '0;
        fq_wr_q    <= '0;
        p_beat_q   <= '0;
        fl_q       <= 1'b0;
      end else begin
        // Check stage.
        if (take) begin
          c_v_q    <= 1'b1;
          c_item_q <= in_data_i;
        end else if (c_go) begin
          c_v_q <= 1'b0;
        end
        if (pf_fl_start) fl_q <= 1'b1;
        if (c_go) fl_q <= 1'b0;
        if (c_go && c_alloc) begin
          alloc_q    <= c_need;
          iss_q      <= ~c_hit;
          iss_wb_q   <= Splat != 0 ? c_wb : 8'h00;
          iss_vtag_q <= tag_rdata;
          iss_xyz_q  <= c_xyz_q;
          for (int unsigned p = 0; p < 8; p++) begin
            if (!c_hit[p]) p_valid_q[p*Sets + 32'(c_set[p*SetW +: SetW])] <= 1'b1;
          end
        end
        if (pf_wb_start) iss_wb_q[pf_wb_p] <= 1'b0;
        // The queue: pop shifts, push appends (a flush with an empty mask).
        for (int unsigned e = 0; e < Prefetch; e++) begin
          if (q_pop && e + 1 < Prefetch) q_q[e] <= q_q[e + 1];
          if (q_push && PfW'(e) == q_n_q - PfW'(q_pop))
            q_q[e] <= {c_need, c_flush ? 8'h00 : c_hit, c_item_q};
        end
        q_n_q <= q_n_q + PfW'(q_push) - PfW'(q_pop);
        // Data stage.
        if (q_pop) begin
          d_v_q <= 1'b1;
          d_q   <= {q_q[0][InW +: 8], q_q[0][0 +: XyzW]};
        end else if (d_go) begin
          d_v_q <= 1'b0;
        end
        // Output register; the stall counts the cycles it could take an item and none was ready
        // while the unit held an item (contract, "Prefetch").
        if (o_v_q && out_ready_i) o_v_q <= 1'b0;
        if (d_go) begin
          o_v_q <= 1'b1;
          for (int unsigned c = 0; c < 8; c++) begin
            cp = 3'(c) ^ {d_q[2*CoordW], d_q[CoordW], d_q[0]};
            o_q[c*WordW +: WordW] <= d_word[cp*WordW +: WordW];
          end
          o_q[8*WordW +: 8 + 2*CountW + StallW] <= {ost_q,
              p_misses_q + CountW'(d_nmiss), p_hits_q + CountW'(d_nhit), d_q[XyzW +: 8]};
          p_hits_q   <= p_hits_q + CountW'(d_nhit);
          p_misses_q <= p_misses_q + CountW'(d_nmiss);
          ost_q      <= '0;
        end else if (o_free && (c_v_q || q_n_q != '0 || d_v_q) && ost_q != '1) begin
          ost_q <= ost_q + StallW'(1);
        end
        // Miss issue and fills.
        if (cmd_valid_r && cmd_ready) begin
          iss_q[iss_p]     <= 1'b0;
          fq_q[fq_wr_q]    <= {iss_p, set_of_line(iss_line)};
          fq_wr_q          <= fq_wr_q + FqW'(1);
        end
        if (beat_valid) p_beat_q <= p_beat_q + BplW'(1);
        if (fill_last) begin
          fq_rd_q  <= fq_rd_q + FqW'(1);
          filled_q <= filled_q + SeqW'(1);
        end
        fq_n_q <= fq_n_q + (FqW+1)'(cmd_valid_r && cmd_ready) - (FqW+1)'(fill_last);
      end
    end

    assign out_valid_o = o_v_q;
    assign out_data_o  = o_q;

    // The blocking unit's logic is unused here.
    logic unused_blocking;
    assign unused_blocking = ^{in_ready_b, out_valid_q, out_data_q, tag_we, ram_re, tag_raddr,
                               dat_we, dat_raddr, beat_q, cmd_valid, cmd_data, tag_of};

`ifndef SYNTHESIS
    // A fill beat has its line's destination; the line's last beat ends at beat Bpl - 1.
    PfFillQueued: assert property (@(posedge clk_i) disable iff (!rst_ni)
        beat_valid |-> fq_n_q != '0 && (beat_data[DataW] == (p_beat_q == BplW'(Bpl - 1))))
      else $error("gicube_cache: a fill beat with no line in flight");
    // The engine never reads the RAMs under the data stage's words.
    PfEngineAlone: assert property (@(posedge clk_i) disable iff (!rst_ni)
        !(rd_go && (q_pop || d_v_q)))
      else $error("gicube_cache: the write-back engine read under the data stage");
`endif
  end


  // ==============================================================================================
  // The eight banks: tags and words in block RAM (one write port, one registered read port)
  // ==============================================================================================

  for (genvar p = 0; p < 8; p++) begin : gen_bank
    cube5_shader_ram #(
      .Depth(Sets),
      .Width(TagW),
      .AddrW(SetW)
    ) u_tags (
      .clk_i  (clk_i),
      .we_i   (tag_we_r[p]),
      .waddr_i(tag_waddr_r[p*SetW +: SetW]),
      .wdata_i(tag_wdata_r[p*TagW +: TagW]),
      .re_i   (tag_re_r[p]),
      .raddr_i(tag_raddr_r[p*SetW +: SetW]),
      .rdata_o(tag_rdata[p*TagW +: TagW])
    );

    cube5_shader_ram #(
      .Depth(Sets * Bpl),
      .Width(DataW),
      .AddrW(DAddrW)
    ) u_words (
      .clk_i  (clk_i),
      .we_i   (dat_we_r[p]),
      .waddr_i(dwr_dep ? {set_of[p*SetW +: SetW], idx_req_beat[p*BplW +: BplW]}
                       : {fill_set_r[p*SetW +: SetW], fill_beat_r}),
      .wdata_i(dwr_dep ? dep_beat[p*DataW +: DataW] : beat_data[DataW-1:0]),
      .re_i   (dat_re_r[p] || (rd_go && eng_p_q == 3'(p))),
      .raddr_i(dat_raddr_r[p*DAddrW +: DAddrW]),
      .rdata_o(dat_rdata[p*DataW +: DataW])
    );
  end

  // ==============================================================================================
  // The read side of the memory controller: one INCR burst of Bpl beats per line
  // ==============================================================================================

  cube5_axi_rd #(
    .AddrW      (AddrW),
    .DataW      (DataW),
    .LenW       (LenW),
    .MaxBurst   (Bpl),
    .Outstanding(Outstanding),
    .IdW        (4)
  ) u_rd (
    .clk_i          (clk_i),
    .rst_ni         (rst_ni),
    .in_valid_i     (cmd_valid_r),
    .in_ready_o     (cmd_ready),
    .in_data_i      (cmd_data_r),
    .out_valid_o    (beat_valid),
    .out_ready_i    (1'b1),
    .out_data_o     (beat_data),
    .err_o          (rd_err),
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

  logic [1:0] unused_resp;
  assign unused_resp = beat_data[DataW+2:DataW+1];

  // ==============================================================================================
  // The write side (Splat): one INCR burst of Bpl beats per dirty line
  // ==============================================================================================

  if (Splat != 0) begin : gen_wr
    logic [17:0] wr_out;
    logic        unused_wr_out;
    cube5_axi_wr #(
      .AddrW      (AddrW),
      .DataW      (DataW),
      .ItemW      (DataW),
      .LenW       (LenW),
      .MaxBurst   (Bpl),
      .Outstanding(Outstanding),
      .IdW        (4)
    ) u_wr (
      .clk_i          (clk_i),
      .rst_ni         (rst_ni),
      .in_valid_i     (wr_cmd_valid),
      .in_ready_o     (wr_cmd_ready),
      .in_data_i      (wr_cmd_data),
      .dat_valid_i    (rd_pend_q),
      .dat_ready_o    (wr_dat_ready),
      .dat_data_i     (wr_dat_data),
      .out_valid_o    (wr_done),
      .out_ready_i    (1'b1),
      .out_data_o     (wr_out),
      .err_o          (wr_err),
      .m_axi_awaddr_o (m_axi_awaddr_o),
      .m_axi_awlen_o  (m_axi_awlen_o),
      .m_axi_awsize_o (m_axi_awsize_o),
      .m_axi_awburst_o(m_axi_awburst_o),
      .m_axi_awid_o   (m_axi_awid_o),
      .m_axi_awvalid_o(m_axi_awvalid_o),
      .m_axi_awready_i(m_axi_awready_i),
      .m_axi_wdata_o  (m_axi_wdata_o),
      .m_axi_wstrb_o  (m_axi_wstrb_o),
      .m_axi_wlast_o  (m_axi_wlast_o),
      .m_axi_wvalid_o (m_axi_wvalid_o),
      .m_axi_wready_i (m_axi_wready_i),
      .m_axi_bresp_i  (m_axi_bresp_i),
      .m_axi_bid_i    (m_axi_bid_i),
      .m_axi_bvalid_i (m_axi_bvalid_i),
      .m_axi_bready_o (m_axi_bready_o)
    );
    assign unused_wr_out = ^wr_out;
  end else begin : gen_no_wr
    // Read-only: the write channels idle; nothing is ever dirty.
    logic unused_wr;
    assign wr_cmd_ready    = 1'b0;
    assign wr_dat_ready    = 1'b0;
    assign wr_done         = 1'b0;
    assign wr_err          = 1'b0;
    assign m_axi_awaddr_o  = '0;
    assign m_axi_awlen_o   = '0;
    assign m_axi_awsize_o  = '0;
    assign m_axi_awburst_o = '0;
    assign m_axi_awid_o    = '0;
    assign m_axi_awvalid_o = 1'b0;
    assign m_axi_wdata_o   = '0;
    assign m_axi_wstrb_o   = '0;
    assign m_axi_wlast_o   = 1'b0;
    assign m_axi_wvalid_o  = 1'b0;
    assign m_axi_bready_o  = 1'b1;
    assign unused_wr = ^{m_axi_awready_i, m_axi_wready_i, m_axi_bresp_i, m_axi_bid_i,
                         m_axi_bvalid_i, wr_cmd_data, wr_dat_data};
  end

  logic rd_err;
  assign err_o = rd_err || wr_err;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_cache: output changed while stalled");
  // Fills arrive only for queued misses, and the line's last beat ends at beat Bpl - 1.
  FillOnlyWhenQueued: assert property (@(posedge clk_i) disable iff (!rst_ni)
      beat_valid && Prefetch == 0 |-> busy_q && state_q == StMiss && fill_q != '0
      && (beat_data[DataW] == (beat_q == BplW'(Bpl - 1))))
    else $error("gicube_cache: a fill beat with no miss queued, or a line of the wrong length");
  // The re-check after the fills hits in every bank.
  ReplayHits: assert property (@(posedge clk_i) disable iff (!rst_ni)
      Prefetch == 0 && busy_q && state_q == StCheck && replay_q |-> all_hit)
    else $error("gicube_cache: the check after the fills missed");
`endif

endmodule
