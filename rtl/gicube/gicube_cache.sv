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
  parameter int unsigned AddrW       = 32
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Request valid.
  input  logic in_valid_i,
  /// The unit takes a request this cycle.
  output logic in_ready_o,
  /// x, y, z (log2 MaxDim bits each): the cell's lowest voxel, LSB first.
  input  logic [3*$clog2(MaxDim)-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// vox[0..8] (WordW each, corner c = cx + 2 cy + 4 cz), hit (8, by bank), hits (32),
  /// misses (32), stall (16), LSB first.
  output logic [8*WordW+8+32+32+16-1:0] out_data_o,

  /// Sticky: some fill beat since reset came back with RRESP != OKAY.
  output logic err_o,

  // AXI4 read address channel.
  /// Burst start address.
  output logic [AddrW-1:0] m_axi_araddr_o,
  /// Beats in the burst minus one.
  output logic [7:0] m_axi_arlen_o,
  /// log2 of the bytes per beat.
  output logic [2:0] m_axi_arsize_o,
  /// INCR.
  output logic [1:0] m_axi_arburst_o,
  /// Always 0.
  output logic [3:0] m_axi_arid_o,
  /// Address valid.
  output logic m_axi_arvalid_o,
  /// Subordinate takes the address.
  input  logic m_axi_arready_i,

  // AXI4 read data channel.
  /// Read data.
  input  logic [DataW-1:0] m_axi_rdata_i,
  /// Read response.
  input  logic [1:0] m_axi_rresp_i,
  /// Last beat of the burst.
  input  logic m_axi_rlast_i,
  /// Read ID (unused: one ID).
  input  logic [3:0] m_axi_rid_i,
  /// Read data valid.
  input  logic m_axi_rvalid_i,
  /// Read data ready (always 1 out of reset: cube5_axi_rd's credit rule).
  output logic m_axi_rready_o
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
  localparam int unsigned InW     = 3 * CoordW;
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
    StMiss    // issuing the miss queue and writing the fills
  } state_e;

  logic             in_fire;
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

  // RAM ports, per bank.
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

  assign in_fire  = in_valid_i && in_ready_o;
  assign out_free = !out_valid_q || out_ready_i;

  for (genvar p = 0; p < 8; p++) begin : gen_fields
    logic [IdxW-1:0] idx_rd, idx_req;
    assign idx_rd  = bank_index(rd_xyz, p);
    assign idx_req = bank_index(req_q, p);
    assign tag_raddr[p*SetW +: SetW]     = set_of_line(idx_rd[IdxW-1:LineLog]);
    assign dat_raddr[p*DAddrW +: DAddrW] = {set_of_line(idx_rd[IdxW-1:LineLog]),
                                            idx_rd[VLog +: BplW]};
    assign line_of[p*LineW +: LineW]     = idx_req[IdxW-1:LineLog];
    assign set_of[p*SetW +: SetW]        = set_of_line(idx_req[IdxW-1:LineLog]);
    if (LineW > SetW) begin : gen_tag
      assign tag_of[p*TagW +: TagW] = idx_req[IdxW-1:LineLog+SetW];
    end else begin : gen_no_tag
      assign tag_of[p*TagW +: TagW] = '0;
    end
    assign wsel_of[p*VLog +: VLog] = idx_req[0 +: VLog];
    // The bank's word of this request: selected within the beat before the corner crossbar.
    logic [DataW-1:0] beat_word;
    assign beat_word = dat_rdata[p*DataW +: DataW];
    assign bank_word[p*WordW +: WordW] = beat_word[wsel_of[p*VLog +: VLog]*WordW +: WordW];
    logic [Sets-1:0] valid_bank;
    assign valid_bank = valid_q[p*Sets +: Sets];
    assign hit[p] = valid_bank[set_of[p*SetW +: SetW]]
        && (tag_rdata[p*TagW +: TagW] == tag_of[p*TagW +: TagW]);
    // The read address takes the set and the beat; the word within the beat is the request's.
    logic unused_rd;
    assign unused_rd = ^{idx_rd[VLog-1:0], idx_req[LineLog-1:VLog]};
  end

  assign all_hit = &hit;
  // A check that hits everywhere (always, after the fills) leaves when the output has room.
  assign leave      = busy_q && state_q == StCheck && all_hit && out_free;
  assign in_ready_o = !busy_q || leave;
  assign reread     = busy_q && state_q == StMiss && issue_q == '0 && fill_q == '0;
  assign rd_xyz     = reread ? req_q : in_data_i;
  assign ram_re     = {8{in_fire || reread}};

  // ==============================================================================================
  // Miss queue (issue in ascending bank order) and fills
  // ==============================================================================================

  assign issue_p   = lowest(issue_q);
  assign fill_p    = lowest(fill_q);
  assign cmd_valid = busy_q && state_q == StMiss && issue_q != '0;
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
        out_data_d[c*WordW +: WordW] = bank_word[cp*WordW +: WordW];
      end
      out_data_d[8*WordW +: 8 + 2*CountW + StallW] = {stall_q, misses_d, hits_d, m};
      out_valid_d = 1'b1;
      busy_d = 1'b0;
    end

    // The first check with misses: allocate (tags written, sets valid), queue the misses.
    if (busy_q && state_q == StCheck && !all_hit) begin
      tag_we   = ~hit;
      hitm_d   = hit;
      issue_d  = ~hit;
      fill_d   = ~hit;
      beat_d   = '0;
      hits_d   = hits_q + CountW'(n_hit);
      misses_d = misses_q + CountW'(n_miss);
      state_d  = StMiss;
      for (int unsigned p = 0; p < 8; p++) begin
        for (int unsigned s = 0; s < Sets; s++) begin
          if (!hit[p] && set_of[p*SetW +: SetW] == SetW'(s)) valid_d[p*Sets + s] = 1'b1;
        end
      end
    end

    if (busy_q && state_q == StMiss) begin
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
  end

  always_comb begin
    dat_we = '0;
    if (beat_valid) dat_we[fill_p] = 1'b1;
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

  assign out_valid_o = out_valid_q;
  assign out_data_o  = out_data_q;

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
      .we_i   (tag_we[p]),
      .waddr_i(set_of[p*SetW +: SetW]),
      .wdata_i(tag_of[p*TagW +: TagW]),
      .re_i   (ram_re[p]),
      .raddr_i(tag_raddr[p*SetW +: SetW]),
      .rdata_o(tag_rdata[p*TagW +: TagW])
    );

    cube5_shader_ram #(
      .Depth(Sets * Bpl),
      .Width(DataW),
      .AddrW(DAddrW)
    ) u_words (
      .clk_i  (clk_i),
      .we_i   (dat_we[p]),
      .waddr_i({set_of[p*SetW +: SetW], beat_q}),
      .wdata_i(beat_data[DataW-1:0]),
      .re_i   (ram_re[p]),
      .raddr_i(dat_raddr[p*DAddrW +: DAddrW]),
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
    .in_valid_i     (cmd_valid),
    .in_ready_o     (cmd_ready),
    .in_data_i      (cmd_data),
    .out_valid_o    (beat_valid),
    .out_ready_i    (1'b1),
    .out_data_o     (beat_data),
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

  logic [1:0] unused_resp;
  assign unused_resp = beat_data[DataW+2:DataW+1];

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_cache: output changed while stalled");
  // Fills arrive only for queued misses, and the line's last beat ends at beat Bpl - 1.
  FillOnlyWhenQueued: assert property (@(posedge clk_i) disable iff (!rst_ni)
      beat_valid |-> busy_q && state_q == StMiss && fill_q != '0
      && (beat_data[DataW] == (beat_q == BplW'(Bpl - 1))))
    else $error("gicube_cache: a fill beat with no miss queued, or a line of the wrong length");
  // The re-check after the fills hits in every bank.
  ReplayHits: assert property (@(posedge clk_i) disable iff (!rst_ni)
      busy_q && state_q == StCheck && replay_q |-> all_hit)
    else $error("gicube_cache: the check after the fills missed");
`endif

endmodule
