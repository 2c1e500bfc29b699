// cube5_axi_arb: two sources of an AXI4 address channel (AR or AW) onto one (cube5_accel, Window
// = 1; docs/accel.md, *The compositing window in the top*). A source that offered an address
// keeps the channel until it is taken (AXI4: no valid is withdrawn, no address changes while it
// waits); otherwise the sources alternate when both wait. Source 0 can be held back (s0_allow_i
// low: it starts no new offer). The payload is the channel's fields, packed by the user.
module cube5_axi_arb #(
  /// Bits of an address beat (address, length, size, burst type, ID: as the user packs them).
  parameter int unsigned Width = 8
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Source 0; it may start an offer only while s0_allow_i (an offer on the channel stays).
  input  logic             s0_allow_i,
  input  logic             s0_valid_i,
  output logic             s0_ready_o,
  input  logic [Width-1:0] s0_data_i,
  /// Source 1.
  input  logic             s1_valid_i,
  output logic             s1_ready_o,
  input  logic [Width-1:0] s1_data_i,

  /// The channel.
  output logic             valid_o,
  input  logic             ready_i,
  output logic [Width-1:0] data_o,
  /// The source offered on the channel this cycle (1: source 1); what a W-order FIFO records.
  output logic             sel_o
);

  logic sel_q, sel_d;     // the source offered last
  logic hold_q, hold_d;   // the offer was not taken: it stays
  logic sel;
  logic s0_req;           // source 0 offers: allowed, or its offer is waiting
  assign s0_req = s0_valid_i && (s0_allow_i || (hold_q && !sel_q));

  always_comb begin
    if (hold_q) begin
      sel = sel_q;
    end else begin
      sel = s1_valid_i && (!s0_req || !sel_q);
    end
  end

  assign valid_o    = sel ? s1_valid_i : s0_req;
  assign data_o     = sel ? s1_data_i : s0_data_i;
  assign s0_ready_o = !sel && ready_i && s0_req;
  assign s1_ready_o = sel && ready_i;
  assign sel_o      = sel;

  assign hold_d = valid_o && !ready_i;
  assign sel_d  = valid_o ? sel : sel_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      hold_q <= 1'b0;
      sel_q  <= 1'b0;
    end else begin
      hold_q <= hold_d;
      sel_q  <= sel_d;
    end
  end

`ifndef SYNTHESIS
  ArbOfferHeld: assert property (@(posedge clk_i) disable iff (!rst_ni)
      valid_o && !ready_i |=> valid_o && $stable(data_o) && $stable(sel_o))
    else $error("cube5_axi_arb: an offered address was withdrawn or changed");
`endif

endmodule
