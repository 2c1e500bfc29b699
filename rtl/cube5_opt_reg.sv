// cube5_opt_reg: an optional pipeline register for a unit's `Pipe`-style parameter: On = 1, a
// data register loaded when en_i is high (the stage's enable); On = 0, a wire (en_i unused). The
// caller keeps its valid chain's stage count in step with On. No reset: data only.
module cube5_opt_reg #(
  /// Data bits.
  parameter int unsigned Width = 8,
  /// 1: a register; 0: a wire.
  parameter int unsigned On    = 1
) (
  input  logic             clk_i,
  /// Load enable (On = 1).
  input  logic             en_i,
  input  logic [Width-1:0] d_i,
  output logic [Width-1:0] q_o
);

  if (On != 0) begin : gen_reg
    logic [Width-1:0] q;
    always_ff @(posedge clk_i) begin
      if (en_i) q <= d_i;
    end
    assign q_o = q;
  end else begin : gen_wire
    assign q_o = d_i;
    logic unused_wire;
    assign unused_wire = ^{clk_i, en_i};
  end

endmodule
