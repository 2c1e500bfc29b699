// gicube_processor: the GI-Cube block processor for direct volume rendering (patent [347]-[357],
// [369]-[374]; docs/gicube-rtl.md step 6; contract docs/numerics/gicube_processor.md, "The ring"
// and "The RTL"). The verified units, unchanged, in the circular ray pipeline:
//
//   host rays ─► gicube_queue_front (arbiter, bucketing, ray queues, sorter) ─► popped ray
//        ▲             ▲ ring ray                    │ overflowed ray           │ (empty LUT)
//        │             │                             ▼                          ▼
//        └──── out ◄───┼──── finished ◄── merge ◄── out FIFO      sampling: cell ─► gicube_cache
//                      │                    ▲                     (weights, colour: cell FIFO)  │
//                      └────────────────────┤                                   │   AXI4 AR/R ◄┘
//                     side FIFO (ray, leap) ┤◄──────────────────────────────────┤
//                     gicube_sample ─► FIFO ┤◄──────── 8 voxels (cache), weights┘
//                     gicube_step   ─► FIFO ┘◄──────────────── start, dir, leap ┘
//
// One processor cycle is one item of the front end. The cycle's popped ray (or a bubble) enters
// the ring; the ring's ray of cycle t is the outcome of the ray popped in cycle t - RingLat (the
// ring latency, the model's `ring_latency`): the cycle waits until that outcome is back, so the
// order of processor cycles, and with it every count, is the model's whatever the clock timing.
// A cycle also waits until the previous cycle's outputs (finished and overflowed rays) have
// left, so that the host has seen an overflowed ray before the next offer (the model appends it
// to the host's list at the end of its cycle).
//
// The volume is in memory behind the AXI4 read port, read through gicube_cache (its bank-major
// layout, padded to MaxDim > N): a sampling ray's cell goes to the cache at dispatch (which waits
// while the cache holds a request for its fills), its eight voxels to gicube_sample. A cache
// stall delays processor cycles (the issue waits for the ring's head), never reorders them.
//
// Light = 1 (the lighting pass of GI, docs/gicube-rtl.md step 7; contract "Splatting through the
// cache"): 32-bit words, the irradiance field above the voxel; every sampling ray's cell goes to
// the cache through gicube_deposit, which gives a lighting ray's item its eight corner energies
// (a deposit: its read too), a rendering ray's a read; the cache splats (Splat = 1) and writes its
// dirty lines back through the AXI4 write channels; a flush (configuration region 3) enters the
// same stream when the processor holds no ray, and its output item (`flush`) comes when memory
// holds every deposit. Rendering rays are lit by the field when `lit` (region 2) is set.
//
// Scatter = 1 (high albedo, photons; contract "Photons in the ring"): with `photons` set (region
// 2, address 1) a lighting ray is a photon: its deposit takes T = 4096 (the deposit sees opacity
// 0), it never terminates early, and at the issue it interacts when the sample's opacity * 16
// reaches its interaction value. Beside the sample and the step, every ring ray also enters a
// second path from its packet alone: the albedo and interaction draws (two gicube_scatter_hash),
// gicube_scatter (isotropic, the ray's mangling bits) and a second gicube_step on the scattered
// direction. The issue takes that path's outcome for a photon that scatters (new direction,
// opacity 0, generation + 1, lifetime - 1, a new interaction value) and finishes one that is
// absorbed. The output item carries a ninth count, the scatterings.
//
// Jitter = 1 and Shade = 1 (contract "Shading and jitter in the processor") are gicube_sample's
// own: with Shade the cache's words hold each voxel's density, tag and gradient index (the host's
// quantization of the volume's central differences), passed from the cache's eight words to the
// sample unit with the voxels; its gradient LUTs and reflectance map load through region 0 (one
// more address bit). Jitter's random LUT reads the sample position's fraction bits, which the
// sample item carries as its weights.

