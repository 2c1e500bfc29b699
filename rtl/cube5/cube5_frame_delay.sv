// cube5_frame_delay: a delay line of runtime length, kept in a RAM with one read/write pointer
// (the row and slice FIFOs of the frame, patent [47]).
//
// Each enabled cycle reads the word at the pointer into the output register and writes the input
// word in its place (read before write), then advances the pointer modulo len_i. The output
// register therefore holds, after enable number t, the input of enable t - len_i; seen from the
// next enabled cycle the line delays by len_i + 1 enables. Contents are datapath state and start
// undefined (the frame masks every tap that reaches before its first write); clear_i returns the
// pointer to 0 for a new frame.
module cube5_frame_delay #(
  /// Word width.
  parameter int unsigned Width = 8,
  /// Words in the RAM: the largest len_i.
  parameter int unsigned Depth = 4
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Pointer to 0 (takes precedence over en_i).
  input  logic clear_i,
  /// Shift: read the oldest word, write d_i.
  input  logic en_i,
  /// Words in use, 1 ..= Depth; hold it constant between clears.
  input  logic [$clog2(Depth+1)-1:0] len_i,
  /// Word written this enable.
  input  logic [Width-1:0] d_i,
  /// Word read at the last enable (written len_i enables before it).
  output logic [Width-1:0] q_o
);

  localparam int unsigned LenW = $clog2(Depth + 1);
  localparam int unsigned PtrW = (Depth > 1) ? $clog2(Depth) : 1;

  if (Depth < 1) begin : gen_bad_depth
    $fatal(1, "cube5_frame_delay: Depth must be at least 1");
  end

  logic [Width-1:0] mem_q [Depth];
  logic [PtrW-1:0]  ptr_q, ptr_d;
  logic [Width-1:0] q_q;
  logic             wrap;

  assign wrap = (LenW'(ptr_q) + LenW'(1)) >= len_i;

  always_comb begin
    ptr_d = ptr_q;
    if (clear_i) begin
      ptr_d = '0;
    end else if (en_i) begin
      ptr_d = wrap ? '0 : ptr_q + PtrW'(1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      ptr_q <= '0;
    end else begin
      ptr_q <= ptr_d;
    end
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      q_q           <= mem_q[ptr_q];
      mem_q[ptr_q]  <= d_i;
    end
  end

  assign q_o = q_q;

endmodule
