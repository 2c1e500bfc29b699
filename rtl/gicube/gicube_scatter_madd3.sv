// gicube_scatter_madd3: z_c = y_c + rnd(a x_c, S) for the three components c of a vector
// (docs/numerics/gicube_scatter.md, Conventions: rnd rounds half up, also for negative values;
// patent [28], [385]). The shape shared by the reflection R = D + rnd(c N', F - 1), the refraction
// terms rnd(eta D, M) and T = rnd(eta D, M) + rnd(coef N', F). Combinational: the caller registers
// z_o. a, x_c and y_c are two's complement (pass an unsigned value with a zero bit on top).
module gicube_scatter_madd3 #(
  /// Bits of the scalar a.
  parameter int unsigned AW = 8,
  /// Bits of each x_c.
  parameter int unsigned XW = 8,
  /// Bits of each y_c.
  parameter int unsigned YW = 8,
  /// Bits a x_c + 2^(S-1) is formed in (the contract's range for it).
  parameter int unsigned PW = 18,
  /// Rounding shift S (at least 1).
  parameter int unsigned S  = 4,
  /// Bits of each z_c (wrapped: the contract's ranges keep it exact).
  parameter int unsigned OW = 10
) (
  /// Scalar a.
  input  logic [AW-1:0]   a_i,
  /// x, component c at [c*XW +: XW].
  input  logic [3*XW-1:0] x_i,
  /// y, component c at [c*YW +: YW].
  input  logic [3*YW-1:0] y_i,
  /// z, component c at [c*OW +: OW].
  output logic [3*OW-1:0] z_o
);

  if (PW <= AW || PW <= XW || OW <= YW || S < 1 || S + OW > PW) begin : gen_bad_widths
    $fatal(1, "gicube_scatter_madd3: need PW > AW, PW > XW, OW > YW, S >= 1, S + OW <= PW");
  end

  logic [3*PW-1:0] prod;  // a x_c + 2^(S-1), kept whole for the unused-bit tie-off

  always_comb begin
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [PW-1:0] as, xs;
      logic signed [OW-1:0] ys;
      as = {{(PW-AW){a_i[AW-1]}}, a_i};
      xs = {{(PW-XW){x_i[c*XW + XW-1]}}, x_i[c*XW +: XW]};
      ys = {{(OW-YW){y_i[c*YW + YW-1]}}, y_i[c*YW +: YW]};
      prod[c*PW +: PW] = as * xs + PW'(1 << (S - 1));
      z_o[c*OW +: OW]  = ys + prod[c*PW + S +: OW];
    end
  end

  logic unused_madd3;
  assign unused_madd3 = ^prod;

endmodule
