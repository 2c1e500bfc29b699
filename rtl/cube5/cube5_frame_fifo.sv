// cube5_frame_fifo: a small synchronous FIFO (RAM of Depth words, read and write pointers) that
// carries side data past a unit of fixed but unit-defined latency: pushed when an item enters the
// unit, popped when the unit's result comes out. The head word is read combinationally.
module cube5_frame_fifo #(
  parameter int unsigned Width = 8,
  /// A power of two, >= 2.
  parameter int unsigned Depth = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Empty the FIFO.
  input  logic clear_i,
  input  logic push_i,
  input  logic [Width-1:0] d_i,
  input  logic pop_i,
  /// The oldest word (valid while not empty).
  output logic [Width-1:0] q_o,
  output logic empty_o,
  output logic full_o
);

  localparam int unsigned PtrW = $clog2(Depth);

  if (Depth < 2 || (1 << PtrW) != Depth) begin : gen_bad_depth
    $fatal(1, "cube5_frame_fifo: Depth must be a power of two >= 2");
  end

  logic [Width-1:0] mem_q [Depth];
  logic [PtrW:0]    wr_q, wr_d, rd_q, rd_d;

  assign empty_o = (wr_q == rd_q);
  assign full_o  = (wr_q[PtrW] != rd_q[PtrW]) && (wr_q[PtrW-1:0] == rd_q[PtrW-1:0]);
  assign q_o     = mem_q[rd_q[PtrW-1:0]];

  always_comb begin
    wr_d = wr_q;
    rd_d = rd_q;
    if (clear_i) begin
      wr_d = '0;
      rd_d = '0;
    end else begin
      if (push_i) wr_d = wr_q + (PtrW+1)'(1);
      if (pop_i)  rd_d = rd_q + (PtrW+1)'(1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      wr_q <= '0;
      rd_q <= '0;
    end else begin
      wr_q <= wr_d;
      rd_q <= rd_d;
    end
  end

  always_ff @(posedge clk_i) begin
    if (push_i) begin
      mem_q[wr_q[PtrW-1:0]] <= d_i;
    end
  end

`ifndef SYNTHESIS
  FifoNoOverflow: assert property (@(posedge clk_i) disable iff (!rst_ni)
      push_i && !clear_i |-> !full_o || pop_i)
    else $error("cube5_frame_fifo: push into a full FIFO");
  FifoNoUnderflow: assert property (@(posedge clk_i) disable iff (!rst_ni)
      pop_i && !clear_i |-> !empty_o)
    else $error("cube5_frame_fifo: pop from an empty FIFO");
`endif

endmodule
