// cube5_valid_chain: the handshake of a pipeline of Stages register stages (STYLE.md rule 3), the
// control half of a pipeline whose datapath registers live in the unit. Stage i takes a new item
// (ready_o[i], the enable of its datapath registers) when it is empty or its item moves on; stage 0
// takes from the input, stage Stages-1 offers the output. One item per clock, latency Stages.
//
// ready_o[i] = !valid_q[i] || ready_o[i+1] is written out as the OR over the stages downstream, so
// no bit of a vector feeds another (a circular vector, which Verilator evaluates stale in a
// gate-level netlist: docs/architecture.md, RTL conventions). Valids reset, synchronously.
module cube5_valid_chain #(
  /// Register stages, >= 1.
  parameter int unsigned Stages = 2
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// The unit's input valid.
  input  logic in_valid_i,
  /// The consumer takes the output this cycle.
  input  logic out_ready_i,
  /// Stage i takes an item this cycle (ready_o[0] is the unit's in_ready_o).
  output logic [Stages-1:0] ready_o,
  /// The last stage holds an item: the unit's out_valid_o.
  output logic out_valid_o
);

  if (Stages < 1) begin : gen_bad_stages
    $fatal(1, "cube5_valid_chain: Stages must be at least 1");
  end

  logic [Stages-1:0] valid_d, valid_q;

  for (genvar i = 0; i < Stages; i++) begin : gen_stage
    assign ready_o[i] = out_ready_i || !(&valid_q[Stages-1:i]);
    if (i == 0) begin : gen_first
      assign valid_d[i] = ready_o[i] ? in_valid_i : valid_q[i];
    end else begin : gen_next
      assign valid_d[i] = ready_o[i] ? valid_q[i-1] : valid_q[i];
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      valid_q <= '0;
    end else begin
      valid_q <= valid_d;
    end
  end

  assign out_valid_o = valid_q[Stages-1];

endmodule
