// gicube_bucket: queue bucketing of ray start positions (patent [348], [370], [371];
// docs/numerics/gicube_bucket.md). For each of Lanes positions per item: the owning processor and
// the queue number of the volume block that holds the position, for the slab, repeating-slab or
// skewed-block distribution of [348]. Shifts, masks, one addition, small constant multiplies.
//
// One register stage: latency 1, one item per cycle when never stalled.
module gicube_bucket #(
  /// Block side n = 2^BlockLog2 voxels, 1..8.
  parameter int unsigned BlockLog2 = 5,
  /// Blocks per axis B, 1..64; volume side N = B * n <= 4096.
  parameter int unsigned VolBlocks = 8,
  /// Processors p = 2^ProcLog2, 0..4; B must be a multiple of p.
  parameter int unsigned ProcLog2  = 2,
  /// Distribution (gicube_pkg::Dist*): 0 slab, 1 repeating slab, 2 skewed block.
  parameter int unsigned Dist      = 0,
  /// Positions per item, 1..4.
  parameter int unsigned Lanes     = 2
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// Lanes positions, lane 0 first; each x, y, z in U(12.8) (the packet's start point).
  input  logic [Lanes*3*gicube_pkg::PosW-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// Lanes results, lane 0 first; each queue, proc, outside (LSB first).
  output logic [Lanes*gicube_pkg::bucket_lane_w(VolBlocks, ProcLog2)-1:0] out_data_o
);

  localparam int unsigned PosW     = gicube_pkg::PosW;
  localparam int unsigned PosFracW = gicube_pkg::PosFracW;
  localparam int unsigned PosIntW  = gicube_pkg::PosIntW;
  localparam int unsigned QueueW   = gicube_pkg::bucket_queue_w(VolBlocks, ProcLog2);
  localparam int unsigned ProcW    = gicube_pkg::bucket_proc_w(ProcLog2);
  localparam int unsigned LaneW    = gicube_pkg::bucket_lane_w(VolBlocks, ProcLog2);
  localparam int unsigned Procs    = 1 << ProcLog2;
  localparam int unsigned VolSide  = VolBlocks << BlockLog2;
  localparam int unsigned Slab     = VolBlocks / Procs;  // blocks per slab (slab scheme)
  localparam int unsigned BlkW     = 7;                  // a block coordinate, 0..127
  localparam int unsigned DistSlabP      = gicube_pkg::DistSlab;
  localparam int unsigned DistRepeatingP = gicube_pkg::DistRepeatingSlab;

  // Elaboration checks mirror BucketConfig::validate in the model.
  if (BlockLog2 < 1 || BlockLog2 > 8) begin : gen_bad_block
    $fatal(1, "gicube_bucket: BlockLog2 must be 1..8");
  end
  if (VolBlocks < 1 || VolBlocks > 64) begin : gen_bad_vol
    $fatal(1, "gicube_bucket: VolBlocks must be 1..64");
  end
  if (VolSide > (1 << PosIntW)) begin : gen_bad_side
    $fatal(1, "gicube_bucket: the volume side VolBlocks << BlockLog2 must be <= 4096");
  end
  if (ProcLog2 > 4) begin : gen_bad_proc
    $fatal(1, "gicube_bucket: ProcLog2 must be 0..4");
  end
  if (VolBlocks % Procs != 0) begin : gen_bad_share
    $fatal(1, "gicube_bucket: VolBlocks must be a multiple of 2^ProcLog2");
  end
  if (Dist > 2) begin : gen_bad_dist
    $fatal(1, "gicube_bucket: Dist must be 0 (slab), 1 (repeating slab) or 2 (skewed)");
  end
  if (Lanes < 1 || Lanes > 4) begin : gen_bad_lanes
    $fatal(1, "gicube_bucket: Lanes must be 1..4");
  end

  // x * VolBlocks as a sum of shifted copies of x, one per set bit of the constant.
  localparam int unsigned QW2 = QueueW + 7;  // room for (xl * B + by) * B before truncation
  function automatic logic [QW2-1:0] times_b(logic [QW2-1:0] x);
    times_b = '0;
    for (int unsigned b = 0; b < 7; b++) begin
      if (((VolBlocks >> b) & 1) != 0) begin
        times_b = times_b + (x << b);
      end
    end
  endfunction

  // ---------------------------------------------------------------------------
  // Per lane: voxel -> block -> (processor, slab index) -> queue
  // ---------------------------------------------------------------------------
  logic [Lanes*LaneW-1:0] result;

  for (genvar l = 0; l < Lanes; l++) begin : gen_lane
    logic [PosIntW:0]   ix, iy, iz;     // integer voxel coordinate, one spare bit for the compare
    logic               outside;
    logic [BlkW-1:0]    bx, by, bz;
    logic [BlkW+1:0]    diag;           // bx + by + bz (skewed scheme)
    logic [ProcW-1:0]   proc;
    logic [BlkW-1:0]    xl;
    logic [BlkW-1:0]    base;           // first block of the slab (slab scheme)
    logic [QueueW-1:0]  queue;

    always_comb begin
      ix = {1'b0, in_data_i[(3*l+0)*PosW + PosFracW +: PosIntW]};
      iy = {1'b0, in_data_i[(3*l+1)*PosW + PosFracW +: PosIntW]};
      iz = {1'b0, in_data_i[(3*l+2)*PosW + PosFracW +: PosIntW]};
      outside = (ix >= (PosIntW+1)'(VolSide)) || (iy >= (PosIntW+1)'(VolSide))
             || (iz >= (PosIntW+1)'(VolSide));

      bx   = BlkW'(ix >> BlockLog2);
      by   = BlkW'(iy >> BlockLog2);
      bz   = BlkW'(iz >> BlockLog2);
      diag = (BlkW+2)'(bx) + (BlkW+2)'(by) + (BlkW+2)'(bz);

      // Processor and slab index. Slab: the processor is the number of slab boundaries at or
      // below bx (a thermometer count, no divider); the others keep the low ProcLog2 bits.
      proc = '0;
      xl   = '0;
      base = '0;
      if (Dist == DistSlabP) begin
        base = '0;
        for (int unsigned k = 1; k < Procs; k++) begin
          if (bx >= BlkW'(k * Slab)) begin
            proc = ProcW'(k);
            base = BlkW'(k * Slab);
          end
        end
        xl = bx - base;
      end else if (Dist == DistRepeatingP) begin
        proc = ProcW'(bx & BlkW'(Procs - 1));
        xl   = bx >> ProcLog2;
      end else begin
        proc = ProcW'(diag & (BlkW+2)'(Procs - 1));
        xl   = bx >> ProcLog2;
      end

      // queue = (xl * B + by) * B + bz, the constant multiplies as shift-and-add (no DSP).
      queue = QueueW'(times_b(times_b(QW2'(xl)) + QW2'(by)) + QW2'(bz));

      if (outside) begin
        proc  = '0;
        queue = '0;
      end
      result[l*LaneW +: LaneW] = {outside, proc, queue};
    end
  end

  // The fraction bits of every position are ignored on purpose (floor, contract step 1).
  logic unused_frac;
  always_comb begin
    unused_frac = 1'b0;
    for (int unsigned k = 0; k < 3 * Lanes; k++) begin
      unused_frac = unused_frac ^ (^in_data_i[k*PosW +: PosFracW]);
    end
  end

  // ---------------------------------------------------------------------------
  // Output register
  // ---------------------------------------------------------------------------
  cube5_pipe_reg #(
    .Width (Lanes * LaneW)
  ) u_out (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .in_ready_o  (in_ready_o),
    .in_data_i   (result),
    .out_valid_o (out_valid_o),
    .out_ready_i (out_ready_i),
    .out_data_o  (out_data_o)
  );

  // A stalled output holds its item: asserted in cube5_pipe_reg.

endmodule
