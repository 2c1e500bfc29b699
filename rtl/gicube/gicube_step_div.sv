// gicube_step_div: one quotient stage of gicube_step's leap count (patent [357];
// docs/numerics/gicube_step.md, "The RTL"). Decides bit Bit of K = k - 1, the largest K with
// K a_i < num_i on every moving axis: with the remainders r_i = num_i - K a_i of the bits above,
// the candidate K | 2^Bit is kept when every moving axis has r_i > a_i 2^Bit, and then every
// moving axis subtracts a_i 2^Bit. Three compares and subtracts, no divider.
//
// One register stage; its enable is the pipeline's (cube5_valid_chain), the side band rides along.
module gicube_step_div #(
  /// Remainder bits (b + 9: num_i <= n 256).
  parameter int unsigned RemW  = 17,
  /// |delta_i| bits.
  parameter int unsigned MagW  = 12,
  /// Bits of K (b + 8).
  parameter int unsigned KBits = 16,
  /// The bit of K this stage decides, KBits-1 .. 0.
  parameter int unsigned Bit   = 0,
  /// Side-band bits carried unchanged.
  parameter int unsigned SideW = 1
) (
  input  logic clk_i,

  /// The stage takes an item this cycle.
  input  logic en_i,
  /// Remainders r_x, r_y, r_z (RemW each, x lowest).
  input  logic [3*RemW-1:0]  rem_i,
  /// |delta_i| (MagW each).
  input  logic [3*MagW-1:0]  mag_i,
  /// delta_i != 0 per axis.
  input  logic [2:0]         move_i,
  /// K so far (bits above Bit decided, the rest 0).
  input  logic [KBits-1:0]   k_i,
  /// Carried unchanged.
  input  logic [SideW-1:0]   side_i,

  output logic [3*RemW-1:0]  rem_o,
  output logic [3*MagW-1:0]  mag_o,
  output logic [2:0]         move_o,
  output logic [KBits-1:0]   k_o,
  output logic [SideW-1:0]   side_o
);

  if (Bit >= KBits) begin : gen_bad_bit
    $fatal(1, "gicube_step_div: Bit must be below KBits");
  end

  // Wide enough for a_i 2^Bit and r_i, plus the borrow.
  localparam int unsigned CmpW = ((RemW > MagW + Bit) ? RemW : MagW + Bit) + 1;

  logic [3*RemW-1:0] rem_d, rem_q;
  logic [3*MagW-1:0] mag_d, mag_q;
  logic [2:0]        move_d, move_q;
  logic [KBits-1:0]  k_d, k_q;
  logic [SideW-1:0]  side_d, side_q;

  logic [2:0]        fits;
  logic [3*CmpW-1:0] cand;
  logic              keep;

  always_comb begin
    for (int unsigned a = 0; a < 3; a++) begin
      cand[a*CmpW +: CmpW] = CmpW'(mag_i[a*MagW +: MagW]) << Bit;
      fits[a] = !move_i[a] || (CmpW'(rem_i[a*RemW +: RemW]) > cand[a*CmpW +: CmpW]);
    end
    keep   = &fits;
    mag_d  = mag_i;
    move_d = move_i;
    side_d = side_i;
    rem_d  = rem_i;
    k_d   = k_i;
    if (keep) begin
      k_d[Bit] = 1'b1;
      for (int unsigned a = 0; a < 3; a++) begin
        if (move_i[a]) begin
          rem_d[a*RemW +: RemW] = rem_i[a*RemW +: RemW] - RemW'(cand[a*CmpW +: CmpW]);
        end
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (en_i) begin
      rem_q  <= rem_d;
      mag_q  <= mag_d;
      move_q <= move_d;
      k_q    <= k_d;
      side_q <= side_d;
    end
  end

  assign rem_o  = rem_q;
  assign mag_o  = mag_q;
  assign move_o = move_q;
  assign k_o    = k_q;
  assign side_o = side_q;

endmodule
