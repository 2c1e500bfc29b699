// gicube_ring: a ring of GI-Cube block processors for direct volume rendering (patent [348],
// [355], [390], [392]; contract docs/numerics/gicube_ring.md). Procs = 2^ProcLog2 copies of
// gicube_processor, processor i owning the slab i of the volume's blocks along x:
//
//   host rays ──► broadcast to the owner ──┐      ┌──► link[0] ──┐
//                                          ▼      │              ▼
//                      ┌── proc 0 ◄─ offer (link first) ─┐   proc 1 ◄─ ...
//                      │   nb_req ──► grant ─────────────┘     │
//                      ▼                                        ▼
//                 out FIFOs ──► merge in processor order ──► out (ray, proc, every count)
//                 AR: round-robin onto one AXI4 port (ARID = processor); R: by RID
//
// Lockstep: every processor issues its processor cycle at the ring's go, when each could and
// some has work and the output is empty, so the order of events between processors is the
// cycle order, never the memory's timing (a cache stall holds every processor). A ray whose next
// block belongs to another processor goes to that processor's link (one register) if the link
// was empty at go and no lower processor sends to it in the same cycle; else it comes back to
// the host with OVERFLOW set. A processor's offer is its link's ray, else the host's ray if it
// owns it. No wait depends on another wait: the contract's *Priority and no deadlock*.

