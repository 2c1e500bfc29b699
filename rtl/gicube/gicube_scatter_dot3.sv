// gicube_scatter_dot3: the exact dot product z = sum_c x_c y_c of two three-component vectors of
// two's complement integers (docs/numerics/gicube_scatter.md: |D|^2, D . N, and the sum of squares
// of normalize(V); patent [385]-[386]). Combinational: the caller registers z_o.
module gicube_scatter_dot3 #(
  /// Bits of each component of x and y.
  parameter int unsigned VW = 8,
  /// Bits of z (wrapped; the callers size it so that the sum is exact).
  parameter int unsigned OW = 18
) (
  /// x, component c at [c*VW +: VW].
  input  logic [3*VW-1:0] x_i,
  /// y, component c at [c*VW +: VW].
  input  logic [3*VW-1:0] y_i,
  /// sum_c x_c y_c.
  output logic [OW-1:0]   z_o
);

  if (OW <= VW) begin : gen_bad_ow
    $fatal(1, "gicube_scatter_dot3: OW must exceed VW");
  end

  always_comb begin
    z_o = '0;
    for (int unsigned c = 0; c < 3; c++) begin
      logic signed [OW-1:0] xc, yc;
      xc  = {{(OW-VW){x_i[c*VW + VW-1]}}, x_i[c*VW +: VW]};
      yc  = {{(OW-VW){y_i[c*VW + VW-1]}}, y_i[c*VW +: VW]};
      z_o = z_o + OW'(xc * yc);
    end
  end

endmodule
