// cube5_warp: the 2-D affine warp of the base-plane image onto the final image for parallel views
// (patent [61], [66]-[110]; contract docs/numerics/warp.md).
//
// The base plane comes in on the input stream (register writes, texels in raster order, `Go`)
// and is kept in four block-RAM banks by texel parity, so the four bilinear taps of any position
// are read in one clock. A `Go` emits the OutW x OutH image in raster order, one pixel per clock:
// exact coordinate steps (integer adds), the taps read, widened to U(0.16), three rounded lerps per
// channel, 8-bit RGB out with tlast at each row end and tuser at the frame start.
//
//   issue (step adders) -> cube5_warp_sample (four parity banks, bilinear, 8-bit RGB; six stages,
//   the banks' output registers first) -> out
//
// Back-pressure stalls the whole pipeline through one enable (`adv`), the banks' read enables
// included, so a stalled output holds and nothing is dropped.
module cube5_warp #(
  /// Bits of a base-plane colour code (the frame's ColorW).
  parameter int unsigned ColorW  = 8,
  /// Fraction bits of a bilinear weight.
  parameter int unsigned WeightW = 8,
  /// Largest base-plane edge held in block RAM (a power of two).
  parameter int unsigned MaxBase = 128,
  /// Largest output edge (a power of two).
  parameter int unsigned MaxOut  = 512
) (
  input  logic clk_i,
  /// Synchronous, active low: registers and texel position to 0, emission stopped.
  input  logic rst_ni,

  /// Items: payload, addr, op (LSB first; docs/numerics/warp.md, "Input item").
  input  logic                                                        in_valid_i,
  output logic                                                        in_ready_o,
  input  logic [cube5_warp_pkg::pay_w(ColorW)+cube5_warp_pkg::RegAddrW+1:0] in_data_i,

  /// Pixels: R, G, B (8 bits each), last (tlast), user (tuser), LSB first.
  output logic                                       out_valid_o,
  input  logic                                       out_ready_i,
  output logic [3*cube5_warp_pkg::OutCodeW+1:0]      out_data_o
);

  localparam int unsigned PayW    = cube5_warp_pkg::pay_w(ColorW);
  localparam int unsigned AddrW   = cube5_warp_pkg::RegAddrW;
  localparam int unsigned CoordW  = cube5_warp_pkg::CoordW;
  localparam int unsigned CodeW   = cube5_warp_pkg::OutCodeW;
  localparam int unsigned O       = $clog2(MaxOut);
  localparam int unsigned TexW    = 3 * ColorW;

  // ColorW, WeightW and MaxBase are checked by cube5_warp_sample.
  if (MaxOut < 4 || MaxOut > 4096 || (1 << O) != MaxOut) begin : gen_bad_max_out
    $fatal(1, "cube5_warp: MaxOut must be a power of two in 4..4096");
  end

  // ---------------------------------------------------------------------------------------------
  // Input items: registers, texel writes, Go
  // ---------------------------------------------------------------------------------------------

  logic [1:0]       op;
  logic [AddrW-1:0] addr;
  logic [PayW-1:0]  payload;
  assign payload = in_data_i[PayW-1:0];
  assign addr    = in_data_i[PayW +: AddrW];
  assign op      = in_data_i[PayW+AddrW +: 2];

  logic busy_q, busy_d;
  logic in_fire;
  assign in_ready_o = !busy_q;
  assign in_fire    = in_valid_i & in_ready_o;

  logic is_write, is_texel, is_go;
  assign is_write = in_fire && (op == cube5_warp_pkg::OpWrite);
  assign is_texel = in_fire && (op == cube5_warp_pkg::OpTexel);
  assign is_go    = in_fire && (op == cube5_warp_pkg::OpGo);

  logic [O:0]        out_w_q, out_w_d, out_h_q, out_h_d;
  logic [CoordW-1:0] x0_q, x0_d, y0_q, y0_d, xpx_q, xpx_d, ypx_q, ypx_d, xpy_q, xpy_d;
  logic [CoordW-1:0] ypy_q, ypy_d;

  always_comb begin
    out_w_d  = out_w_q;
    out_h_d  = out_h_q;
    x0_d     = x0_q;
    y0_d     = y0_q;
    xpx_d    = xpx_q;
    ypx_d    = ypx_q;
    xpy_d    = xpy_q;
    ypy_d    = ypy_q;
    if (is_write) begin
      if (addr == AddrW'(cube5_warp_pkg::RegOutW))  out_w_d  = payload[O:0];
      if (addr == AddrW'(cube5_warp_pkg::RegOutH))  out_h_d  = payload[O:0];
      if (addr == AddrW'(cube5_warp_pkg::RegX0))    x0_d     = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_warp_pkg::RegY0))    y0_d     = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_warp_pkg::RegXPx))   xpx_d    = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_warp_pkg::RegYPx))   ypx_d    = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_warp_pkg::RegXPy))   xpy_d    = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_warp_pkg::RegYPy))   ypy_d    = payload[CoordW-1:0];
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Issue: raster counters and exact coordinate steps
  // ---------------------------------------------------------------------------------------------

  logic adv;          // the whole pipeline moves
  logic issue;        // a pixel enters the sampler in this clock
  logic out_valid;    // the sampler's last stage holds a pixel
  assign adv   = !out_valid || out_ready_i;
  assign issue = busy_q && adv;

  logic [O:0]        px_q, px_d, py_q, py_d;
  logic [CoordW-1:0] xrow_q, xrow_d, yrow_q, yrow_d, xcur_q, xcur_d, ycur_q, ycur_d;
  logic              row_end, frame_end;
  assign row_end   = (px_q == out_w_q - (O+1)'(1));
  assign frame_end = (py_q == out_h_q - (O+1)'(1));

  always_comb begin
    busy_d = busy_q;
    px_d   = px_q;
    py_d   = py_q;
    xrow_d = xrow_q;
    yrow_d = yrow_q;
    xcur_d = xcur_q;
    ycur_d = ycur_q;
    if (is_go) begin
      busy_d = (out_w_q != '0) && (out_h_q != '0);
      px_d   = '0;
      py_d   = '0;
      xrow_d = x0_q;
      yrow_d = y0_q;
      xcur_d = x0_q;
      ycur_d = y0_q;
    end else if (issue) begin
      if (row_end) begin
        px_d   = '0;
        py_d   = py_q + (O+1)'(1);
        xrow_d = xrow_q + xpy_q;
        yrow_d = yrow_q + ypy_q;
        xcur_d = xrow_q + xpy_q;
        ycur_d = yrow_q + ypy_q;
        busy_d = !frame_end;
      end else begin
        px_d   = px_q + (O+1)'(1);
        xcur_d = xcur_q + xpx_q;
        ycur_d = ycur_q + ypx_q;
      end
    end
  end

  // ---------------------------------------------------------------------------------------------
  // The banks and the bilinear filter (shared with cube5_pwarp)
  // ---------------------------------------------------------------------------------------------

  // Carried with each pixel: {tuser (the frame's first pixel), tlast (a row's last)}.
  logic [1:0]         meta_in, meta;
  logic [3*CodeW-1:0] rgb;
  assign meta_in = {(px_q == '0) && (py_q == '0), row_end};

  cube5_warp_sample #(
    .ColorW (ColorW),
    .WeightW(WeightW),
    .MaxBase(MaxBase),
    .MetaW  (2)
  ) u_sample (
    .clk_i         (clk_i),
    .rst_ni        (rst_ni),
    .adv_i         (adv),
    .issue_i       (issue),
    .x_i           (xcur_q),
    .y_i           (ycur_q),
    .reg_wr_i      (is_write),
    .reg_addr_i    (addr),
    .meta_i        (meta_in),
    .tex_i         (is_texel),
    .tex_restart_i (is_write || is_go),
    .wdata_i       (payload[TexW-1:0]),
    .valid_o       (out_valid),
    .rgb_o         (rgb),
    .meta_o        (meta)
  );

  // ---------------------------------------------------------------------------------------------
  // Registers
  // ---------------------------------------------------------------------------------------------

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      busy_q   <= 1'b0;
      out_w_q  <= '0;
      out_h_q  <= '0;
      x0_q     <= '0;
      y0_q     <= '0;
      xpx_q    <= '0;
      ypx_q    <= '0;
      xpy_q    <= '0;
      ypy_q    <= '0;
    end else begin
      busy_q   <= busy_d;
      out_w_q  <= out_w_d;
      out_h_q  <= out_h_d;
      x0_q     <= x0_d;
      y0_q     <= y0_d;
      xpx_q    <= xpx_d;
      ypx_q    <= ypx_d;
      xpy_q    <= xpy_d;
      ypy_q    <= ypy_d;
    end
  end

  // Datapath: counters and coordinates (set by Go before use).
  always_ff @(posedge clk_i) begin
    px_q   <= px_d;
    py_q   <= py_d;
    xrow_q <= xrow_d;
    yrow_q <= yrow_d;
    xcur_q <= xcur_d;
    ycur_q <= ycur_d;
  end

  assign out_valid_o = out_valid;
  assign out_data_o  = {meta, rgb};

  // Unused: the payload above a texel's codes or a register's width.
  logic unused;
  assign unused = ^payload;

`ifndef SYNTHESIS
  stalled_output_holds : assert property (@(posedge clk_i) disable iff (!rst_ni)
    out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_warp: a stalled output changed or dropped valid");
`endif

endmodule
