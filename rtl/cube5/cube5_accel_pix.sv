// cube5_accel_pix: one coxel's colour as a 32-bit pixel (cube5_accel: the read-out and the
// window's final pixels). Each channel c (U(1.AccW), AccW + 1 bits) becomes the code
// min(2^ColorW - 1, (c (2^ColorW - 1) + 2^(AccW - 1)) >> AccW) (docs/numerics/warp.md, "Base-plane
// codes", applied to all four channels); R, G, B, A at byte lanes 0 to 3. Combinational.
module cube5_accel_pix #(
  parameter int unsigned AccW   = 20,
  /// Code bits per channel, at most 8.
  parameter int unsigned ColorW = 8
) (
  /// {A, B, G, R}, AccW + 1 bits each, R lowest.
  input  logic [4*(AccW+1)-1:0] cox_i,
  /// {A, B, G, R} codes, a byte each, R in the lowest byte.
  output logic [31:0]           pix_o
);

  localparam int unsigned ChanW = AccW + 1;
  localparam int unsigned SumW  = ChanW + ColorW + 1;
  localparam int unsigned CodeW = ChanW + ColorW - AccW + 1;

  if (ColorW > 8 || AccW < 1) begin : gen_bad_width
    $fatal(1, "cube5_accel_pix: ColorW must be at most 8 and AccW at least 1");
  end

  logic [4*AccW-1:0] unused_low;

  for (genvar c = 0; c < 4; c++) begin : gen_code
    logic [SumW-1:0]  scaled;
    logic [CodeW-1:0] code;
    assign scaled = (SumW'(cox_i[c*ChanW +: ChanW]) << ColorW) - SumW'(cox_i[c*ChanW +: ChanW])
                    + (SumW'(1) << (AccW - 1));
    assign code   = CodeW'(scaled[SumW-1:AccW]);
    assign pix_o[8*c +: 8] = 8'(code > CodeW'((1 << ColorW) - 1) ? CodeW'((1 << ColorW) - 1) : code);
    assign unused_low[c*AccW +: AccW] = scaled[AccW-1:0];
  end

  logic unused;
  assign unused = ^unused_low;

endmodule
