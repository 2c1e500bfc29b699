// cube5_frame_agen: address generation of the sweep (patent [43]; docs/numerics/frame.md,
// "Order of work in the RTL"): beam reads of P voxels along the beam axis i, beams in row order
// (a = 0, P, 2P, ..), rows b = 0 .. nj-1, slices s = s_first .. s_last front to back (the empty
// slices before and after skipped; 0 .. nk-1 for the whole volume), for any of the six base
// planes: the volume axis of i, j, k comes from axis_k (i, j are the other two in ascending order),
// and slice s is k = s, or k = nk-1-s when the view runs toward -k. One command per accepted cycle.
module cube5_frame_agen #(
  parameter int unsigned P          = 4,
  /// log2 of the largest volume edge (coordinate bits).
  parameter int unsigned MaxDimLog2 = 6
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Begin a sweep (the inputs below hold until it ends).
  input  logic start_i,
  /// Beats per row (ni / P), rows (nj) and slices (nk); the sweep's first and last slice.
  input  logic [MaxDimLog2:0] nbr_i,
  input  logic [MaxDimLog2:0] nj_i,
  input  logic [MaxDimLog2:0] nk_i,
  input  logic [MaxDimLog2:0] s_first_i,
  input  logic [MaxDimLog2:0] s_last_i,
  /// Volume axis (0 x, 1 y, 2 z) of the slice axis k; the sweep runs toward -k.
  input  logic [1:0] axis_k_i,
  input  logic k_reversed_i,

  /// A beam read: start (x, y, z) and the beam axis.
  output logic cmd_valid_o,
  input  logic cmd_ready_i,
  output logic [MaxDimLog2-1:0] cmd_x_o,
  output logic [MaxDimLog2-1:0] cmd_y_o,
  output logic [MaxDimLog2-1:0] cmd_z_o,
  output logic [1:0] cmd_axis_o
);

  localparam int unsigned M    = MaxDimLog2;
  localparam int unsigned LogP = $clog2(P);

  logic          active_q, active_d;
  logic [M:0]    m_q, m_d, b_q, b_d, s_q, s_d, k_q, k_d;
  logic          last_beat, last_row, last_slice, fire;

  assign last_beat  = (m_q == nbr_i - (M+1)'(1));
  assign last_row   = (b_q == nj_i - (M+1)'(1));
  assign last_slice = (s_q == s_last_i);
  assign fire       = active_q && cmd_ready_i;

  always_comb begin
    active_d = active_q;
    m_d      = m_q;
    b_d      = b_q;
    s_d      = s_q;
    k_d      = k_q;
    if (start_i) begin
      active_d = 1'b1;
      m_d      = '0;
      b_d      = '0;
      s_d      = s_first_i;
      k_d      = k_reversed_i ? nk_i - (M+1)'(1) - s_first_i : s_first_i;
    end else if (fire) begin
      if (!last_beat) begin
        m_d = m_q + (M+1)'(1);
      end else begin
        m_d = '0;
        if (!last_row) begin
          b_d = b_q + (M+1)'(1);
        end else begin
          b_d = '0;
          s_d = s_q + (M+1)'(1);
          k_d = k_reversed_i ? k_q - (M+1)'(1) : k_q + (M+1)'(1);
          if (last_slice) active_d = 1'b0;
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      active_q <= 1'b0;
      m_q      <= '0;
      b_q      <= '0;
      s_q      <= '0;
      k_q      <= '0;
    end else begin
      active_q <= active_d;
      m_q      <= m_d;
      b_q      <= b_d;
      s_q      <= s_d;
      k_q      <= k_d;
    end
  end

  // Frame axes to volume axes: (i, j) = (y, z), (x, z), (x, y) for k = x, y, z.
  logic [M-1:0] a, bb, kk;
  assign a  = M'(m_q << LogP);
  assign bb = M'(b_q);
  assign kk = M'(k_q);

  always_comb begin
    unique case (axis_k_i)
      2'd0: begin
        cmd_x_o    = kk;
        cmd_y_o    = a;
        cmd_z_o    = bb;
        cmd_axis_o = 2'd1;
      end
      2'd1: begin
        cmd_x_o    = a;
        cmd_y_o    = kk;
        cmd_z_o    = bb;
        cmd_axis_o = 2'd0;
      end
      default: begin
        cmd_x_o    = a;
        cmd_y_o    = bb;
        cmd_z_o    = kk;
        cmd_axis_o = 2'd0;
      end
    endcase
  end

  assign cmd_valid_o = active_q;

  logic unused_hi;
  assign unused_hi = ^{m_q[M], b_q[M], k_q[M]};

endmodule
