// cube5_pipe_reg: one valid/ready register stage with its data (STYLE.md rule 3): it takes an item
// when it is empty or its item leaves in the same cycle, and holds valid and data while the output
// is stalled. One item per clock, latency 1. The valid resets; the data register does not.
module cube5_pipe_reg #(
  /// Item bits.
  parameter int unsigned Width = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic in_valid_i,
  /// The stage takes the input item this cycle (if valid).
  output logic in_ready_o,
  /// Input item.
  input  logic [Width-1:0] in_data_i,

  /// Output valid.
  output logic out_valid_o,
  /// The consumer takes the output this cycle.
  input  logic out_ready_i,
  /// Output item, held while stalled.
  output logic [Width-1:0] out_data_o
);

  logic             ready;
  logic [Width-1:0] data_q;

  cube5_valid_chain #(
    .Stages (1)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     (ready),
    .out_valid_o (out_valid_o)
  );

  always_ff @(posedge clk_i) begin
    if (ready) begin
      data_q <= in_data_i;
    end
  end

  assign in_ready_o = ready;
  assign out_data_o = data_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3); for the tops whose output this stage is,
  // their own output.
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_pipe_reg: output changed while stalled");
`endif

endmodule
