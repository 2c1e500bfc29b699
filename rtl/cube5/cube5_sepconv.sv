// cube5_sepconv: one 1-D, 3-tap pass of a symmetric separable filter (patent [204]-[205]): {1 w 1}
// (smoothing; Gaussian approximation) or {-1 0 1} (derivative) on the neighbours a, b, c along the
// pass axis. Three of these in a row (x, y, z), or one in three passes, make the 3x3x3 Sobel or
// Gaussian filter with three multipliers and six adders instead of 27 and 26 ([205]).
//
// docs/numerics/sepconv.md: the symmetric kernel folds into one pre-add (a + c, or c - a) and one
// multiply w * b, so a stage is one multiplier and two adders. The result is exact; OutShift
// rounds it half up once. The centre weight w is a register on the configuration port (address 0),
// not reset; an item uses the w in force in the cycle it is accepted.
//
// Two register stages: pre-add and product in the accepting stage, then the sum and the rounding.
module cube5_sepconv #(
  /// Width of each tap, two's complement.
  parameter int unsigned TapW        = 17,
  /// Fraction bits of the centre weight w, U(4.WeightFracW).
  parameter int unsigned WeightFracW = 4,
  /// Right shift of the exact result, rounded half up (0: exact output).
  parameter int unsigned OutShift    = 0
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Configuration write this cycle.
  input  logic cfg_valid_i,
  /// Configuration address: 0 is w, every other address is ignored.
  input  logic [cube5_gradient_pkg::SepCfgAddrW-1:0] cfg_addr_i,
  /// Configuration data: w, U(4.WeightFracW).
  input  logic [cube5_gradient_pkg::SepWeightIntW+WeightFracW-1:0] cfg_data_i,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// a, b, c (TapW each: offsets -1, 0, +1), kernel (1: 0 = {1 w 1}, 1 = {-1 0 1}); LSB first.
  input  logic [3*TapW:0] in_data_i,

  /// Output valid.
  output logic out_valid_o,
  /// Consumer takes the output this cycle.
  input  logic out_ready_i,
  /// rnd_s(y, OutShift), two's complement.
  output logic [cube5_gradient_pkg::sepconv_exact_w(TapW, WeightFracW)-OutShift-1:0] out_data_o
);

  localparam int unsigned WeightW = cube5_gradient_pkg::SepWeightIntW + WeightFracW;
  localparam int unsigned ExactW  = cube5_gradient_pkg::sepconv_exact_w(TapW, WeightFracW);
  localparam int unsigned OutW    = ExactW - OutShift;
  localparam int unsigned PreW    = TapW + 1;          // a + c or c - a
  localparam int unsigned ProdW   = TapW + WeightW + 1; // w * b, signed

  // Elaboration checks mirror SepconvConfig::validate in the model.
  if (TapW < 4 || TapW > 32) begin : gen_bad_tap_w
    $fatal(1, "cube5_sepconv: TapW must be 4..32");
  end
  if (WeightFracW > 8) begin : gen_bad_weight_frac_w
    $fatal(1, "cube5_sepconv: WeightFracW must be 0..8");
  end
  if (OutShift > WeightFracW + 4) begin : gen_bad_out_shift
    $fatal(1, "cube5_sepconv: OutShift must be 0..WeightFracW+4");
  end

  // ---------------------------------------------------------------------------
  // Centre weight register (configuration port, address 0; not reset: datapath state)
  // ---------------------------------------------------------------------------
  logic [WeightW-1:0] w_d, w_q;

  assign w_d = (cfg_valid_i && cfg_addr_i == cube5_gradient_pkg::SepCfgAddrW0) ? cfg_data_i : w_q;

  always_ff @(posedge clk_i) begin
    w_q <= w_d;
  end

  // ---------------------------------------------------------------------------
  // Stage handshakes
  // ---------------------------------------------------------------------------
  logic ready_1, ready_2;

  cube5_valid_chain #(
    .Stages (2)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     ({ready_2, ready_1}),
    .out_valid_o (out_valid_o)
  );
  assign in_ready_o = ready_1;

  // ---------------------------------------------------------------------------
  // Stage 1: the symmetric fold and the one multiply
  // ---------------------------------------------------------------------------
  logic signed [TapW-1:0]  tap_a, tap_b, tap_c;
  logic                    kernel;
  logic signed [PreW-1:0]  pre_d, pre_q;
  logic signed [ProdW-1:0] prod_d, prod_q;

  always_comb begin
    tap_a  = $signed(in_data_i[0*TapW +: TapW]);
    tap_b  = $signed(in_data_i[1*TapW +: TapW]);
    tap_c  = $signed(in_data_i[2*TapW +: TapW]);
    kernel = in_data_i[3*TapW];
    if (kernel == cube5_gradient_pkg::SepKernelDiff) begin
      pre_d  = PreW'(tap_c) - PreW'(tap_a);
      prod_d = '0;
    end else begin
      pre_d  = PreW'(tap_a) + PreW'(tap_c);
      prod_d = ProdW'($signed({1'b0, w_q}) * tap_b);
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 2: y = pre * 2^WeightFracW + prod, then rnd_s(y, OutShift)
  // ---------------------------------------------------------------------------
  logic signed [ExactW-1:0] exact, rounded, shifted;
  logic        [OutW-1:0]   out_d, out_q;

  assign exact = (ExactW'(pre_q) <<< WeightFracW) + ExactW'(prod_q);
  if (OutShift == 0) begin : gen_exact
    assign rounded = exact;
  end else begin : gen_round_half_up
    // |y| < 9 * 2^(TapW+WeightFracW) leaves room for the half below 2^(ExactW-1).
    assign rounded = exact + $signed(ExactW'(1) << (OutShift - 1));
  end
  assign shifted = rounded >>> OutShift;
  assign out_d   = shifted[OutW-1:0];

  if (OutShift > 0) begin : gen_unused_shifted
    logic unused_shifted;
    assign unused_shifted = ^shifted[ExactW-1:OutW];
  end

  // ---------------------------------------------------------------------------
  // Datapath registers (not reset; the valids are u_valid's)
  // ---------------------------------------------------------------------------
  always_ff @(posedge clk_i) begin
    if (ready_1) begin
      pre_q  <= pre_d;
      prod_q <= prod_d;
    end
    if (ready_2) begin
      out_q <= out_d;
    end
  end

  assign out_data_o  = out_q;

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_sepconv: output changed while stalled");
`endif

endmodule
