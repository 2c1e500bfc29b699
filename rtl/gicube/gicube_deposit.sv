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
// 2^(s-1)) >> s. Three stages: E T and the weights' pair products; E T dr and the eight weights;
// the eight products, rounded and clamped. The pipeline stalls as a whole (the processor sends at
// most one item per processor cycle of five clocks).
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

  localparam int unsigned CellW  = 3 * MW;
  localparam int unsigned DepW   = 42;                 // 12 + 12 + 8 + 24 - 14
  localparam logic [1:0]  OpDeposit = 2'd1;

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

  // Stage 1: E T, the four x-y weight products, the z weights, the corners inside the volume.
  logic             v1_q;
  logic [CellW-1:0] cell1_q;
  logic [1:0]       op1_q;
  logic [24:0]      et1_q;
  logic [17:0]      wxy1_q [4];
  logic [8:0]       wz1_q [2];
  logic [7:0]       in1_q;

  logic [8:0]  w_x [2], w_y [2];
  logic [12:0] t_left;
  logic [7:0]  in_vol;

  always_comb begin
    t_left = 13'd4096 - 13'(i_op_a);
    w_x[0] = 9'd256 - 9'(i_f[0]);
    w_x[1] = 9'(i_f[0]);
    w_y[0] = 9'd256 - 9'(i_f[1]);
    w_y[1] = 9'(i_f[1]);
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
      cell1_q   <= i_cell;
      op1_q     <= i_op;
      et1_q     <= 25'(i_e) * 25'(t_left);
      for (int c = 0; c < 4; c++) begin
        wxy1_q[c] <= 18'(w_x[c & 1]) * 18'(w_y[c >> 1]);
      end
      wz1_q[0]  <= 9'd256 - 9'(i_f[2]);
      wz1_q[1]  <= 9'(i_f[2]);
      in1_q     <= (i_op == OpDeposit) ? in_vol : 8'd0;
    end
  end

  // Stage 2: E T dr, the eight weights.
  logic             v2_q;
  logic [CellW-1:0] cell2_q;
  logic [1:0]       op2_q;
  logic [35:0]      ets2_q;
  logic [24:0]      w2_q [8];
  logic [7:0]       in2_q;

  always_ff @(posedge clk_i) begin
    if (en) begin
      cell2_q <= cell1_q;
      op2_q   <= op1_q;
      ets2_q  <= 36'(et1_q) * 36'(Step);
      for (int c = 0; c < 8; c++) begin
        w2_q[c] <= 25'(wxy1_q[c & 3]) * 25'(wz1_q[c >> 2]);
      end
      in2_q   <= in1_q;
    end
  end

  // Stage 3: the products, rounded half up at 42 bits, clamped to the field.
  logic [60:0] prod [8];
  logic [18:0] rounded [8];
  logic [15:0] energy [8];

  always_comb begin
    for (int c = 0; c < 8; c++) begin
      prod[c]    = 61'(ets2_q) * 61'(w2_q[c]) + (61'(1) << (DepW - 1));
      rounded[c] = prod[c][DepW +: 19];
      energy[c]  = !in2_q[c] ? 16'd0 : (rounded[c] > 19'hffff) ? 16'hffff : rounded[c][15:0];
    end
  end

  logic [8*16-1:0] e3_q;
  logic [CellW-1:0] cell3_q;
  logic [1:0]       op3_q;

  always_ff @(posedge clk_i) begin
    if (en) begin
      cell3_q <= cell2_q;
      op3_q   <= op2_q;
      for (int c = 0; c < 8; c++) begin
        e3_q[16 * c +: 16] <= energy[c];
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      v1_q        <= 1'b0;
      v2_q        <= 1'b0;
      out_valid_o <= 1'b0;
    end else if (en) begin
      v1_q        <= in_valid_i;
      v2_q        <= v1_q;
      out_valid_o <= v2_q;
    end
  end

  assign out_data_o = {e3_q, op3_q, cell3_q};

  // The top bits of a product are below 2^61 by the ranges (E T dr < 2^36, w < 2^25).
  logic unused;
  assign unused = ^{prod[0][DepW-1:0], prod[1][DepW-1:0], prod[2][DepW-1:0], prod[3][DepW-1:0],
                    prod[4][DepW-1:0], prod[5][DepW-1:0], prod[6][DepW-1:0], prod[7][DepW-1:0]};

endmodule