`include "cube5_axi_ports.svh"

module gicube_ring #(
  /// Processors 2^ProcLog2, 1..2 (0: one processor, its ring ports unused).
  parameter int unsigned ProcLog2    = 1,
  /// The processors' parameters (gicube_processor's; Light = 0).
  parameter int unsigned BlockLog2   = 2,
  parameter int unsigned VolBlocks   = 4,
  parameter int unsigned QueueLen    = 16,
  parameter int unsigned Ranks       = 8,
  parameter int unsigned VoxelW      = 8,
  parameter int unsigned Step        = 256,
  parameter int unsigned RingLat     = 8,
  parameter int unsigned DataW       = 64,
  parameter int unsigned LineVox     = 16,
  parameter int unsigned Sets        = 32,
  parameter int unsigned Outstanding = 8,
  parameter int unsigned Prefetch    = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Host ray valid (held until taken), broadcast to the processor that owns its start.
  input  logic in_valid_i,
  /// The host ray is taken this clock.
  output logic in_ready_o,
  /// The host's ray packet (256 bits).
  input  logic [gicube_pkg::PacketW-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the output item this clock.
  input  logic out_ready_i,
  /// done (1), ray (256), proc (2), then per processor (0 first) its ten counts, 32 bits each
  /// (rays_in, finished, overflowed, samples, leaps, cycles, cache hits, misses, nb_in,
  /// nb_out) as the item entered the output register; LSB first.
  output logic [1+gicube_pkg::PacketW+2+(1<<ProcLog2)*gicube_ring_pkg::RingCounts*32-1:0] out_data_o,

  /// Configuration write (broadcast: every processor holds every table and empty flag).
  input  logic cfg_valid_i,
  input  logic [2+gicube_sample_pkg::CfgAddrW-1:0] cfg_addr_i,
  input  logic [gicube_sample_pkg::CfgDataW-1:0] cfg_data_i,

  /// Sticky: some volume read came back with RRESP != OKAY (any processor's cache).
  output logic err_o,

  // The processors' volume reads on one AXI4 read port: ARID = the processor.
  `CUBE5_AXI4_RD_MGR_PORTS(m_axi_, 32, DataW, 4)
);

  localparam int unsigned Procs    = 1 << ProcLog2;
  localparam int unsigned PacketW  = gicube_pkg::PacketW;
  localparam int unsigned CntsW    = gicube_ring_pkg::RingCounts * 32;
  localparam int unsigned POutW    = 1 + PacketW + 8 * 32 + 1;   // the processor's item
  localparam int unsigned OutW     = 1 + PacketW + 2 + Procs * CntsW;
  localparam int unsigned ArW      = 32 + 8 + 3 + 2;            // addr, len, size, burst
  localparam int unsigned StartLsb = gicube_pkg::PacketStartLsb;
  localparam int unsigned PosFracW = gicube_pkg::PosFracW;
  localparam int unsigned PW       = (ProcLog2 == 0) ? 1 : ProcLog2;

  if (ProcLog2 > 1) begin : gen_bad_procs
    $fatal(1, "gicube_ring: ProcLog2 must be 0 or 1 (the verified ring has two processors)");
  end
  if (VolBlocks % Procs != 0) begin : gen_bad_slabs
    $fatal(1, "gicube_ring: VolBlocks must be a multiple of 2^ProcLog2 (slabs)");
  end

  // ---------------------------------------------------------------------------
  // The processors
  // ---------------------------------------------------------------------------
  logic [Procs-1:0]         p_in_valid, p_in_ready, p_in_nb, p_out_valid, p_out_ready;
  logic [Procs-1:0]         p_can, p_busy, p_waiting, p_nb_req, p_nb_grant, p_err;
  logic [Procs*PacketW-1:0] p_in_data, p_nb_data;
  logic [Procs*2-1:0]       p_nb_dest;
  logic [Procs*POutW-1:0]   p_out_data;
  logic [Procs*CntsW-1:0]   p_cnt;
  logic [Procs*ArW-1:0]     p_ar;
  logic [Procs-1:0]         p_arvalid, p_arready, p_rvalid, p_rready;
  logic                     go;

  // The links: one register per receiving processor.
  logic [Procs-1:0]         link_v_q, src_nb_q;
  logic [Procs*PacketW-1:0] link_q;

  // The host's ray goes to the processor that owns its start.
  logic [1:0] host_owner;
  assign host_owner = gicube_ring_pkg::ring_owner(in_data_i[StartLsb + PosFracW +: gicube_pkg::PosIntW],
                                             BlockLog2, VolBlocks / Procs, Procs);

  for (genvar p = 0; p < Procs; p++) begin : gen_proc
    // The offer: the link's ray first, else the host's if this processor owns it.
    assign p_in_valid[p] = link_v_q[p] || (in_valid_i && host_owner == 2'(p));
    assign p_in_nb[p]    = link_v_q[p];
    assign p_in_data[p * PacketW +: PacketW] = link_v_q[p] ? link_q[p * PacketW +: PacketW]
                                                            : in_data_i;
    logic [POutW-1:0] out_d;
    assign p_out_data[p * POutW +: POutW] = out_d;

    logic [31:0] araddr;
    logic [7:0]  arlen;
    logic [2:0]  arsize;
    logic [1:0]  arburst;
    logic [3:0]  arid;
    assign p_ar[p * ArW +: ArW] = {araddr, arlen, arsize, arburst};

    // The write channels are idle (Light = 0).
    logic [31:0]        awaddr;
    logic [7:0]         awlen;
    logic [2:0]         awsize;
    logic [1:0]         awburst;
    logic [3:0]         awid;
    logic               awvalid, wlast, wvalid, bready;
    logic [DataW-1:0]   wdata;
    logic [DataW/8-1:0] wstrb;

    gicube_processor #(
      .BlockLog2   (BlockLog2),
      .VolBlocks   (VolBlocks),
      .QueueLen    (QueueLen),
      .Ranks       (Ranks),
      .VoxelW      (VoxelW),
      .Step        (Step),
      .RingLat     (RingLat),
      .DataW       (DataW),
      .LineVox     (LineVox),
      .Sets        (Sets),
      .Outstanding (Outstanding),
      .Prefetch    (Prefetch),
      .Light       (0),
      .Scatter     (0),
      .Procs       (Procs),
      .ProcId      (p)
    ) u_proc (
      .clk_i           (clk_i),
      .rst_ni          (rst_ni),
      .in_valid_i      (p_in_valid[p]),
      .in_ready_o      (p_in_ready[p]),
      .in_data_i       (p_in_data[p * PacketW +: PacketW]),
      .out_valid_o     (p_out_valid[p]),
      .out_ready_i     (p_out_ready[p]),
      .out_data_o      (out_d),
      .cfg_valid_i     (cfg_valid_i),
      .cfg_addr_i      (cfg_addr_i),
      .cfg_data_i      (cfg_data_i),
      .err_o           (p_err[p]),
      .go_i            (go),
      .can_o           (p_can[p]),
      .busy_o          (p_busy[p]),
      .waiting_o       (p_waiting[p]),
      .in_nb_i         (p_in_nb[p]),
      .nb_req_o        (p_nb_req[p]),
      .nb_dest_o       (p_nb_dest[p * 2 +: 2]),
      .nb_data_o       (p_nb_data[p * PacketW +: PacketW]),
      .nb_grant_i      (p_nb_grant[p]),
      .cnt_o           (p_cnt[p * CntsW +: CntsW]),
      .m_axi_araddr_o  (araddr),
      .m_axi_arlen_o   (arlen),
      .m_axi_arsize_o  (arsize),
      .m_axi_arburst_o (arburst),
      .m_axi_arid_o    (arid),
      .m_axi_arvalid_o (p_arvalid[p]),
      .m_axi_arready_i (p_arready[p]),
      .m_axi_rdata_i   (m_axi_rdata_i),
      .m_axi_rresp_i   (m_axi_rresp_i),
      .m_axi_rlast_i   (m_axi_rlast_i),
      .m_axi_rid_i     (m_axi_rid_i),
      .m_axi_rvalid_i  (p_rvalid[p]),
      .m_axi_rready_o  (p_rready[p]),
      .m_axi_awaddr_o  (awaddr),
      .m_axi_awlen_o   (awlen),
      .m_axi_awsize_o  (awsize),
      .m_axi_awburst_o (awburst),
      .m_axi_awid_o    (awid),
      .m_axi_awvalid_o (awvalid),
      .m_axi_awready_i (1'b0),
      .m_axi_wdata_o   (wdata),
      .m_axi_wstrb_o   (wstrb),
      .m_axi_wlast_o   (wlast),
      .m_axi_wvalid_o  (wvalid),
      .m_axi_wready_i  (1'b0),
      .m_axi_bresp_i   (2'b00),
      .m_axi_bid_i     (4'd0),
      .m_axi_bvalid_i  (1'b0),
      .m_axi_bready_o  (bready)
    );

    logic unused_proc;
    assign unused_proc = ^{arid, awaddr, awlen, awsize, awburst, awid, awvalid, wdata, wstrb,
                           wlast, wvalid, bready, out_d[PacketW + 1 +: POutW - PacketW - 1]};

    // R beats by RID: this processor's reads.
    assign p_rvalid[p] = m_axi_rvalid_i && (m_axi_rid_i[PW-1:0] == PW'(p));
  end

  // ---------------------------------------------------------------------------
  // Lockstep issue and the links
  // ---------------------------------------------------------------------------
  logic out_v_q;
  assign go = (&p_can) && (|p_busy) && !out_v_q;

  // A sender is granted its destination's link if the link is empty and no lower processor
  // sends to it in this cycle.
  logic [3:0] link_v4;  // the link flags indexed by a 2-bit processor number
  assign link_v4 = 4'(link_v_q);
  always_comb begin
    for (int unsigned p = 0; p < Procs; p++) begin
      p_nb_grant[p] = p_nb_req[p] && !link_v4[p_nb_dest[p * 2 +: 2]];
      for (int unsigned q = 0; q < p; q++) begin
        if (p_nb_req[q] && p_nb_dest[q * 2 +: 2] == p_nb_dest[p * 2 +: 2]) begin
          p_nb_grant[p] = 1'b0;
        end
      end
    end
  end

  logic [Procs-1:0]         link_v_d, src_nb_d;
  logic [Procs*PacketW-1:0] link_d;
  always_comb begin
    link_v_d = link_v_q;
    link_d   = link_q;
    src_nb_d = go ? link_v_q : src_nb_q;
    for (int unsigned r = 0; r < Procs; r++) begin
      // Emptied in the dispatch of the cycle that took the link's ray.
      if (p_in_ready[r] && src_nb_q[r]) begin
        link_v_d[r] = 1'b0;
      end
      for (int unsigned p = 0; p < Procs; p++) begin
        if (go && p_nb_grant[p] && p_nb_dest[p * 2 +: 2] == 2'(r)) begin
          link_v_d[r] = 1'b1;
          link_d[r * PacketW +: PacketW] = p_nb_data[p * PacketW +: PacketW];
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      link_v_q <= '0;
      src_nb_q <= '0;
    end else begin
      link_v_q <= link_v_d;
      src_nb_q <= src_nb_d;
    end
  end

  always_ff @(posedge clk_i) begin
    link_q <= link_d;
  end

  // The host's ray is taken when its owner's cycle took it (an offer from the host, not a link).
  assign in_ready_o = |(p_in_ready & ~src_nb_q);

  // ---------------------------------------------------------------------------
  // The output merge: processor order within a cycle
  // ---------------------------------------------------------------------------
  logic [PW:0]      mg_q, mg_d;     // the processor served, Procs: the cycle's outputs are out
  logic             out_v_d, load;
  logic [OutW-1:0]  out_q, out_d;
  logic [PW-1:0]    mg;

  assign mg = mg_q[PW-1:0];
  always_comb begin
    mg_d        = mg_q;
    load        = 1'b0;
    p_out_ready = '0;
    if (go) begin
      mg_d = '0;
    end else if (mg_q < (PW + 1)'(Procs)) begin
      if (p_out_valid[mg]) begin
        load = !out_v_q || out_ready_i;
        p_out_ready[mg] = load;
      end else if (!p_waiting[mg]) begin
        mg_d = mg_q + (PW + 1)'(1);
      end
    end
    out_v_d = load || (out_v_q && !out_ready_i);
    out_d   = {p_cnt, 2'(mg), p_out_data[mg * POutW +: PacketW + 1]};
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      mg_q    <= '0;
      out_v_q <= 1'b0;
    end else begin
      mg_q    <= mg_d;
      out_v_q <= out_v_d;
    end
  end

  always_ff @(posedge clk_i) begin
    if (load) begin
      out_q <= out_d;
    end
  end

  assign out_valid_o = out_v_q;
  assign out_data_o  = out_q;
  assign err_o       = |p_err;

  // ---------------------------------------------------------------------------
  // AXI4: the processors' AR round-robin onto one port (an offered address keeps the channel),
  // R by RID
  // ---------------------------------------------------------------------------
  logic          ar_hold_q, ar_hold_d;
  logic [PW-1:0] ar_sel_q, ar_sel_d, ar_last_q, ar_last_d, ar_sel;
  logic          ar_any;

  always_comb begin
    ar_sel = ar_sel_q;
    ar_any = 1'b0;
    if (!ar_hold_q) begin
      for (int unsigned k = Procs; k >= 1; k--) begin
        // The first processor with an address after the last one served (k = Procs: itself).
        if (p_arvalid[PW'((32'(ar_last_q) + k) % Procs)]) begin
          ar_sel = PW'((32'(ar_last_q) + k) % Procs);
          ar_any = 1'b1;
        end
      end
    end else begin
      ar_any = 1'b1;
    end
  end
  assign ar_hold_d = m_axi_arvalid_o && !m_axi_arready_i;
  assign ar_sel_d  = ar_sel;
  assign ar_last_d = (m_axi_arvalid_o && m_axi_arready_i) ? ar_sel : ar_last_q;

  assign m_axi_arvalid_o = ar_any && p_arvalid[ar_sel];
  assign {m_axi_araddr_o, m_axi_arlen_o, m_axi_arsize_o, m_axi_arburst_o} = p_ar[ar_sel * ArW +: ArW];
  assign m_axi_arid_o    = 4'(ar_sel);
  assign p_arready       = m_axi_arready_i ? (Procs'(ar_any) << ar_sel) : '0;
  assign m_axi_rready_o  = p_rready[m_axi_rid_i[PW-1:0]];

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      ar_hold_q <= 1'b0;
      ar_sel_q  <= '0;
      ar_last_q <= PW'(Procs - 1);
    end else begin
      ar_hold_q <= ar_hold_d;
      ar_sel_q  <= ar_sel_d;
      ar_last_q <= ar_last_d;
    end
  end

`ifndef SYNTHESIS
  RingOutHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_ring: a stalled output item changed");
  RingArHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      m_axi_arvalid_o && !m_axi_arready_i |=> m_axi_arvalid_o && $stable(m_axi_araddr_o)
      && $stable(m_axi_arid_o))
    else $error("gicube_ring: an offered AR address was withdrawn or changed");
`endif

endmodule
