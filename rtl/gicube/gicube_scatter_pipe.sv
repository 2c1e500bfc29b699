// gicube_scatter_pipe: a delay line of N register stages that all load on one enable. Carries the
// fields of an item beside the arithmetic of the scattering pipeline (datapath: no reset; patent
// [385]-[386], one scattering result per clock).
module gicube_scatter_pipe #(
  /// Bits carried.
  parameter int unsigned W = 1,
  /// Register stages (0 = a wire).
  parameter int unsigned N = 1
) (
  /// Clock.
  input  logic         clk_i,
  /// Pipeline advance: every stage loads.
  input  logic         en_i,
  /// Value entering the first stage.
  input  logic [W-1:0] d_i,
  /// Value leaving the last stage.
  output logic [W-1:0] q_o
);

  if (N == 0) begin : gen_wire
    assign q_o = d_i;
  end else if (N == 1) begin : gen_one
    logic [W-1:0] stage_q;
    always_ff @(posedge clk_i) begin
      if (en_i) stage_q <= d_i;
    end
    assign q_o = stage_q;
  end else begin : gen_many
    // Stage s at [s*W +: W]; stage 0 takes d_i.
    logic [N*W-1:0] stages_d, stages_q;
    assign stages_d = {stages_q[(N-1)*W-1:0], d_i};
    always_ff @(posedge clk_i) begin
      if (en_i) stages_q <= stages_d;
    end
    assign q_o = stages_q[(N-1)*W +: W];
  end

endmodule
