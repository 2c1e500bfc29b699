// cube5_compos_unorm: a W-bit unit-interval code (all-ones = 1.0) on the scale 2^S, combinational
// (docs/numerics/compos.md, U(r, W, S)).
//
// The code is replicated to 2W bits ({r, r} = r * (2^W + 1)) and its top bit added, which puts the
// all-ones code at exactly 2^(2W); then it is shifted up, or rounded half up down, to S bits.
module cube5_compos_unorm #(
  /// Code width.
  parameter int unsigned W = 8,
  /// Fraction bits of the result.
  parameter int unsigned S = 20
) (
  /// The code, value code / (2^W - 1).
  input  logic [W-1:0] code_i,
  /// The value on the scale 2^S, in [0, 2^S].
  output logic [S:0]   value_o
);

  // {r, r} + msb <= 2^(2W): one carry bit.
  logic [2*W:0] wide;
  assign wide = {1'b0, code_i, code_i} + (2*W+1)'(code_i[W-1]);

  if (S >= 2 * W) begin : gen_shift_up
    assign value_o = (S+1)'(wide) << (S - 2*W);
  end else begin : gen_round_down
    localparam int unsigned Drop = 2 * W - S;
    logic [2*W:0] rounded;
    assign rounded = wide + ((2*W+1)'(1) << (Drop - 1));
    assign value_o = rounded[Drop +: S+1];
    // The discarded fraction bits.
    logic unused_rounded;
    assign unused_rounded = ^rounded[Drop-1:0];
  end

endmodule
