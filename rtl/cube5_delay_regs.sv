// cube5_delay_regs: a delay line of Stages register stages that all load on one enable (Stages = 0:
// a wire, en_i unused). Carries an item's fields beside arithmetic that takes that many stages, or
// is the optional register of a `Pipe`-style parameter (Stages = Pipe); the caller keeps its valid
// chain's stage count in step. Datapath: no reset.
module cube5_delay_regs #(
  /// Bits carried.
  parameter int unsigned Width  = 1,
  /// Register stages (0 = a wire).
  parameter int unsigned Stages = 1
) (
  input  logic             clk_i,
  /// Pipeline advance: every stage loads.
  input  logic             en_i,
  /// Value entering the first stage.
  input  logic [Width-1:0] d_i,
  /// Value leaving the last stage.
  output logic [Width-1:0] q_o
);

  if (Stages == 0) begin : gen_wire
    assign q_o = d_i;
    logic unused_wire;
    assign unused_wire = ^{clk_i, en_i};
  end else if (Stages == 1) begin : gen_one
    logic [Width-1:0] stage_q;
    always_ff @(posedge clk_i) begin
      if (en_i) stage_q <= d_i;
    end
    assign q_o = stage_q;
  end else begin : gen_many
    // Stage s at [s*Width +: Width]; stage 0 takes d_i.
    logic [Stages*Width-1:0] stages_d, stages_q;
    assign stages_d = {stages_q[(Stages-1)*Width-1:0], d_i};
    always_ff @(posedge clk_i) begin
      if (en_i) stages_q <= stages_d;
    end
    assign q_o = stages_q[(Stages-1)*Width +: Width];
  end

endmodule
