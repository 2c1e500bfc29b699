// gicube_pkg: the GI-Cube ray packet (patent [349]) and the constants and width helpers of the
// queue bucketing and queue sorter units (patent [370], [373], [374]).
//
// The SystemVerilog reading of docs/numerics/gicube_packet.md, gicube_bucket.md and
// gicube_sorter.md; the Rust model (model/src/gicube/) reads the same pages independently.
// Functions assign their name (no `return`) so Yosys 0.23 accepts them.
package gicube_pkg;

  // ---------------------------------------------------------------------------
  // Ray packet (docs/numerics/gicube_packet.md)
  // ---------------------------------------------------------------------------

  /// Bits in a ray packet: 32 bytes [349].
  localparam int unsigned PacketW  = 256;
  /// One start-point coordinate, U(12.8) voxels.
  localparam int unsigned PosW     = 20;
  localparam int unsigned PosFracW = 8;
  localparam int unsigned PosIntW  = 12;

  /// Ray types (the 2-bit `rtype` field); 2 and 3 are reserved and carried unchanged.
  localparam logic [1:0] RayTypeRendering = 2'd0;
  localparam logic [1:0] RayTypeLighting  = 2'd1;

  /// Bit numbers within the 6-bit `flags` field; bits 3..5 are reserved.
  localparam int unsigned FlagIrradiance = 0;  // irradiance carrier [382]
  localparam int unsigned FlagTerminated = 1;  // early ray termination [357]
  localparam int unsigned FlagOverflow   = 2;  // returned to the host [372]

  /// The ray. A packed struct puts its FIRST member at the MOST significant bits, so this is the
  /// contract's LSB-first table read from the bottom up (bit ranges on the right).
  typedef struct packed {
    logic [23:0]        reserved;      // 232..255
    logic [5:0]         flags;         // 226..231
    logic [1:0]         rtype;         // 224..225
    logic [7:0]         generation;    // 216..223
    logic [7:0]         lifetime;      // 208..215
    logic [15:0]        interaction;   // 192..207  U(0.16)
    logic [11:0]        contribution;  // 180..191  U(0.12)
    logic [11:0]        opacity;       // 168..179  U(0.12)
    logic [11:0]        blue;          // 156..167  U(0.12)
    logic [11:0]        green;         // 144..155  U(0.12)
    logic [11:0]        red;           // 132..143  U(0.12)
    logic signed [15:0] dir_z;         // 116..131  S(2.14)
    logic signed [15:0] dir_y;         // 100..115  S(2.14)
    logic signed [15:0] dir_x;         //  84..99   S(2.14)
    logic [19:0]        start_z;       //  64..83   U(12.8)
    logic [19:0]        start_y;       //  44..63   U(12.8)
    logic [19:0]        start_x;       //  24..43   U(12.8)
    logic [11:0]        v;             //  12..23
    logic [11:0]        u;             //   0..11
  } ray_packet_t;

  /// Bit offset of the start point (x, y, z, PosW each) within a packet.
  localparam int unsigned PacketStartLsb = 24;
  /// Bit offset of the 6-bit flags field within a packet.
  localparam int unsigned PacketFlagsLsb = 226;

  // ---------------------------------------------------------------------------
  // Queue bucketing (docs/numerics/gicube_bucket.md)
  // ---------------------------------------------------------------------------

  /// Block distributions of [348] (the `Dist` parameter).
  localparam int unsigned DistSlab          = 0;
  localparam int unsigned DistRepeatingSlab = 1;
  localparam int unsigned DistSkewed        = 2;

  /// Queues per processor, Q = B^3 / p.
  function automatic int unsigned bucket_queues(int unsigned vol_blocks, int unsigned proc_log2);
    bucket_queues = (vol_blocks * vol_blocks * vol_blocks) >> proc_log2;
  endfunction

  /// QueueW = max(1, clog2(Q)).
  function automatic int unsigned bucket_queue_w(int unsigned vol_blocks, int unsigned proc_log2);
    int unsigned w;
    w = $clog2(bucket_queues(vol_blocks, proc_log2));
    bucket_queue_w = (w < 1) ? 1 : w;
  endfunction

  /// ProcW = max(1, ProcLog2).
  function automatic int unsigned bucket_proc_w(int unsigned proc_log2);
    bucket_proc_w = (proc_log2 < 1) ? 1 : proc_log2;
  endfunction

  /// Bits of one output lane: queue, proc, outside.
  function automatic int unsigned bucket_lane_w(int unsigned vol_blocks, int unsigned proc_log2);
    bucket_lane_w = bucket_queue_w(vol_blocks, proc_log2) + bucket_proc_w(proc_log2) + 1;
  endfunction

  // ---------------------------------------------------------------------------
  // Queue sorter (docs/numerics/gicube_sorter.md)
  // ---------------------------------------------------------------------------

  /// Update operations (the 2-bit `op` field); 3 is reserved and behaves as SorterOpNoop.
  localparam logic [1:0] SorterOpNoop = 2'd0;
  localparam logic [1:0] SorterOpAdd  = 2'd1;
  localparam logic [1:0] SorterOpSet  = 2'd2;

  /// Bits of one update item: op, queue, value (ImpW + 1, two's complement).
  function automatic int unsigned sorter_in_w(int unsigned queue_w, int unsigned imp_w);
    sorter_in_w = 2 + queue_w + imp_w + 1;
  endfunction

  /// Bits of one buffer in the state output: valid, queue, importance.
  function automatic int unsigned sorter_entry_w(int unsigned queue_w, int unsigned imp_w);
    sorter_entry_w = 1 + queue_w + imp_w;
  endfunction

  /// Bits of the state output: four flags, imp_q, the scan pointer, and S then C of every rank.
  function automatic int unsigned sorter_out_w(int unsigned ranks, int unsigned queue_w,
                                               int unsigned imp_w);
    sorter_out_w = 4 + imp_w + queue_w + 2 * ranks * sorter_entry_w(queue_w, imp_w);
  endfunction

  // ---------------------------------------------------------------------------
  // Ray queues (docs/numerics/gicube_ray_queues.md)
  // ---------------------------------------------------------------------------

  /// LenW = bitlen(QueueLen): one queue's count, 0..QueueLen.
  function automatic int unsigned rq_len_w(int unsigned queue_len);
    rq_len_w = $clog2(queue_len + 1);
  endfunction

  /// TotW = bitlen(2^QueueW QueueLen): the rays in all queues.
  function automatic int unsigned rq_tot_w(int unsigned queue_w, int unsigned queue_len);
    rq_tot_w = $clog2((queue_len << queue_w) + 1);
  endfunction

  /// Bits of one input item: pop, pop_q, push, push_q, data.
  function automatic int unsigned rq_in_w(int unsigned queue_w, int unsigned data_w);
    rq_in_w = 2 + 2 * queue_w + data_w;
  endfunction

  /// Bits of one output item: four flags, pop_len, push_len, total, pop_data, ovf_data.
  function automatic int unsigned rq_out_w(int unsigned queue_w, int unsigned queue_len,
                                           int unsigned data_w);
    rq_out_w = 4 + 2 * rq_len_w(queue_len) + rq_tot_w(queue_w, queue_len) + 2 * data_w;
  endfunction

endpackage
