// cube5_frame_fifo: a small synchronous FIFO (RAM of Depth words, read and write pointers) that
// carries side data past a unit of fixed but unit-defined latency: pushed when an item enters the
// unit, popped when the unit's result comes out. The head word is read combinationally, or
// (OutReg = 1) held in a register: the same words in the same cycles, the head from a flip-flop.
module cube5_frame_fifo #(
  parameter int unsigned Width = 8,
  /// A power of two, >= 2.
  parameter int unsigned Depth = 8,
  /// 1: the head word in a register, loaded from the RAM at the next read address (itself a
  /// register) or from the pushed word, so no RAM read or pointer logic lies after q_o (for
  /// clock rate, docs/accel.md, *Synthesis*). Width more flip-flops.
  parameter int unsigned OutReg = 0
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

  if (OutReg != 0) begin : gen_head_q
    // rd1_q = rd_q + 1: the word after the head, read with a registered address. The head after
    // a pop is that word, or the pushed one when it is written this cycle (it was the last);
    // into an empty FIFO the pushed word.
    logic [Width-1:0] head_q;
    logic [PtrW:0]    rd1_q;
    always_ff @(posedge clk_i) begin
      if (!rst_ni) begin
        rd1_q <= (PtrW+1)'(1);
      end else begin
        rd1_q <= rd_d + (PtrW+1)'(1);
      end
    end
    always_ff @(posedge clk_i) begin
      if (pop_i) begin
        head_q <= (push_i && wr_q == rd1_q) ? d_i : mem_q[rd1_q[PtrW-1:0]];
      end else if (push_i && wr_q == rd_q) begin
        head_q <= d_i;
      end
    end
    assign q_o = head_q;
`ifndef SYNTHESIS
    // (The RAM's head word through a wire: Verilator 5 cannot read an array inside a property.)
    logic [Width-1:0] ram_head;
    assign ram_head = mem_q[rd_q[PtrW-1:0]];
    FifoHeadAsRam: assert property (@(posedge clk_i) disable iff (!rst_ni)
        !empty_o |-> head_q == ram_head)
      else $error("cube5_frame_fifo: the head register is not the RAM's head word");
`endif
  end else begin : gen_head_w
    assign q_o = mem_q[rd_q[PtrW-1:0]];
  end

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
