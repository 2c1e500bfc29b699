// gicube_deposit: the splatting unit's energies (part M of docs/gicube-rtl.md, [362], [381]):
// the cache item of a sampling ray's cell, with, for a lighting ray's deposit, the energy of each
// of the cell's eight corners (contract docs/numerics/gicube_processor.md, *Global illumination*
// and *Splatting through the cache*):
//
//   e[c] = min(rnd(E * T * dr * w_c, 42), 2^16 - 1),  T = 4096 - opacity,
//   w_c  = wx * wy * wz, wa = 256 - f_a (corner bit 0) or f_a (corner bit 1),
//
// 0 for a corner outside the volume (a coordinate at or above its dimension) and for every item
// that is not a deposit (a read or a flush passes with its op and cell). rnd(x, s) = (x +
// 2^(s-1)) >> s. Five stages, every multiply one MULT18 (at most 18 x 18 bits unsigned) between
// registers: (1) T, the weights and the corners inside; (2) E T, the x-y weight products and the
// z weights times dr's odd factor m (dr = m 2^sh); (3) the eight weights times m; (4) E T times a
// weight in four 18-bit pieces; (5) their sum, rounded (the 2^sh folded into the shift) and
// clamped. The pipeline stalls as a whole (the processor sends at most one item per processor
// cycle of five clocks).
module gicube_deposit #(
  /// Bits of a cell coordinate (the cache's log2 MaxDim).
  parameter int unsigned MW   = 5,
  /// Sample distance dr, U(4.8) voxels, 16..1024.
  parameter int unsigned Step = 256
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Item valid.
  input  logic in_valid_i,
  /// The item is taken this clock.
  output logic in_ready_o,
  /// x, y, z (MW bits each), E (red, 12), opacity (12), the fractions f_x, f_y, f_z (8 each), op
  /// (2: 0 read, 1 deposit, 2 flush), the volume's dimensions (7 bits each, x lowest: a corner at
  /// or above one gets nothing); LSB first.
  input  logic [3*MW+12+12+24+2+21-1:0] in_data_i,

  /// Cache item valid.
  output logic out_valid_o,
  /// The cache takes the item this clock.
  input  logic out_ready_i,
  /// x, y, z, op, e[0..8] (16 bits each): gicube_cache's input item with Splat = 1.
  output logic [3*MW+2+8*16-1:0] out_data_o
);

  localparam int unsigned CellW     = 3 * MW;
  localparam int unsigned DepW      = 42;              // 12 + 12 + 8 + 24 - 14
  localparam logic [1:0]  OpDeposit = 2'd1;

  // dr = StepOdd 2^StepSh, StepOdd odd (<= 1023 unless dr = 1024, where it is 1): a z weight
  // times StepOdd stays below 2^18, a weight times it below 2^34.
  localparam int unsigned StepSh  = (Step % 1024 == 0) ? 10 : (Step % 512 == 0) ? 9
                                  : (Step % 256 == 0) ? 8 : (Step % 128 == 0) ? 7
                                  : (Step % 64 == 0) ? 6 : (Step % 32 == 0) ? 5
                                  : (Step % 16 == 0) ? 4 : (Step % 8 == 0) ? 3
                                  : (Step % 4 == 0) ? 2 : (Step % 2 == 0) ? 1 : 0;
  localparam int unsigned StepOdd = Step >> StepSh;
  // The sum of stage 5 is E T w StepOdd >> 18 (< 2^40); the energy its bits from RndSh up.
  localparam int unsigned RndSh   = DepW - StepSh - 18;

  if (MW < 2 || MW > 7) begin : gen_bad_mw
    $fatal(1, "gicube_deposit: MW must be 2..7");
  end
  if (Step < 16 || Step > 1024) begin : gen_bad_step
    $fatal(1, "gicube_deposit: Step must be 16..1024");
  end

  logic en;
  assign en         = !out_valid_o || out_ready_i;
  assign in_ready_o = en;

  // The input's fields.
  logic [CellW-1:0] i_cell;
  logic [11:0]      i_e, i_op_a;
  logic [7:0]       i_f [3];
  logic [1:0]       i_op;
  logic [20:0]      i_dims;

  assign i_cell = in_data_i[0 +: CellW];
  assign i_e    = in_data_i[CellW +: 12];
  assign i_op_a = in_data_i[CellW + 12 +: 12];
  for (genvar a = 0; a < 3; a++) begin : gen_f
    assign i_f[a] = in_data_i[CellW + 24 + 8 * a +: 8];
  end
  assign i_op   = in_data_i[CellW + 48 +: 2];
  assign i_dims = in_data_i[CellW + 50 +: 21];

  // The cell and op ride along the five stages; the corners inside (0 unless a deposit) four.
  logic [4:0]       v_q;
  logic [CellW-1:0] cell_q [5];
  logic [1:0]       op_q [5];
  logic [7:0]       in_q [4];

  logic [7:0] in_vol;
  always_comb begin
    for (int c = 0; c < 8; c++) begin
      in_vol[c] = 1'b1;
      for (int a = 0; a < 3; a++) begin
        if ({1'b0, i_cell[a * MW +: MW]} + (MW + 1)'((c >> a) & 1) >=
            (MW + 1)'(i_dims[7 * a +: 7])) begin
          in_vol[c] = 1'b0;
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (en) begin
      cell_q[0] <= i_cell;
      op_q[0]   <= i_op;
      in_q[0]   <= (i_op == OpDeposit) ? in_vol : 8'd0;
      for (int k = 1; k < 5; k++) begin
        cell_q[k] <= cell_q[k-1];
        op_q[k]   <= op_q[k-1];
      end
      for (int k = 1; k < 4; k++) begin
        in_q[k] <= in_q[k-1];
      end
    end
  end

  // Stage 1: E, T, the six weights (256 - f or f).
  logic [11:0] e1_q;
  logic [12:0] t1_q;
  logic [8:0]  wx1_q [2], wy1_q [2], wz1_q [2];

  always_ff @(posedge clk_i) begin
    if (en) begin
      e1_q     <= i_e;
      t1_q     <= 13'd4096 - 13'(i_op_a);
      wx1_q[0] <= 9'd256 - 9'(i_f[0]);
      wx1_q[1] <= 9'(i_f[0]);
      wy1_q[0] <= 9'd256 - 9'(i_f[1]);
      wy1_q[1] <= 9'(i_f[1]);
      wz1_q[0] <= 9'd256 - 9'(i_f[2]);
      wz1_q[1] <= 9'(i_f[2]);
    end
  end

  // Stage 2: E T (< 2^24), the four x-y weights (<= 2^16), the two z weights times StepOdd.
  logic [23:0] et2_q;
  logic [16:0] wxy2_q [4];
  logic [17:0] wzs2_q [2];

  always_ff @(posedge clk_i) begin
    if (en) begin
      et2_q <= 24'(e1_q) * 24'(t1_q);
      for (int c = 0; c < 4; c++) begin
        wxy2_q[c] <= 17'(wx1_q[c & 1]) * 17'(wy1_q[c >> 1]);
      end
      for (int c = 0; c < 2; c++) begin
        wzs2_q[c] <= 18'(wz1_q[c]) * 18'(StepOdd);
      end
    end
  end

  // Stage 3: the eight weights times StepOdd (< 2^34).
  logic [23:0] et3_q;
  logic [33:0] w3_q [8];

  always_ff @(posedge clk_i) begin
    if (en) begin
      et3_q <= et2_q;
      for (int c = 0; c < 8; c++) begin
        w3_q[c] <= 34'(wxy2_q[c & 3]) * 34'(wzs2_q[c >> 2]);
      end
    end
  end

  // Stage 4: E T w StepOdd in four pieces: E T = a1 2^18 + a0, the weight b1 2^18 + b0.
  logic [35:0] p00_q [8];
  logic [33:0] p01_q [8];
  logic [23:0] p10_q [8];
  logic [21:0] p11_q [8];

  always_ff @(posedge clk_i) begin
    if (en) begin
      for (int c = 0; c < 8; c++) begin
        p00_q[c] <= 36'(et3_q[17:0]) * 36'(w3_q[c][17:0]);
        p01_q[c] <= 34'(et3_q[17:0]) * 34'(w3_q[c][33:18]);
        p10_q[c] <= 24'(et3_q[23:18]) * 24'(w3_q[c][17:0]);
        p11_q[c] <= 22'(et3_q[23:18]) * 22'(w3_q[c][33:18]);
      end
    end
  end

  // Stage 5: the sum from bit 18 up (the low 18 bits of p00 carry nothing: the rounding bit,
  // 2^(41 - StepSh), is at bit 31 or above), rounded half up, clamped to the field.
  logic [39:0] sum [8];
  logic [39:0] rounded [8];
  logic [15:0] energy [8];

  always_comb begin
    for (int c = 0; c < 8; c++) begin
      sum[c]     = (40'(p00_q[c][35:18]) + 40'(p01_q[c])) +
                   (40'(p10_q[c]) + {p11_q[c], 18'd0} + (40'(1) << (RndSh - 1)));
      rounded[c] = sum[c] >> RndSh;
      energy[c]  = !in_q[3][c] ? 16'd0 : (rounded[c] > 40'hffff) ? 16'hffff : rounded[c][15:0];
    end
  end

  logic [8*16-1:0] e5_q;

  always_ff @(posedge clk_i) begin
    if (en) begin
      for (int c = 0; c < 8; c++) begin
        e5_q[16 * c +: 16] <= energy[c];
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      v_q <= '0;
    end else if (en) begin
      v_q <= {v_q[3:0], in_valid_i};
    end
  end

  assign out_valid_o = v_q[4];
  assign out_data_o  = {e5_q, op_q[4], cell_q[4]};

  // The low bits of p00 carry nothing into the sum (above).
  logic unused;
  assign unused = ^{p00_q[0][17:0], p00_q[1][17:0], p00_q[2][17:0], p00_q[3][17:0],
                    p00_q[4][17:0], p00_q[5][17:0], p00_q[6][17:0], p00_q[7][17:0]};

endmodule
