// gicube_packet_loop: a test fixture for the GI-Cube ray packet (patent [349];
// docs/numerics/gicube_packet.md). It unpacks each 256-bit packet into gicube_pkg::ray_packet_t and
// outputs it packed again (`repack`) beside a copy in which field k of the contract table (counted
// from 0) is incremented by k + 1 modulo its own width (`probe`). Against the Rust model
// (RayPacket::from_bits -> probed -> to_bits) the probe shows any field that the SV struct places
// at other bits, or with another width, than the contract table (its carry spills into a neighbour
// or wraps short), and any two fields of equal width that are swapped (different increments).
//
// Stages = 1: one output register. Stages = 2: an input register in front of it. Each stage takes
// a new item when it is empty or its item moves on: one item per cycle, latency Stages.
module gicube_packet_loop #(
  /// Register stages between input and output, 1..2.
  parameter int unsigned Stages = 1
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Input packet valid.
  input  logic in_valid_i,
  /// Unit can take a packet this cycle.
  output logic in_ready_o,
  /// One ray packet, fields LSB first as docs/numerics/gicube_packet.md.
  input  logic [gicube_pkg::PacketW-1:0] in_data_i,

  /// Output valid.
  output logic out_valid_o,
  /// Consumer takes the output this cycle.
  input  logic out_ready_i,
  /// repack (bits 0..255), then probe (bits 256..511).
  output logic [2*gicube_pkg::PacketW-1:0] out_data_o
);

  localparam int unsigned PacketW = gicube_pkg::PacketW;

  if (Stages < 1 || Stages > 2) begin : gen_bad_stages
    $fatal(1, "gicube_packet_loop: Stages must be 1..2");
  end

  // ---------------------------------------------------------------------------
  // Optional input register
  // ---------------------------------------------------------------------------
  logic               src_valid, src_ready;
  logic [PacketW-1:0] src_data;

  if (Stages == 2) begin : gen_in_reg
    cube5_pipe_reg #(
      .Width (PacketW)
    ) u_in (
      .clk_i       (clk_i),
      .rst_ni      (rst_ni),
      .in_valid_i  (in_valid_i),
      .in_ready_o  (in_ready_o),
      .in_data_i   (in_data_i),
      .out_valid_o (src_valid),
      .out_ready_i (src_ready),
      .out_data_o  (src_data)
    );
  end else begin : gen_no_in_reg
    assign in_ready_o = src_ready;
    assign src_valid  = in_valid_i;
    assign src_data   = in_data_i;
  end

  // ---------------------------------------------------------------------------
  // Unpack, add k + 1 to field k on its own, pack
  // ---------------------------------------------------------------------------
  gicube_pkg::ray_packet_t pkt, probe;

  always_comb begin
    pkt                = src_data;
    probe.u            = pkt.u            + 12'd1;
    probe.v            = pkt.v            + 12'd2;
    probe.start_x      = pkt.start_x      + 20'd3;
    probe.start_y      = pkt.start_y      + 20'd4;
    probe.start_z      = pkt.start_z      + 20'd5;
    probe.dir_x        = pkt.dir_x        + 16'sd6;
    probe.dir_y        = pkt.dir_y        + 16'sd7;
    probe.dir_z        = pkt.dir_z        + 16'sd8;
    probe.red          = pkt.red          + 12'd9;
    probe.green        = pkt.green        + 12'd10;
    probe.blue         = pkt.blue         + 12'd11;
    probe.opacity      = pkt.opacity      + 12'd12;
    probe.contribution = pkt.contribution + 12'd13;
    probe.interaction  = pkt.interaction  + 16'd14;
    probe.lifetime     = pkt.lifetime     + 8'd15;
    probe.generation   = pkt.generation   + 8'd16;
    probe.rtype        = pkt.rtype        + 2'd1;
    probe.flags        = pkt.flags        + 6'd18;
    probe.reserved     = pkt.reserved     + 24'd19;
  end

  // ---------------------------------------------------------------------------
  // Output register
  // ---------------------------------------------------------------------------
  cube5_pipe_reg #(
    .Width (2 * PacketW)
  ) u_out (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (src_valid),
    .in_ready_o  (src_ready),
    .in_data_i   ({probe, pkt}),
    .out_valid_o (out_valid_o),
    .out_ready_i (out_ready_i),
    .out_data_o  (out_data_o)
  );

  // A stalled output holds its item: asserted in cube5_pipe_reg.

endmodule
