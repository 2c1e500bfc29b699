// gicube_step: step, leap and advance of a GI-Cube ray (patent [355], [357]; parts E and O of
// docs/gicube-rtl.md; contract docs/numerics/gicube_step.md). Per ray: the step
// delta_i = rnd(dir_i dr, 14); with `leap` the count k of grid steps to the first position
// outside the block of `start` (else k = 1); next = start + k delta; the exit test against the
// domain [0, N 256)^3; the queue of next (slab numbering, one processor), or start and the old
// queue on exit.
//
// The leap's count without dividers or the product k delta (contract, "The RTL"): b + 8 quotient
// stages (gicube_step_div) find K = k - 1 on the three axes at once, and k |delta_i| comes out as
// num_i - r_i + |delta_i|. Latency b + 14, one ray per clock, leaping or not.
module gicube_step #(
  /// Block side n = 2^BlockLog2 voxels, 2..8.
  parameter int unsigned BlockLog2 = 5,
  /// Blocks a side B, 1..64; domain side N = B n <= 4096.
  parameter int unsigned VolBlocks = 8,
  /// Sample distance dr, U(4.8) voxels, 16..1024.
  parameter int unsigned Step      = 200
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an item this cycle.
  output logic in_ready_o,
  /// start x, y, z (U(12.8)), dir x, y, z (S(2.14)), queue, leap; LSB first.
  input  logic [3*gicube_pkg::PosW+3*16+gicube_pkg::bucket_queue_w(VolBlocks, 0)+1-1:0] in_data_i,

  /// Output item valid.
  output logic out_valid_o,
  /// Consumer takes the item this cycle.
  input  logic out_ready_i,
  /// k (BlockLog2 + 9), exit, next x, y, z (U(12.8)), queue; LSB first.
  output logic [BlockLog2+9+1+3*gicube_pkg::PosW+gicube_pkg::bucket_queue_w(VolBlocks, 0)-1:0]
    out_data_o
);

  localparam int unsigned PosW     = gicube_pkg::PosW;
  localparam int unsigned PosFracW = gicube_pkg::PosFracW;
  localparam int unsigned PosIntW  = gicube_pkg::PosIntW;
  localparam int unsigned DirW     = 16;                       // S(2.14)
  localparam int unsigned DirFracW = 14;
  localparam int unsigned StepW    = 11;                       // dr <= 1024
  localparam int unsigned ProdW    = DirW + StepW + 1;         // dir * dr, signed
  localparam int unsigned DeltaW   = 13;                       // |delta| <= 2048, signed
  localparam int unsigned MagW     = 12;                       // |delta|
  localparam int unsigned QueueW   = gicube_pkg::bucket_queue_w(VolBlocks, 0);
  localparam int unsigned KBits    = BlockLog2 + 8;            // K = k - 1 < n 256
  localparam int unsigned KW       = BlockLog2 + 9;            // k <= n 256
  localparam int unsigned BlkRawW  = BlockLog2 + PosFracW;     // raw position within a block
  localparam int unsigned RemW     = BlkRawW + 1;              // num_i in [1, n 256]
  localparam int unsigned OffW     = RemW + 1;                 // k |delta_i| < n 256 + 2049
  localparam int unsigned NextW    = PosW + 2;                 // start +- off, signed
  localparam int unsigned BlkW     = PosIntW - BlockLog2;      // a block coordinate
  localparam int unsigned InW      = 3 * PosW + 3 * DirW + QueueW + 1;
  localparam int unsigned OutW     = KW + 1 + 3 * PosW + QueueW;
  localparam int unsigned Stages   = KBits + 6;
  localparam int unsigned DivFirst = 3;                        // ready index of the first quotient stage
  localparam int unsigned Limit    = (VolBlocks << BlockLog2) << PosFracW;  // N 256
  localparam int unsigned SideW    = 3 * PosW + QueueW + 1 + 3;  // start, queue, leap, neg

  if (BlockLog2 < 2 || BlockLog2 > 8) begin : gen_bad_block
    $fatal(1, "gicube_step: BlockLog2 must be 2..8");
  end
  if (VolBlocks < 1 || VolBlocks > 64) begin : gen_bad_vol
    $fatal(1, "gicube_step: VolBlocks must be 1..64");
  end
  if ((VolBlocks << BlockLog2) > (1 << PosIntW)) begin : gen_bad_side
    $fatal(1, "gicube_step: the domain side VolBlocks << BlockLog2 must be <= 4096");
  end
  if (Step < 16 || Step > 1024) begin : gen_bad_step
    $fatal(1, "gicube_step: Step must be 16..1024");
  end

  // x * VolBlocks as a sum of shifted copies of x, one per set bit of the constant (no DSP).
  localparam int unsigned QW2 = QueueW + 7;
  function automatic logic [QW2-1:0] times_b(logic [QW2-1:0] x);
    times_b = '0;
    for (int unsigned b = 0; b < 7; b++) begin
      if (((VolBlocks >> b) & 1) != 0) begin
        times_b = times_b + (x << b);
      end
    end
  endfunction

  // ---------------------------------------------------------------------------
  // Handshake: one enable per stage
  // ---------------------------------------------------------------------------
  logic [Stages-1:0] ready;

  cube5_valid_chain #(
    .Stages (Stages)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     (ready),
    .out_valid_o (out_valid_o)
  );

  assign in_ready_o = ready[0];

  // ---------------------------------------------------------------------------
  // Stage 1: the products dir_i * dr (MULT18)
  // ---------------------------------------------------------------------------
  localparam logic [StepW-1:0] StepC = StepW'(Step);

  logic [3*ProdW-1:0]            prod_d, prod_q;
  logic [3*PosW+QueueW+1-1:0]    side1_d, side1_q;  // start, queue, leap

  for (genvar a = 0; a < 3; a++) begin : gen_mul
    logic signed [DirW-1:0]  dir_s;
    logic signed [StepW:0]   step_s;
    logic signed [ProdW-1:0] prod_s;
    always_comb begin
      dir_s  = $signed(in_data_i[3*PosW + a*DirW +: DirW]);
      step_s = $signed({1'b0, StepC});
      prod_s = dir_s * step_s;
      prod_d[a*ProdW +: ProdW] = prod_s;
    end
  end

  always_comb begin
    side1_d = {in_data_i[InW-1 -: QueueW+1], in_data_i[0 +: 3*PosW]};
  end

  always_ff @(posedge clk_i) begin
    if (ready[0]) begin
      prod_q  <= prod_d;
      side1_q <= side1_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 2: delta_i = (prod + 2^13) >>> 14
  // ---------------------------------------------------------------------------
  logic [3*DeltaW-1:0]           delta_d, delta_q;
  logic [3*PosW+QueueW+1-1:0]    side2_q;
  logic [3*ProdW-1:0]            rounded;

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      rounded[a*ProdW +: ProdW] = prod_q[a*ProdW +: ProdW] + ProdW'(1 << (DirFracW - 1));
      delta_d[a*DeltaW +: DeltaW] = rounded[a*ProdW + DirFracW +: DeltaW];
    end
  end

  always_ff @(posedge clk_i) begin
    if (ready[1]) begin
      delta_q <= delta_d;
      side2_q <= side1_q;
    end
  end

  // The rounded product's top bits repeat the sign (|delta| <= 2048 fits DeltaW); its low bits
  // are the dropped fraction.
  logic unused_rounded;
  always_comb begin
    unused_rounded = 1'b0;
    for (int unsigned a = 0; a < 3; a++) begin
      unused_rounded = unused_rounded ^ (^rounded[a*ProdW +: DirFracW])
                     ^ (^rounded[a*ProdW + DirFracW + DeltaW +: ProdW - DirFracW - DeltaW]);
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 3: |delta|, sign, moving axes and the numerators num_i
  // ---------------------------------------------------------------------------
  logic [3*RemW-1:0] num_d, num_q;
  logic [3*MagW-1:0] mag_d, mag_q;
  logic [2:0]        move_d, move_q;
  logic [2:0]        neg;
  logic [SideW-1:0]  side3_d, side3_q;

  // num_i: n 256 - (p mod n 256) moving up, (p mod n 256) + 1 moving down.
  // `low` is the position's raw offset within its block (p mod n 256).
  function automatic logic [RemW-1:0] numerator(logic [BlkRawW-1:0] low_raw, logic down);
    logic [RemW-1:0] low;
    low = RemW'(low_raw);
    numerator = down ? low + RemW'(1) : RemW'(1 << BlkRawW) - low;
  endfunction

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      neg[a]    = delta_q[a*DeltaW + DeltaW - 1];
      move_d[a] = delta_q[a*DeltaW +: DeltaW] != '0;
      mag_d[a*MagW +: MagW] = neg[a] ? MagW'(-delta_q[a*DeltaW +: DeltaW])
                                     : MagW'(delta_q[a*DeltaW +: DeltaW]);
      num_d[a*RemW +: RemW] = numerator(side2_q[a*PosW +: BlkRawW], neg[a]);
    end
    side3_d = {neg, side2_q};
  end

  always_ff @(posedge clk_i) begin
    if (ready[2]) begin
      num_q   <= num_d;
      mag_q   <= mag_d;
      move_q  <= move_d;
      side3_q <= side3_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Stages 4 .. KBits + 3: the quotient, one bit of K per stage, top bit first
  // ---------------------------------------------------------------------------
  logic [(KBits+1)*3*RemW-1:0] rem_s;
  logic [(KBits+1)*3*MagW-1:0] mag_s;
  logic [(KBits+1)*3-1:0]      move_s;
  logic [(KBits+1)*KBits-1:0]  k_s;
  logic [(KBits+1)*SideW-1:0]  side_s;

  assign rem_s[0 +: 3*RemW]  = num_q;
  assign mag_s[0 +: 3*MagW]  = mag_q;
  assign move_s[0 +: 3]      = move_q;
  assign k_s[0 +: KBits]     = '0;
  assign side_s[0 +: SideW]  = side3_q;

  for (genvar s = 0; s < KBits; s++) begin : gen_div
    gicube_step_div #(
      .RemW  (RemW),
      .MagW  (MagW),
      .KBits (KBits),
      .Bit   (KBits - 1 - s),
      .SideW (SideW)
    ) u_div (
      .clk_i  (clk_i),
      .en_i   (ready[DivFirst + s]),
      .rem_i  (rem_s[s*3*RemW +: 3*RemW]),
      .mag_i  (mag_s[s*3*MagW +: 3*MagW]),
      .move_i (move_s[s*3 +: 3]),
      .k_i    (k_s[s*KBits +: KBits]),
      .side_i (side_s[s*SideW +: SideW]),
      .rem_o  (rem_s[(s+1)*3*RemW +: 3*RemW]),
      .mag_o  (mag_s[(s+1)*3*MagW +: 3*MagW]),
      .move_o (move_s[(s+1)*3 +: 3]),
      .k_o    (k_s[(s+1)*KBits +: KBits]),
      .side_o (side_s[(s+1)*SideW +: SideW])
    );
  end

  logic [3*RemW-1:0]  rem_f;
  logic [3*MagW-1:0]  mag_f;
  logic [2:0]         move_f;
  logic [KBits-1:0]   k_f;
  logic [SideW-1:0]   side_f;
  assign rem_f  = rem_s[KBits*3*RemW +: 3*RemW];
  assign mag_f  = mag_s[KBits*3*MagW +: 3*MagW];
  assign move_f = move_s[KBits*3 +: 3];
  assign k_f    = k_s[KBits*KBits +: KBits];
  assign side_f = side_s[KBits*SideW +: SideW];

  // ---------------------------------------------------------------------------
  // Stage KBits + 4: k and the offsets k |delta_i|
  // ---------------------------------------------------------------------------
  logic                       leap_f;
  logic [2:0]                 neg_f;
  logic [3*OffW-1:0]          off_d, off_q;
  logic [KW-1:0]              kk_d, kk_q, kk_q2;
  logic [3*PosW+QueueW+3-1:0] side4_d, side4_q;  // start, queue, neg

  always_comb begin
    leap_f = side_f[3*PosW + QueueW];
    neg_f  = side_f[SideW-1 -: 3];
    for (int unsigned a = 0; a < 3; a++) begin
      // k |delta_i| = num_i - r_i + |delta_i| on a leap (0 on an axis that does not move).
      off_d[a*OffW +: OffW] = leap_f
          ? OffW'(numerator(side_f[a*PosW +: BlkRawW], neg_f[a])) - OffW'(rem_f[a*RemW +: RemW])
            + OffW'(mag_f[a*MagW +: MagW])
          : OffW'(mag_f[a*MagW +: MagW]);
    end
    kk_d    = (leap_f && (move_f != '0)) ? KW'(k_f) + KW'(1) : KW'(1);
    side4_d = {neg_f, side_f[0 +: 3*PosW+QueueW]};
  end

  always_ff @(posedge clk_i) begin
    if (ready[DivFirst + KBits]) begin
      off_q   <= off_d;
      kk_q    <= kk_d;
      side4_q <= side4_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage KBits + 5: next_i = start_i +- k |delta_i|
  // ---------------------------------------------------------------------------
  logic [3*NextW-1:0]         next_d, next_q;
  logic [3*PosW+QueueW-1:0]   side5_d, side5_q;  // start, queue
  logic [2:0]                 neg5;

  always_comb begin
    neg5 = side4_q[3*PosW+QueueW +: 3];
    for (int unsigned a = 0; a < 3; a++) begin
      next_d[a*NextW +: NextW] = neg5[a]
          ? NextW'(side4_q[a*PosW +: PosW]) - NextW'(off_q[a*OffW +: OffW])
          : NextW'(side4_q[a*PosW +: PosW]) + NextW'(off_q[a*OffW +: OffW]);
    end
    side5_d = side4_q[0 +: 3*PosW+QueueW];
  end

  always_ff @(posedge clk_i) begin
    if (ready[DivFirst + KBits + 1]) begin
      next_q  <= next_d;
      kk_q2   <= kk_q;
      side5_q <= side5_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage KBits + 6: exit test and re-bucketing (slab, one processor)
  // ---------------------------------------------------------------------------
  logic                 exit;
  logic [3*BlkW-1:0]    blk;
  logic [QueueW-1:0]    queue_new;
  logic [OutW-1:0]      out_d, out_q;

  always_comb begin
    exit = 1'b0;
    for (int unsigned a = 0; a < 3; a++) begin
      // Signed: the top bit is the sign; [0, N 256) is below Limit <= 2^20.
      if (next_q[a*NextW + NextW - 1] || (next_q[a*NextW +: NextW] >= NextW'(Limit))) begin
        exit = 1'b1;
      end
      blk[a*BlkW +: BlkW] = next_q[a*NextW + BlkRawW +: BlkW];
    end
    queue_new = QueueW'(times_b(times_b(QW2'(blk[0 +: BlkW])) + QW2'(blk[BlkW +: BlkW]))
                        + QW2'(blk[2*BlkW +: BlkW]));
    out_d[0 +: KW] = kk_q2;
    out_d[KW]      = exit;
    for (int unsigned a = 0; a < 3; a++) begin
      out_d[KW + 1 + a*PosW +: PosW] = exit ? side5_q[a*PosW +: PosW]
                                            : next_q[a*NextW +: PosW];
    end
    out_d[KW + 1 + 3*PosW +: QueueW] = exit ? side5_q[3*PosW +: QueueW] : queue_new;
  end

  always_ff @(posedge clk_i) begin
    if (ready[Stages-1]) begin
      out_q <= out_d;
    end
  end

  assign out_data_o = out_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("gicube_step: output changed while stalled");
`endif

endmodule
