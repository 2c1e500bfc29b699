// cube5_axi_slice: a two-entry register slice for one valid/ready channel (an AXI4 address
// channel in cube5_accel; docs/accel.md, *The compositing window in the top*). Full throughput
// (one item per clock) with valid, data AND ready all from flip-flops: the output register holds
// the item offered downstream, a skid register catches the one item the input may send in the
// cycle the output stalls. So nothing combinational passes between the two sides: out_ready_i
// reaches no input-side signal in the same cycle, in_valid_i no output-side one. The usual
// "skid buffer" of AXI interconnects (a full register slice). Latency 1. Valids reset, data not.
module cube5_axi_slice #(
  /// Item bits (an address channel's fields, as the user packs them).
  parameter int unsigned Width = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input item valid.
  input  logic             in_valid_i,
  /// The slice takes the input item this cycle (if valid): a register (the skid is empty).
  output logic             in_ready_o,
  /// Input item.
  input  logic [Width-1:0] in_data_i,

  /// Output valid (a register).
  output logic             out_valid_o,
  /// The consumer takes the output this cycle.
  input  logic             out_ready_i,
  /// Output item (a register), held while stalled.
  output logic [Width-1:0] out_data_o
);

  logic             out_v_q, out_v_d;     // the output register holds an item
  logic             skid_v_q, skid_v_d;   // the skid register holds an item
  logic [Width-1:0] out_q, out_d, skid_q;
  logic             out_load;              // the output register takes its next item

  assign in_ready_o  = !skid_v_q;
  assign out_valid_o = out_v_q;
  assign out_data_o  = out_q;
  assign out_load    = !out_v_q || out_ready_i;

  always_comb begin
    out_v_d  = out_v_q;
    skid_v_d = skid_v_q;
    out_d    = out_q;
    if (out_load) begin
      // From the skid when it holds an item (the input is not taken then), else the input.
      out_v_d  = skid_v_q || in_valid_i;
      out_d    = skid_v_q ? skid_q : in_data_i;
      skid_v_d = 1'b0;
    end else if (in_valid_i && !skid_v_q) begin
      skid_v_d = 1'b1;
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      out_v_q  <= 1'b0;
      skid_v_q <= 1'b0;
    end else begin
      out_v_q  <= out_v_d;
      skid_v_q <= skid_v_d;
    end
  end

  // Data registers (no reset): the skid follows the input while it is empty.
  always_ff @(posedge clk_i) begin
    out_q <= out_d;
    if (!skid_v_q) skid_q <= in_data_i;
  end

`ifndef SYNTHESIS
  SliceOfferHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_axi_slice: an offered item was withdrawn or changed");
`endif

endmodule
