// gicube_scatter_trig: the quarter-wave table TRIG of docs/numerics/gicube_scatter.md,
// TRIG[r] = (cos, sin) of r quarter turns / 2^A, U(1.F) each, with two asynchronous read ports
// (the glossy angle theta and the axis angle phi). Loaded through the configuration port. Patent
// [28] (glossy angle), [385]-[386].
module gicube_scatter_trig #(
  /// Direction fraction bits F.
  parameter int unsigned F = 14,
  /// Index bits A.
  parameter int unsigned A = 8
) (
  /// Clock.
  input  logic clk_i,
  /// Table write.
  input  logic cfg_we_i,
  /// Index written.
  input  logic [A-1:0] cfg_idx_i,
  /// Entry written: cos at [0 +: F+1], sin at [F+1 +: F+1].
  input  logic [2*F+1:0] cfg_entry_i,

  /// Read port 0 index (theta).
  input  logic [A-1:0] idx0_i,
  /// Read port 0 entry, asynchronous.
  output logic [2*F+1:0] entry0_o,
  /// Read port 1 index (phi within its quadrant).
  input  logic [A-1:0] idx1_i,
  /// Read port 1 entry, asynchronous.
  output logic [2*F+1:0] entry1_o
);

  logic [2*F+1:0] table_q [2**A];

  always_ff @(posedge clk_i) begin
    if (cfg_we_i) table_q[cfg_idx_i] <= cfg_entry_i;
  end

  assign entry0_o = table_q[idx0_i];
  assign entry1_o = table_q[idx1_i];

endmodule