`include "cube5_axi_ports.svh"

module gicube_processor #(
  /// Block side n = 2^BlockLog2 voxels, 2..8.
  parameter int unsigned BlockLog2 = 2,
  /// Blocks a side B, 1..6 (B^3 <= 256 queues); N = B n voxels a side, 4..64 here.
  parameter int unsigned VolBlocks = 4,
  /// Rays per queue, 1..4096.
  parameter int unsigned QueueLen  = 16,
  /// Sorter ranks, 2..64 and <= 2^QueueW.
  parameter int unsigned Ranks     = 8,
  /// Bits per voxel, 4..16.
  parameter int unsigned VoxelW    = 8,
  /// Sample distance dr, U(4.8) voxels, 16..1024.
  parameter int unsigned Step      = 256,
  /// Ring latency in processor cycles, 1..16.
  parameter int unsigned RingLat   = 8,
  /// The volume cache's AXI4 data bus bits (gicube_cache's DataW).
  parameter int unsigned DataW       = 64,
  /// Voxels of a cache line (gicube_cache's LineVox).
  parameter int unsigned LineVox     = 16,
  /// Lines per cache bank (gicube_cache's Sets).
  parameter int unsigned Sets        = 32,
  /// Line reads in flight at most (gicube_cache's Outstanding).
  parameter int unsigned Outstanding = 8,
  /// gicube_cache's Prefetch: requests whose tags are checked ahead of the data read, 0..8 (with
  /// Light too: the splatting cache prefetches since session 16).
  parameter int unsigned Prefetch    = 0,
  /// 1: lighting rays splat into the field in memory (32-bit words, the cache's Splat = 1, the
  /// AXI4 write channels, the flush); 0: direct volume rendering (the write channels idle).
  parameter int unsigned Light       = 0,
  /// 1 (with Light): high-albedo photons scatter in the ring (gicube_scatter, the photon
  /// registers, the scatterings count in the output); 0: lighting rays never scatter.
  parameter int unsigned Scatter     = 0,
  /// 1: jitter ([353], [380]): gicube_sample's random, log and power LUTs correct each sample's
  /// opacity for a step r dr, r from the sample position's fraction bits; 0: none.
  parameter int unsigned Jitter      = 0,
  /// 1 (without Light): shading ([352], [378], [379], [383]): a voxel word holds the density,
  /// the tag above it and the gradient index above the tag; gicube_sample decodes the corners'
  /// indices (gradient LUTs), interpolates the gradient, classifies by density and the nearest
  /// tag and lights rendering rays by the reflectance map; 0: unlit.
  parameter int unsigned Shade       = 0,
  /// Gradient index bits of a voxel word (Shade = 1), 2..11.
  parameter int unsigned GradIdxW    = 11,
  /// Tag bits of a voxel word (Shade = 1), 0..4; 0 with Shade = 0.
  parameter int unsigned TagW        = 0,
  /// Processors of the ring this one is in (docs/numerics/gicube_ring.md): 1 (alone: the
  /// ring ports are not read), 2 or 4 (slabs along x; Light = 0).
  parameter int unsigned Procs       = 1,
  /// This processor's index in the ring, 0..Procs-1: it owns slab ProcId.
  parameter int unsigned ProcId      = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Host ray valid (held until taken: an offer that the cycle does not take stays).
  input  logic in_valid_i,
  /// The host ray is taken this clock.
  output logic in_ready_o,
  /// The host's ray packet (256 bits).
  input  logic [gicube_pkg::PacketW-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the output item this clock.
  input  logic out_ready_i,
  /// done (1: finished, 0: overflowed), ray (256), then the counts after it: rays_in,
  /// rays_finished, rays_overflowed, samples, leaps, cycles, cache_hits, cache_misses (32
  /// each), then flush (1: the flush's item, done and ray 0), then (Scatter) scatterings (32);
  /// LSB first.
  output logic [1+gicube_pkg::PacketW+8*32+1+Scatter*32-1:0] out_data_o,

  /// Configuration write this clock (tables, empty flags; they survive reset).
  input  logic cfg_valid_i,
  /// Region (top 2 bits): 0 gicube_sample's address (low 14 bits; Shade: 15), 1 the empty flag
  /// of queue (low bits); Light: 2 the volume's dimensions and lit, 3 a flush.
  input  logic [2+gicube_sample_pkg::cfg_addr_w(Shade)-1:0] cfg_addr_i,
  /// gicube_sample's data; the empty flag in bit 0; region 2: x, y, z dimensions (7 bits each),
  /// lit (bit 21).
  input  logic [gicube_sample_pkg::CfgDataW-1:0] cfg_data_i,

  /// Sticky: some volume read (or write-back) since reset came back with RRESP (BRESP) != OKAY
  /// (gicube_cache's).
  output logic err_o,

  // The ring (Procs > 1; docs/numerics/gicube_ring.md): lockstep cycles and the neighbour port.
  /// Issue the processor cycle now (the ring's go: every processor could, some has work).
  input  logic go_i,
  /// This processor could issue a cycle (its front end, output and ring's head are ready).
  output logic can_o,
  /// It has work: an offer on in_*, a ray in its queues or in its ring.
  output logic busy_o,
  /// A cycle is between its issue and its dispatch.
  output logic waiting_o,
  /// The offer on in_* is a neighbour's ray (its link), not the host's.
  input  logic in_nb_i,
  /// The ring's ray belongs to processor nb_dest_o: at go it is sent if nb_grant_i, else it is
  /// returned to the host through the output (OVERFLOW set).
  output logic nb_req_o,
  output logic [1:0] nb_dest_o,
  output logic [gicube_pkg::PacketW-1:0] nb_data_o,
  /// The link to nb_dest_o takes the ray.
  input  logic nb_grant_i,
  /// The counts (rays_in, finished, overflowed, samples, leaps, cycles, cache hits, misses,
  /// nb_in, nb_out; 32 bits each, LSB first).
  output logic [gicube_ring_pkg::RingCounts*32-1:0] cnt_o,

  // AXI4 channels (gicube_cache's): the volume in memory (AR, R); Light: the cache's
  // write-back of dirty lines (AW, W, B), else idle.
  `CUBE5_AXI4_MGR_PORTS(m_axi_, 32, DataW, 4)
);

  localparam int unsigned PacketW  = gicube_pkg::PacketW;
  localparam int unsigned PosW     = gicube_pkg::PosW;
  localparam int unsigned PosFracW = gicube_pkg::PosFracW;
  localparam int unsigned StartLsb = gicube_pkg::PacketStartLsb;
  localparam int unsigned DirLsb   = StartLsb + 3 * PosW;            // 84
  localparam int unsigned ColLsb   = DirLsb + 3 * 16;                // 132: red, green, blue, opacity
  localparam int unsigned TypeLsb  = 224;
  localparam int unsigned TermBit  = gicube_pkg::PacketFlagsLsb + gicube_pkg::FlagTerminated;
  localparam int unsigned QueueW   = gicube_pkg::bucket_queue_w(VolBlocks, 0);
  localparam int unsigned Queues   = 1 << QueueW;
  localparam int unsigned LenW     = gicube_pkg::rq_len_w(QueueLen);
  localparam int unsigned TotW     = gicube_pkg::rq_tot_w(QueueW, QueueLen);
  localparam int unsigned FeInW    = 3 + 2 * PacketW;
  localparam int unsigned FeOutW   = 7 + 3 * QueueW + LenW + TotW + 2 * PacketW;
  localparam int unsigned Side     = VolBlocks << BlockLog2;         // N
  // The cache: the volume padded to the smallest power of two above N, a voxel per word (Light:
  // the irradiance field in the word's top 16 bits; Shade: the density, tag and gradient index
  // in the smallest of 8, 16 or 32 bits that holds them).
  localparam int unsigned MaxDim   = 1 << $clog2(Side + 1);
  localparam int unsigned MW       = $clog2(MaxDim);                 // bits of a cache coordinate
  localparam int unsigned FieldsW  = VoxelW + ((Shade != 0) ? TagW + GradIdxW : 0);
  localparam int unsigned WordW    = (Light != 0) ? 32 : (FieldsW <= 8) ? 8
                                   : (FieldsW <= 16) ? 16 : 32;
  localparam int unsigned TagLsb   = VoxelW;                         // Shade: the tag,
  localparam int unsigned GradLsb  = VoxelW + TagW;                  // the gradient index
  localparam int unsigned IrrW     = gicube_sample_pkg::IrrW;
  localparam int unsigned CaInW    = 3 * MW + ((Light != 0) ? 2 + 8 * IrrW : 0);
  localparam int unsigned DpInW    = 3 * MW + 12 + 12 + 3 * PosFracW + 2 + 21;
  localparam int unsigned CaOutW   = 8 * WordW + 8 + 2 * 32 + 16;    // vox, hit, hits, misses, stall
  // flush, lighting, colour, weights
  localparam int unsigned CellW    = 1 + 1 + 48 + 3 * PosFracW;
  // The cell FIFO covers the requests the cache holds (P + 3 with prefetch: CacheConfig::held_max)
  // and the one in the skid before it.
  // Light: five more in gicube_deposit (P + 3 + 1 + 5, a power of two; 8 without prefetch).
  localparam int unsigned CellD    = (Light != 0) ? ((Prefetch == 0) ? 8 : (1 << $clog2(Prefetch + 9)))
                                                : (1 << $clog2(Prefetch + 4));
  // 2 region bits over gicube_sample's address.
  localparam int unsigned SmCfgAW  = gicube_sample_pkg::cfg_addr_w(Shade);
  localparam int unsigned CfgAW    = 2 + SmCfgAW;
  localparam int unsigned SmShW    = gicube_sample_pkg::shade_in_w(Shade, GradIdxW, TagW);
  localparam int unsigned SmInW    = gicube_sample_pkg::in_w(VoxelW) + SmShW;
  localparam int unsigned SmOutW   = gicube_sample_pkg::OutW;        // colour, opacity, terminated
  localparam int unsigned StInW    = 3 * PosW + 3 * 16 + QueueW + 1;
  localparam int unsigned KW       = BlockLog2 + 9;
  localparam int unsigned StOutW   = KW + 1 + 3 * PosW + QueueW;
  localparam int unsigned TvW      = 1 + 3 * PosW;                   // exit, next
  localparam int unsigned SideW    = 2 + PacketW;                    // ray, leap, packet
  localparam int unsigned FifoD    = (RingLat < 2) ? 2 : (1 << $clog2(RingLat));
  localparam int unsigned LeadW    = $clog2(RingLat + 1);
  localparam int unsigned CntW     = 32;
  localparam int unsigned OutW     = 1 + PacketW + 8 * CntW + 1 + Scatter * CntW;
  localparam int unsigned IntLsb   = 192;                            // interaction, lifetime,
  localparam int unsigned LifeLsb  = 208;                            // generation
  localparam int unsigned GenLsb   = 216;

  if (BlockLog2 < 2 || BlockLog2 > 8) begin : gen_bad_block_log2
    $fatal(1, "gicube_processor: BlockLog2 must be 2..8");
  end
  if (VolBlocks < 1 || VolBlocks > 6 || Side > 64) begin : gen_bad_vol_blocks
    $fatal(1, "gicube_processor: VolBlocks must be 1..6 with N = VolBlocks 2^BlockLog2 <= 64");
  end
  if (RingLat < 1 || RingLat > 16) begin : gen_bad_ring_lat
    $fatal(1, "gicube_processor: RingLat must be 1..16");
  end
  if (Light > 1 || (Light != 0 && DataW < 64)) begin : gen_bad_light
    $fatal(1, "gicube_processor: Light must be 0 or 1, with DataW >= 64");
  end
  if (Scatter > 1 || (Scatter != 0 && Light == 0)) begin : gen_bad_scatter
    $fatal(1, "gicube_processor: Scatter must be 0 or 1, and 1 only with Light");
  end
  if (Jitter > 1) begin : gen_bad_jitter
    $fatal(1, "gicube_processor: Jitter must be 0 or 1");
  end
  if (Shade > 1 || (Shade != 0 && Light != 0) || (Shade == 0 && TagW != 0)) begin : gen_bad_shade
    $fatal(1, "gicube_processor: Shade must be 0 or 1, 1 only without Light, TagW 0 without it");
  end
  if (!(Procs == 1 || Procs == 2 || Procs == 4) || VolBlocks % Procs != 0 || ProcId >= Procs
      || (Procs > 1 && Light != 0)) begin : gen_bad_procs
    $fatal(1, "gicube_processor: Procs must be 1, 2 or 4 dividing VolBlocks, ProcId below it, Light 0");
  end

  // ---------------------------------------------------------------------------
  // Configuration: the empty flags (gicube_sample takes region 0)
  // ---------------------------------------------------------------------------
  logic [1:0]        cfg_region;
  logic              cfg_sample, cfg_empty, cfg_gi, cfg_flush;
  logic [Queues-1:0] empty_q;
  logic [20:0]       dims_q;    // Light: the volume's dimensions, x lowest (7 bits each)
  logic              lit_q;     // Light: rendering rays are lit by the field

  assign cfg_region = cfg_addr_i[CfgAW-1 -: 2];
  assign cfg_sample = cfg_valid_i && (cfg_region == 2'd0);
  assign cfg_empty  = cfg_valid_i && (cfg_region == 2'd1);
  // Scatter: region 2 address 0 the GI registers, 1 the photon registers, 2 the top bits of a
  // scattering-table entry, 0x2000 + a the scattering unit's address a.
  assign cfg_gi     = cfg_valid_i && (cfg_region == 2'd2) && (Light != 0)
                      && (Scatter == 0 || cfg_addr_i[13:0] == 14'd0);
  assign cfg_flush  = cfg_valid_i && (cfg_region == 2'd3) && (Light != 0);

  // The block LUT of empty flags [357] and the GI registers (datapath state: no reset, written by
  // the host).
  always_ff @(posedge clk_i) begin
    if (cfg_empty) begin
      empty_q[cfg_addr_i[0 +: QueueW]] <= cfg_data_i[0];
    end
    if (cfg_gi) begin
      dims_q <= cfg_data_i[20:0];
      lit_q  <= cfg_data_i[21];
    end
  end

  // ---------------------------------------------------------------------------
  // The processor cycle: issue (the front end's item) and dispatch (its output item)
  // ---------------------------------------------------------------------------
  logic               waiting_q;            // an item is in the front end
  logic [LeadW-1:0]   lead_q;               // ring slots still owed their initial bubble
  logic               fe_in_valid, fe_in_ready, fe_out_valid, fe_out_ready;
  logic [FeInW-1:0]   fe_in;
  logic [FeOutW-1:0]  fe_out;

  // The front end's output item.
  logic               o_act_v, o_popped, o_ring_ovf, o_host_taken;
  logic [QueueW-1:0]  o_act_q;
  logic [TotW-1:0]    o_total;
  logic [PacketW-1:0] o_pop_ray, o_ovf_ray;

  assign o_act_v      = fe_out[0];
  assign o_act_q      = fe_out[1 +: QueueW];
  assign o_popped     = fe_out[1 + QueueW];
  assign o_ring_ovf   = fe_out[4 + QueueW];
  assign o_host_taken = fe_out[5 + QueueW];
  assign o_total      = fe_out[7 + 3 * QueueW + LenW +: TotW];
  assign o_pop_ray    = fe_out[7 + 3 * QueueW + LenW + TotW +: PacketW];
  assign o_ovf_ray    = fe_out[7 + 3 * QueueW + LenW + TotW + PacketW +: PacketW];

  // The ring's head: the record of the cycle RingLat ago (side FIFO), and its results.
  logic               sd_empty, sd_full, sm_empty, sm_full, tv_empty, tv_full;
  logic [SideW-1:0]   sd_head;
  logic [SmOutW-1:0]  sm_head;
  logic [TvW-1:0]     tv_head;
  logic               h_ray, h_leap, h_term, h_done;
  logic [PacketW-1:0] h_pkt, h_out;
  logic               head_ready, issue, dispatch;
  logic [4:0]         ring_rays_q;  // rays in the ring (popped, outcome not yet taken), <= RingLat
  logic               held_q;       // the queues hold rays (the last cycle's total)
  logic               busy;

  // The host offers or a ray is in the processor: the condition of the model's frame loop.
  assign busy = in_valid_i || held_q || (ring_rays_q != '0);

  assign h_ray  = sd_head[0];
  assign h_leap = sd_head[1];
  assign h_pkt  = sd_head[2 +: PacketW];

  // The popped ray leaps: its block is empty and it is a rendering ray.
  logic rec_leap;
  assign rec_leap = empty_q[o_act_q] && (o_pop_ray[TypeLsb +: 2] == gicube_pkg::RayTypeRendering);

  // Scatter: the photon path's results at the ring's head (the scattered direction, the albedo
  // draw, the new interaction value; the step on the scattered direction), and the photon mode.
  logic              photon_q;   // Scatter: lighting rays are photons (region 2, address 1)
  logic [16:0]       albedo_q;   // Scatter: the albedo, U(0.16), up to 65536
  logic              sc_empty, sc_full, t2_empty, t2_full;
  logic [16+1+48-1:0] sc_head;   // new interaction, scatter (albedo draw and lifetime), dir
  logic [TvW-1:0]    t2_head;    // exit, next on the scattered direction
  logic              h_photon, h_meet, h_scat, h_absorb, h_exit;

  // The outcome (contract, "One pipeline cycle on one ray"): a sample's colour and opacity unless
  // the ray leapt; terminated, or out of the volume: finished; else advanced to `next`. A photon
  // (Scatter, "Photons in the ring") never terminates; when its opacity reaches its interaction
  // value it scatters (the photon path's direction and step) or is absorbed (finished).
  always_comb begin
    h_out    = h_pkt;
    h_photon = (Scatter != 0) && photon_q
               && (h_pkt[TypeLsb +: 2] == gicube_pkg::RayTypeLighting);
    h_meet   = h_photon && ({sm_head[36 +: 12], 4'b0} >= h_pkt[IntLsb +: 16]);
    h_scat   = h_meet && sc_head[48];
    h_absorb = h_meet && !sc_head[48];
    h_term   = !h_leap && sm_head[SmOutW-1] && !h_photon;
    if (!h_leap) begin
      h_out[ColLsb +: 48] = sm_head[0 +: 48];
    end
    h_exit = h_scat ? t2_head[0] : tv_head[0];
    h_done = h_term || h_absorb || h_exit;
    if (h_scat) begin
      h_out[DirLsb +: 48]     = sc_head[0 +: 48];
      h_out[ColLsb + 36 +: 12] = 12'd0;
      h_out[IntLsb +: 16]     = sc_head[49 +: 16];
      h_out[LifeLsb +: 8]     = h_pkt[LifeLsb +: 8] - 8'd1;
      h_out[GenLsb +: 8]      = h_pkt[GenLsb +: 8] + {7'd0, h_pkt[GenLsb +: 8] != 8'hff};
    end
    if (h_term) begin
      h_out[TermBit] = 1'b1;
    end else if (!h_absorb && !h_exit) begin
      h_out[StartLsb +: 3 * PosW] = h_scat ? t2_head[1 +: 3 * PosW] : tv_head[1 +: 3 * PosW];
    end
  end

  // Output FIFO (finished at issue, overflowed at dispatch); a cycle issues when it is empty.
  logic            of_empty, of_full, of_push_fin, of_push_ovf, of_push, of_pop;
  logic [OutW-1:0] of_d, of_q;

  // A leap's slot needs its step only; a sample's, its sample too; Scatter: every ray's the
  // photon path's results too.
  assign head_ready = (lead_q != '0)
      || (!sd_empty && (!h_ray || (!tv_empty && (h_leap || !sm_empty)
                                   && (Scatter == 0 || (!sc_empty && !t2_empty)))));
  // A cycle is issued only while the host offers or a ray is in the processor (the model's frame
  // loop): idle cycles would step the sorter (its Noops move its scan), which the model's frame
  // does not see.
  // While a flush is in the cache, no cycle is issued (its output item has the output alone).
  logic flush_fly_q;
  logic can_issue;
  assign can_issue  = !waiting_q && fe_in_ready && of_empty && head_ready && !flush_fly_q;
  // In a ring (Procs > 1) every processor issues at the ring's go (lockstep cycles).
  assign issue      = (Procs == 1) ? (can_issue && busy) : go_i;
  // A sampling ray's cell goes to the cache (Light: to gicube_deposit) in the dispatch clock: the
  // dispatch waits while the cache (or the deposit pipeline) cannot take it.
  logic smp_req, fetch_ready;
  assign smp_req    = waiting_q && fe_out_valid && o_popped && !rec_leap;
  assign dispatch   = waiting_q && fe_out_valid && (!smp_req || fetch_ready);

  // The front end's item: take, ring, host, ring ray, host ray.
  // The ring's ray in a ring of processors: it belongs to slab h_owner; another's is sent to its
  // link (granted) or returned to the host (nb_ret), and does not enter this front end.
  logic       ring_v, nb_req, nb_ret, offer_nb_q, offer_nb;
  logic [1:0] h_owner;
  assign h_owner      = gicube_ring_pkg::ring_owner(h_out[StartLsb + PosFracW +: gicube_pkg::PosIntW],
                                               BlockLog2, VolBlocks / Procs, Procs);
  assign nb_req       = (Procs > 1) && (lead_q == '0) && h_ray && !h_done
                        && (h_owner != 2'(ProcId));
  assign nb_ret       = issue && nb_req && !nb_grant_i;
  assign offer_nb     = (Procs > 1) && offer_nb_q;
  assign ring_v       = (lead_q == '0) && h_ray && !h_done && !nb_req;
  assign fe_in_valid  = issue;
  assign fe_in        = {in_data_i, h_out, in_valid_i, ring_v, 1'b1};
  assign fe_out_ready = dispatch;

  // The host's ray is taken in the dispatch clock of the cycle that took it (it was offered, and
  // held, since the issue).
  assign in_ready_o = dispatch && o_host_taken;


  // Counts.
  logic [CntW-1:0] c_in_q, c_fin_q, c_ovf_q, c_smp_q, c_leap_q, c_cyc_q, c_hit_q, c_mis_q;
  logic [CntW-1:0] c_in_d, c_fin_d, c_ovf_d, c_smp_d, c_leap_d, c_cyc_d, c_hit_d, c_mis_d;
  logic [CntW-1:0] c_sct_q, c_sct_d, c_nbi_q, c_nbi_d, c_nbo_q, c_nbo_d;
  logic              ca_out_valid;
  logic [CaOutW-1:0] ca_out;

  always_comb begin
    c_in_d   = c_in_q   + CntW'(dispatch && o_host_taken && !offer_nb);
    c_nbi_d  = c_nbi_q  + CntW'(dispatch && o_host_taken && offer_nb);
    c_nbo_d  = c_nbo_q  + CntW'(issue && nb_req && nb_grant_i);
    c_ovf_d  = c_ovf_q  + CntW'(dispatch && o_ring_ovf) + CntW'(nb_ret);
    c_smp_d  = c_smp_q  + CntW'(dispatch && o_popped && !rec_leap);
    c_leap_d = c_leap_q + CntW'(dispatch && o_popped && rec_leap);
    c_fin_d  = c_fin_q  + CntW'(issue && (lead_q == '0) && h_ray && h_done);
    c_cyc_d  = c_cyc_q  + CntW'(issue);
    c_sct_d  = c_sct_q  + CntW'(issue && (lead_q == '0) && h_ray && h_scat);
    // The cache's running counts, as its last output gave them.
    c_hit_d  = ca_out_valid ? ca_out[8 * WordW + 8 +: CntW] : c_hit_q;
    c_mis_d  = ca_out_valid ? ca_out[8 * WordW + 8 + CntW +: CntW] : c_mis_q;
  end

  assign of_push_fin = issue && (lead_q == '0) && h_ray && h_done;
  assign of_push_ovf = dispatch && o_ring_ovf;
  assign of_push     = of_push_fin || of_push_ovf || of_push_flush || nb_ret;
  logic of_push_flush;
  // A ray the link refused goes back to the host with OVERFLOW set.
  logic [PacketW-1:0] h_ret;
  always_comb begin
    h_ret = h_out;
    h_ret[gicube_pkg::PacketFlagsLsb + gicube_pkg::FlagOverflow] = 1'b1;
  end
  logic [OutW-CntW*Scatter-1:0] of_base;
  assign of_base     = {of_push_flush, c_mis_d, c_hit_d, c_cyc_d, c_leap_d, c_smp_d, c_ovf_d,
                        c_fin_d, c_in_d,
                        of_push_fin ? h_out : nb_ret ? h_ret
                                    : of_push_flush ? PacketW'(0) : o_ovf_ray,
                        of_push_fin};
  // Scatter: the scatterings above the flush bit.
  if (Scatter != 0) begin : gen_out_sct
    assign of_d = {c_sct_d, of_base};
  end else begin : gen_out_base
    assign of_d = of_base;
  end
  assign of_pop      = out_valid_o && out_ready_i;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      waiting_q   <= 1'b0;
      lead_q      <= LeadW'(RingLat);
      ring_rays_q <= '0;
      held_q      <= 1'b0;
      c_in_q      <= '0;
      c_fin_q     <= '0;
      c_ovf_q     <= '0;
      c_smp_q     <= '0;
      c_leap_q    <= '0;
      c_cyc_q     <= '0;
      c_hit_q     <= '0;
      c_mis_q     <= '0;
      c_sct_q     <= '0;
      c_nbi_q     <= '0;
      c_nbo_q     <= '0;
      offer_nb_q  <= 1'b0;
    end else begin
      if (issue) begin
        offer_nb_q <= in_nb_i;
      end
      if (issue) begin
        waiting_q <= 1'b1;
      end else if (dispatch) begin
        waiting_q <= 1'b0;
      end
      if (issue && lead_q != '0) begin
        lead_q <= lead_q - LeadW'(1);
      end
      if (dispatch) begin
        held_q <= (o_total != '0);
      end
      if (dispatch && o_popped) begin
        ring_rays_q <= ring_rays_q + 5'd1;
      end else if (issue && lead_q == '0 && h_ray) begin
        ring_rays_q <= ring_rays_q - 5'd1;
      end
      c_in_q   <= c_in_d;
      c_fin_q  <= c_fin_d;
      c_ovf_q  <= c_ovf_d;
      c_smp_q  <= c_smp_d;
      c_leap_q <= c_leap_d;
      c_cyc_q  <= c_cyc_d;
      c_hit_q  <= c_hit_d;
      c_mis_q  <= c_mis_d;
      c_sct_q  <= c_sct_d;
      c_nbi_q  <= c_nbi_d;
      c_nbo_q  <= c_nbo_d;
    end
  end

  // The ring's view of this processor (Procs > 1; with one processor the ports are tied off, so
  // a processor on its own spends no logic on them).
  if (Procs > 1) begin : gen_ring_view
    assign can_o     = can_issue;
    assign busy_o    = busy;
    assign waiting_o = waiting_q;
    assign nb_req_o  = nb_req;
    assign nb_dest_o = h_owner;
    assign nb_data_o = h_out;
    assign cnt_o     = {c_nbo_q, c_nbi_q, c_mis_q, c_hit_q, c_cyc_q, c_leap_q, c_smp_q, c_ovf_q,
                        c_fin_q, c_in_q};
  end else begin : gen_no_ring_view
    assign can_o     = 1'b0;
    assign busy_o    = 1'b0;
    assign waiting_o = 1'b0;
    assign nb_req_o  = 1'b0;
    assign nb_dest_o = 2'd0;
    assign nb_data_o = '0;
    assign cnt_o     = '0;
  end

  gicube_queue_front #(
    .BlockLog2 (BlockLog2),
    .VolBlocks (VolBlocks),
    .QueueLen  (QueueLen),
    .Ranks     (Ranks)
  ) u_front (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (fe_in_valid),
    .in_ready_o  (fe_in_ready),
    .in_data_i   (fe_in),
    .out_valid_o (fe_out_valid),
    .out_ready_i (fe_out_ready),
    .out_data_o  (fe_out)
  );

  // ---------------------------------------------------------------------------
  // Fetch: the sampling ray's cell through the volume cache (the volume in memory)
  // ---------------------------------------------------------------------------
  logic               ca_in_valid, ca_in_ready, fx_valid, fx_ready;
  logic [CaInW-1:0]   ca_in, fx_data;
  logic               cell_push, cell_empty, cell_full, cell_flush;
  logic [CellW-1:0]   cell_d, cell_q;
  logic [3*MW-1:0]    cell_xyz;
  logic               flush_pend_q, flush_go;

  // The cell's lowest voxel: the start's integer part (below N < MaxDim).
  assign cell_xyz    = {o_pop_ray[StartLsb + 2 * PosW + PosFracW +: MW],
                        o_pop_ray[StartLsb + PosW + PosFracW +: MW],
                        o_pop_ray[StartLsb + PosFracW +: MW]};
  // The flush enters the cache's stream when the processor holds no ray and no cycle is in
  // flight (the host wrote it after the pass's last ray came out), and the output is empty.
  assign flush_go    = (Light != 0) && flush_pend_q && !waiting_q && !issue && (ring_rays_q == '0)
                       && !held_q && of_empty && fetch_ready;
  // What the sample needs beside the voxels: lighting, colour and opacity, the weights; a
  // flush's record says so.
  assign cell_push   = (smp_req && fetch_ready) || flush_go;
  assign cell_d      = {flush_go,
                        o_pop_ray[TypeLsb +: 2] == gicube_pkg::RayTypeLighting,
                        o_pop_ray[ColLsb +: 48],
                        o_pop_ray[StartLsb + 2 * PosW +: PosFracW],
                        o_pop_ray[StartLsb + PosW +: PosFracW], o_pop_ray[StartLsb +: PosFracW]};
  assign cell_flush  = cell_q[CellW-1];

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      flush_pend_q <= 1'b0;
      flush_fly_q  <= 1'b0;
    end else begin
      if (cfg_flush) begin
        flush_pend_q <= 1'b1;
      end else if (flush_go) begin
        flush_pend_q <= 1'b0;
      end
      if (flush_go) begin
        flush_fly_q <= 1'b1;
      end else if (of_push_flush) begin
        flush_fly_q <= 1'b0;
      end
    end
  end

  if (Light != 0) begin : gen_deposit
    // The item: a lighting ray's deposit, a rendering ray's read, or the flush.
    logic [DpInW-1:0] dp_in;
    logic [1:0]       dp_op;
    logic [11:0]      dp_opa;
    assign dp_op  = flush_go ? 2'd2
                  : (o_pop_ray[TypeLsb +: 2] == gicube_pkg::RayTypeLighting) ? 2'd1 : 2'd0;
    // A photon deposits with T = 4096: its deposit sees opacity 0 (Scatter).
    assign dp_opa = photon_q ? 12'd0 : o_pop_ray[ColLsb + 36 +: 12];
    assign dp_in  = {dims_q, dp_op,
                     o_pop_ray[StartLsb + 2 * PosW +: PosFracW],
                     o_pop_ray[StartLsb + PosW +: PosFracW], o_pop_ray[StartLsb +: PosFracW],
                     dp_opa, o_pop_ray[ColLsb +: 12], cell_xyz};

    gicube_deposit #(
      .MW   (MW),
      .Step (Step)
    ) u_deposit (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (smp_req || flush_go),
      .in_ready_o  (fetch_ready),
      .in_data_i   (dp_in),
      .out_valid_o (fx_valid),
      .out_ready_i (fx_ready),
      .out_data_o  (fx_data)
    );
  end else begin : gen_read
    assign fx_valid    = smp_req;
    assign fx_data     = cell_xyz;
    assign fetch_ready = fx_ready;
  end

  // The skid before the cache: its ready is a register, so the dispatch (and with it the ring's
  // issue) does not wait on the cache's hit, miss or flush decision of the same clock. An item
  // the cache refuses parks in the skid (in order), and the next item waits until the cache has
  // taken it; the cache sees the same items in the same order.
  logic             skid_v_q;
  logic [CaInW-1:0] skid_q;

  assign fx_ready    = !skid_v_q;
  assign ca_in_valid = skid_v_q || fx_valid;
  assign ca_in       = skid_v_q ? skid_q : fx_data;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      skid_v_q <= 1'b0;
    end else if (skid_v_q) begin
      skid_v_q <= !ca_in_ready;
    end else begin
      skid_v_q <= fx_valid && !ca_in_ready;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!skid_v_q) begin
      skid_q <= fx_data;
    end
  end


  gicube_cache #(
    .MaxDim      (MaxDim),
    .WordW       (WordW),
    .DataW       (DataW),
    .LineVox     (LineVox),
    .Sets        (Sets),
    .Outstanding (Outstanding),
    .AddrW       (32),
    .Splat       (Light),
    .Prefetch    (Prefetch)
  ) u_cache (
    .clk_i           (clk_i),
    .rst_ni          (rst_ni),
    .in_valid_i      (ca_in_valid),
    .in_ready_o      (ca_in_ready),
    .in_data_i       (ca_in),
    .out_valid_o     (ca_out_valid),
    .out_ready_i     (1'b1),
    .out_data_o      (ca_out),
    .err_o           (err_o),
    .m_axi_araddr_o  (m_axi_araddr_o),
    .m_axi_arlen_o   (m_axi_arlen_o),
    .m_axi_arsize_o  (m_axi_arsize_o),
    .m_axi_arburst_o (m_axi_arburst_o),
    .m_axi_arid_o    (m_axi_arid_o),
    .m_axi_arvalid_o (m_axi_arvalid_o),
    .m_axi_arready_i (m_axi_arready_i),
    .m_axi_rdata_i   (m_axi_rdata_i),
    .m_axi_rresp_i   (m_axi_rresp_i),
    .m_axi_rlast_i   (m_axi_rlast_i),
    .m_axi_rid_i     (m_axi_rid_i),
    .m_axi_rvalid_i  (m_axi_rvalid_i),
    .m_axi_rready_o  (m_axi_rready_o),
    // Light: the write-back of dirty lines; Splat = 0 keeps them idle.
    .m_axi_awaddr_o  (m_axi_awaddr_o),
    .m_axi_awlen_o   (m_axi_awlen_o),
    .m_axi_awsize_o  (m_axi_awsize_o),
    .m_axi_awburst_o (m_axi_awburst_o),
    .m_axi_awid_o    (m_axi_awid_o),
    .m_axi_awvalid_o (m_axi_awvalid_o),
    .m_axi_awready_i (m_axi_awready_i),
    .m_axi_wdata_o   (m_axi_wdata_o),
    .m_axi_wstrb_o   (m_axi_wstrb_o),
    .m_axi_wlast_o   (m_axi_wlast_o),
    .m_axi_wvalid_o  (m_axi_wvalid_o),
    .m_axi_wready_i  (m_axi_wready_i),
    .m_axi_bresp_i   (m_axi_bresp_i),
    .m_axi_bid_i     (m_axi_bid_i),
    .m_axi_bvalid_i  (m_axi_bvalid_i),
    .m_axi_bready_o  (m_axi_bready_o)
  );

  // The cache holds two requests at most (the one at its check, its output register), the skid
  // one; Light: five more in gicube_deposit.
  cube5_frame_fifo #(.Width(CellW), .Depth(CellD)) u_cell_fifo (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (cell_push),
    .d_i     (cell_d),
    .pop_i   (ca_out_valid),
    .q_o     (cell_q),
    .empty_o (cell_empty),
    .full_o  (cell_full)
  );

  // Corner c's voxel: the low VoxelW bits of the cache's word c; its irradiance (Light): the
  // word's top IrrW bits.
  logic [8*VoxelW-1:0] voxels;
  logic [8*IrrW-1:0]   irrs;
  for (genvar c = 0; c < 8; c++) begin : gen_voxel
    assign voxels[c * VoxelW +: VoxelW] = ca_out[c * WordW +: VoxelW];
    if (Light != 0) begin : gen_irr
      assign irrs[c * IrrW +: IrrW] = ca_out[c * WordW + WordW - IrrW +: IrrW];
    end else begin : gen_no_irr
      assign irrs[c * IrrW +: IrrW] = '0;
    end
  end
  // A rendering ray is lit when the field is loaded (Light, `lit`).
  logic irr_en;
  assign irr_en = (Light != 0) && lit_q && !cell_q[CellW-2];

  // The record of the dispatched cycle, one clock later.
  logic               f_v_q, f_ray_q, f_leap_q;
  logic [QueueW-1:0]  f_q_q;
  logic [PacketW-1:0] f_pkt_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      f_v_q <= 1'b0;
    end else begin
      f_v_q <= dispatch;
    end
  end

  always_ff @(posedge clk_i) begin
    if (dispatch) begin
      f_ray_q  <= o_popped;
      f_leap_q <= rec_leap;
      f_q_q    <= o_act_q;
      f_pkt_q  <= o_pop_ray;
    end
  end

  // ---------------------------------------------------------------------------
  // The ring: the sample and the step side by side, never stalled, each into a FIFO
  // ---------------------------------------------------------------------------
  logic              go, go_sample;
  logic [SmInW-1:0]  sm_in;
  logic [StInW-1:0]  st_in;
  logic              sm_in_ready, sm_out_valid, st_in_ready, st_out_valid;
  logic [SmOutW-1:0] sm_out;
  logic [StOutW-1:0] st_out;

  assign go        = f_v_q && f_ray_q;
  assign go_sample = ca_out_valid && !cell_flush;
  assign of_push_flush = ca_out_valid && cell_flush;
  // voxels, weights (the start's fraction bits), irradiance, colour and opacity, lighting;
  // Shade: the corners' gradient indices, then their tags, the fields above each word's
  // density.
  if (Shade != 0) begin : gen_sm_in_shade
    logic [SmShW-1:0] shades;
    for (genvar c = 0; c < 8; c++) begin : gen_corner
      assign shades[c * GradIdxW +: GradIdxW] = ca_out[c * WordW + GradLsb +: GradIdxW];
      if (TagW != 0) begin : gen_tag
        assign shades[8 * GradIdxW + c * TagW +: TagW] = ca_out[c * WordW + TagLsb +: TagW];
      end
    end
    assign sm_in = {shades, cell_q[CellW-2 -: 49], irrs, irr_en, cell_q[0 +: 3 * PosFracW],
                    voxels};
  end else begin : gen_sm_in
    assign sm_in = {cell_q[CellW-2 -: 49], irrs, irr_en, cell_q[0 +: 3 * PosFracW], voxels};
  end
  // start, dir, queue, leap.
  assign st_in = {f_leap_q, f_q_q, f_pkt_q[DirLsb +: 48], f_pkt_q[StartLsb +: 3 * PosW]};

  gicube_sample #(
    .VoxelW   (VoxelW),
    .Jitter   (Jitter),
    .Shade    (Shade),
    .GradIdxW (GradIdxW),
    .TagW     (TagW)
  ) u_sample (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (go_sample),
    .in_ready_o  (sm_in_ready),
    .in_data_i   (sm_in),
    .out_valid_o (sm_out_valid),
    .out_ready_i (1'b1),
    .out_data_o  (sm_out),
    .cfg_valid_i (cfg_sample),
    .cfg_addr_i  (cfg_addr_i[SmCfgAW-1:0]),
    .cfg_data_i  (cfg_data_i)
  );

  gicube_step #(
    .BlockLog2 (BlockLog2),
    .VolBlocks (VolBlocks),
    .Step      (Step)
  ) u_step (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (go),
    .in_ready_o  (st_in_ready),
    .in_data_i   (st_in),
    .out_valid_o (st_out_valid),
    .out_ready_i (1'b1),
    .out_data_o  (st_out)
  );

  logic pop_head;
  assign pop_head = issue && (lead_q == '0);

  // ---------------------------------------------------------------------------
  // Scatter: the photon path beside the sample and the step (contract, "Photons in the ring")
  // ---------------------------------------------------------------------------
  if (Scatter != 0) begin : gen_photon
    localparam int unsigned ScF    = 14;                                  // S(2.14) directions
    localparam int unsigned ScGW   = 21;
    localparam int unsigned ScM    = 8;
    localparam int unsigned ScInW  = gicube_scatter_pkg::in_w(ScF, ScGW, ScM);
    localparam int unsigned ScOutW = gicube_scatter_pkg::out_w(ScF);
    localparam int unsigned ScCfgW = gicube_scatter_pkg::cfg_data_w(ScF);
    localparam int unsigned HashL  = gicube_scatter_pkg::HashLatency;
    localparam int unsigned AuxW   = 16 + 1 + 3 * PosW;                  // interaction, scatter, start
    localparam logic [31:0] AlbedoKey      = 32'h2545_f491;
    localparam logic [31:0] InteractionKey = 32'h5bd1_e995;

    // The photon registers and the top bits of a scattering-table entry (no reset: host state).
    logic               cfg_photon, cfg_hi, cfg_sc;
    logic [ScCfgW-gicube_sample_pkg::CfgDataW-1:0] hi_q;
    assign cfg_photon = cfg_valid_i && (cfg_region == 2'd2) && (cfg_addr_i[13:0] == 14'd1);
    assign cfg_hi     = cfg_valid_i && (cfg_region == 2'd2) && (cfg_addr_i[13:0] == 14'd2);
    assign cfg_sc     = cfg_valid_i && (cfg_region == 2'd2) && cfg_addr_i[13];

    always_ff @(posedge clk_i) begin
      if (cfg_photon) begin
        albedo_q <= cfg_data_i[16:0];
        photon_q <= cfg_data_i[17];
      end
      if (cfg_hi) begin
        hi_q <= cfg_data_i[0 +: ScCfgW - gicube_sample_pkg::CfgDataW];
      end
    end

    // The ray's mangling bits ([380], [385]): u + 2^12 v + 2^24 generation, XOR the position
    // x ^ rotl(y, 10) ^ rotl(z, 20); with the next generation (saturating) for the new draw.
    logic [31:0] pos_bits, bits, bits_next, sy, sz;
    logic [7:0]  gen, gen_next;
    assign sy        = 32'(f_pkt_q[StartLsb + PosW +: PosW]);
    assign sz        = 32'(f_pkt_q[StartLsb + 2 * PosW +: PosW]);
    assign pos_bits  = 32'(f_pkt_q[StartLsb +: PosW]) ^ {sy[21:0], sy[31:22]}
                       ^ {sz[11:0], sz[31:12]};
    assign gen       = f_pkt_q[GenLsb +: 8];
    assign gen_next  = gen + {7'd0, gen != 8'hff};
    assign bits      = {gen, f_pkt_q[0 +: 24]} ^ pos_bits;
    assign bits_next = {gen_next, f_pkt_q[0 +: 24]} ^ pos_bits;

    // The albedo draw and the next interaction value: lane 0 of two hash units, HashL clocks.
    logic [95:0] pool_a, pool_i;
    gicube_scatter_hash u_hash_albedo (
      .clk_i      (clk_i),
      .en_i       (1'b1),
      .ray_bits_i (bits ^ AlbedoKey),
      .pool_o     (pool_a)
    );
    gicube_scatter_hash u_hash_interaction (
      .clk_i      (clk_i),
      .en_i       (1'b1),
      .ray_bits_i (bits_next ^ InteractionKey),
      .pool_o     (pool_i)
    );

    // The ray's start and whether it may scatter (lifetime > 0), beside the hashes.
    logic [HashL-1:0]   hv_q;
    logic [3*PosW-1:0]  hstart_q [HashL];
    logic [HashL-1:0]   hlive_q;
    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        hv_q <= '0;
      end else begin
        hv_q <= {hv_q[HashL-2:0], go};
      end
    end
    always_ff @(posedge clk_i) begin
      hstart_q[0] <= f_pkt_q[StartLsb +: 3 * PosW];
      hlive_q[0]  <= f_pkt_q[LifeLsb +: 8] != 8'd0;
      for (int i = 1; i < HashL; i++) begin
        hstart_q[i] <= hstart_q[i-1];
        hlive_q[i]  <= hlive_q[i-1];
      end
    end

    // Scatter (the albedo draw below the albedo, lifetime left) and the new interaction value
    // min(H >> 16, 65520).
    logic [AuxW-1:0] aux_d, aux_q;
    logic            aux_empty, aux_full;
    logic [15:0]     int_new;
    assign int_new = (pool_i[31:16] > 16'd65520) ? 16'd65520 : pool_i[31:16];
    assign aux_d   = {int_new, ({1'b0, pool_a[15:0]} < albedo_q) && hlive_q[HashL-1],
                      hstart_q[HashL-1]};

    // gicube_scatter: isotropic (iso = 1, no reflection, refraction or gloss, eta = 1, zero
    // gradient) from the ray's direction and bits; 42 clocks, never stalled.
    logic [ScInW-1:0]  sc_in;
    logic [ScOutW-1:0] sc_out;
    logic              sc_in_ready, sc_out_valid;
    assign sc_in = {bits, (ScM + 2)'(1 << ScM), (ScM + 1)'(0), (ScM + 1)'(1 << ScM),
                    (ScM + 1)'(0), (ScM + 1)'(0), (3 * ScGW)'(0), f_pkt_q[DirLsb +: 48]};

    gicube_scatter u_scatter (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (go),
      .in_ready_o  (sc_in_ready),
      .in_data_i   (sc_in),
      .out_valid_o (sc_out_valid),
      .out_ready_i (1'b1),
      .out_data_o  (sc_out),
      .cfg_valid_i (cfg_sc),
      .cfg_addr_i  (cfg_addr_i[gicube_scatter_pkg::CfgAddrW-1:0]),
      .cfg_data_i  ({hi_q, cfg_data_i})
    );

    cube5_frame_fifo #(.Width(AuxW), .Depth(FifoD)) u_aux_fifo (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (1'b0),
      .push_i  (hv_q[HashL-1]),
      .d_i     (aux_d),
      .pop_i   (sc_out_valid),
      .q_o     (aux_q),
      .empty_o (aux_empty),
      .full_o  (aux_full)
    );

    // The step on the scattered direction (no leap: a photon never leaps).
    logic [StOutW-1:0] t2_out;
    logic              t2_in_ready, t2_out_valid;
    gicube_step #(
      .BlockLog2 (BlockLog2),
      .VolBlocks (VolBlocks),
      .Step      (Step)
    ) u_step_scattered (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (sc_out_valid),
      .in_ready_o  (t2_in_ready),
      .in_data_i   ({1'b0, QueueW'(0), sc_out[0 +: 48], aux_q[0 +: 3 * PosW]}),
      .out_valid_o (t2_out_valid),
      .out_ready_i (1'b1),
      .out_data_o  (t2_out)
    );

    cube5_frame_fifo #(.Width(16 + 1 + 48), .Depth(FifoD)) u_scatter_fifo (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (1'b0),
      .push_i  (sc_out_valid),
      .d_i     ({aux_q[AuxW-1 -: 17], sc_out[0 +: 48]}),
      .pop_i   (pop_head && h_ray),
      .q_o     (sc_head),
      .empty_o (sc_empty),
      .full_o  (sc_full)
    );

    cube5_frame_fifo #(.Width(TvW), .Depth(FifoD)) u_step2_fifo (
      .clk_i   (clk_i),
      .rst_ni  (rst_ni),
      .clear_i (1'b0),
      .push_i  (t2_out_valid),
      .d_i     (t2_out[KW +: TvW]),
      .pop_i   (pop_head && h_ray),
      .q_o     (t2_head),
      .empty_o (t2_empty),
      .full_o  (t2_full)
    );

    logic unused_photon;
    assign unused_photon = ^{sc_out[ScOutW-1:48], t2_out[0 +: KW], t2_out[KW + TvW +: QueueW],
                             sc_in_ready, t2_in_ready, aux_empty, aux_full, pool_a[95:16],
                             pool_i[95:32], pool_i[15:0]};

`ifndef SYNTHESIS
    // The photon path keeps pace with the ring: its units take every ray, and its FIFOs hold
    // a record each of the ring's RingLat at most.
    PhotonPathInStep: assert property (@(posedge clk_i) disable iff (!rst_ni)
        (!go || sc_in_ready) && (!sc_out_valid || (t2_in_ready && !aux_empty))
        && !(hv_q[HashL-1] && aux_full) && !(sc_out_valid && sc_full)
        && !(t2_out_valid && t2_full))
      else $error("gicube_processor: the photon path fell out of step");
`endif
  end else begin : gen_no_photon
    assign photon_q = 1'b0;
    assign albedo_q = '0;
    assign sc_head  = '0;
    assign t2_head  = '0;
    assign sc_empty = 1'b1;
    assign t2_empty = 1'b1;
    assign sc_full  = 1'b0;
    assign t2_full  = 1'b0;
  end

  cube5_frame_fifo #(.Width(SideW), .Depth(FifoD)) u_side_fifo (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (f_v_q),
    .d_i     ({f_pkt_q, f_leap_q, f_ray_q}),
    .pop_i   (pop_head),
    .q_o     (sd_head),
    .empty_o (sd_empty),
    .full_o  (sd_full)
  );

  cube5_frame_fifo #(.Width(SmOutW), .Depth(FifoD)) u_sample_fifo (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (sm_out_valid),
    .d_i     (sm_out),
    .pop_i   (pop_head && h_ray && !h_leap),
    .q_o     (sm_head),
    .empty_o (sm_empty),
    .full_o  (sm_full)
  );

  cube5_frame_fifo #(.Width(TvW), .Depth(FifoD)) u_step_fifo (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (st_out_valid),
    .d_i     (st_out[KW +: TvW]),
    .pop_i   (pop_head && h_ray),
    .q_o     (tv_head),
    .empty_o (tv_empty),
    .full_o  (tv_full)
  );

  cube5_frame_fifo #(.Width(OutW), .Depth(2)) u_out_fifo (
    .clk_i   (clk_i),
    .rst_ni  (rst_ni),
    .clear_i (1'b0),
    .push_i  (of_push),
    .d_i     (of_d),
    .pop_i   (of_pop),
    .q_o     (of_q),
    .empty_o (of_empty),
    .full_o  (of_full)
  );

  assign out_valid_o = !of_empty;
  assign out_data_o  = of_q;

  // The step's k and queue are not used (the front end re-buckets the ray); the FIFOs' full
  // flags are covered by the assertions below (a record per cycle, RingLat cycles at most).
  logic unused;
  assign unused = ^{st_out[0 +: KW], st_out[KW + TvW +: QueueW], sd_full, sm_full, tv_full,
                    of_full, sm_in_ready, st_in_ready, o_act_v, fe_out, cell_full, cell_empty,
                    ca_out, dims_q, albedo_q, sc_full, t2_full};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_processor: output changed while stalled");
  // The units are never stalled: they take every ray of the ring.
  UnitsTakeEveryRay: assert property (@(posedge clk_i) disable iff (!rst_ni)
      (go || go_sample) |-> (!go || st_in_ready) && (!go_sample || sm_in_ready))
    else $error("gicube_processor: a ring unit refused a ray");
  // The ring holds RingLat records at most, so its FIFOs never overflow.
  RingFifosNeverOverflow: assert property (@(posedge clk_i) disable iff (!rst_ni)
      !(f_v_q && sd_full) && !(sm_out_valid && sm_full) && !(st_out_valid && tv_full))
    else $error("gicube_processor: a ring FIFO overflowed");
  // The host's ray taken at dispatch was offered at the issue and held.
  HostHeldUntilTaken: assert property (@(posedge clk_i) disable iff (!rst_ni)
      in_ready_o |-> in_valid_i)
    else $error("gicube_processor: host ray taken while not offered");
  // Every cache output has its cell's record, and the cell FIFO never overflows.
  CellFifoMatchesCache: assert property (@(posedge clk_i) disable iff (!rst_ni)
      !(ca_out_valid && cell_empty) && !(cell_push && cell_full && !ca_out_valid))
    else $error("gicube_processor: the cell FIFO is out of step with the cache");
`endif

endmodule
