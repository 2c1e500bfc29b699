// cube5_warp: the 2-D affine warp of the base-plane image onto the final image for parallel views
// (patent [61], [66]-[110]; contract docs/numerics/warp.md).
//
// The base plane comes in on the input stream (register writes, texels in raster order, `Go`)
// and is kept in four block-RAM banks by texel parity, so the four bilinear taps of any position
// are read in one clock. A `Go` emits the OutW x OutH image in raster order, one pixel per clock:
// exact coordinate steps (integer adds), the taps read, widened to U(0.16), three rounded lerps per
// channel, 8-bit RGB out with tlast at each row end and tuser at the frame start.
//
//   issue (step adders, bank addresses) -> [banks' output registers, S1] -> [S1r] -> taps by
//   parity, widening [S2] -> two lerps along x [S3] -> lerp along y [S4] -> 8-bit rounding [S5] -> out
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
  localparam int unsigned FracW   = cube5_warp_pkg::CoordFracW;
  localparam int unsigned IntW    = CoordW - FracW;
  localparam int unsigned UnormW  = cube5_warp_pkg::UnormW;
  localparam int unsigned CodeW   = cube5_warp_pkg::OutCodeW;
  localparam int unsigned B       = $clog2(MaxBase);
  localparam int unsigned O       = $clog2(MaxOut);
  localparam int unsigned TexW    = 3 * ColorW;
  localparam int unsigned BankAW  = 2 * (B - 1);
  localparam int unsigned Drop    = FracW - WeightW;
  localparam int unsigned ValW    = UnormW + 1;

  if (ColorW < 4 || ColorW > 12) begin : gen_bad_color_w
    $fatal(1, "cube5_warp: ColorW must be 4..12");
  end
  if (WeightW < 4 || WeightW > 12) begin : gen_bad_weight_w
    $fatal(1, "cube5_warp: WeightW must be 4..12");
  end
  if (MaxBase < 4 || MaxBase > 1024 || (1 << B) != MaxBase) begin : gen_bad_max_base
    $fatal(1, "cube5_warp: MaxBase must be a power of two in 4..1024");
  end
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

  logic [B:0]        base_w_q, base_w_d, base_h_q, base_h_d;
  logic [O:0]        out_w_q, out_w_d, out_h_q, out_h_d;
  logic [CoordW-1:0] x0_q, x0_d, y0_q, y0_d, xpx_q, xpx_d, ypx_q, ypx_d, xpy_q, xpy_d;
  logic [CoordW-1:0] ypy_q, ypy_d;

  always_comb begin
    base_w_d = base_w_q;
    base_h_d = base_h_q;
    out_w_d  = out_w_q;
    out_h_d  = out_h_q;
    x0_d     = x0_q;
    y0_d     = y0_q;
    xpx_d    = xpx_q;
    ypx_d    = ypx_q;
    xpy_d    = xpy_q;
    ypy_d    = ypy_q;
    if (is_write) begin
      if (addr == AddrW'(cube5_warp_pkg::RegBaseW)) base_w_d = payload[B:0];
      if (addr == AddrW'(cube5_warp_pkg::RegBaseH)) base_h_d = payload[B:0];
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

  // Texel position: raster order over BaseW, y held at MaxBase once it gets there.
  logic [B:0] tx_q, tx_d, ty_q, ty_d;
  logic       tex_we;
  assign tex_we = is_texel && !tx_q[B] && !ty_q[B];

  always_comb begin
    tx_d = tx_q;
    ty_d = ty_q;
    if (is_write || is_go) begin
      tx_d = '0;
      ty_d = '0;
    end else if (is_texel) begin
      if ((tx_q + (B+1)'(1)) >= base_w_q) begin
        tx_d = '0;
        ty_d = ty_q[B] ? ty_q : ty_q + (B+1)'(1);
      end else begin
        tx_d = tx_q + (B+1)'(1);
      end
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Issue: raster counters and exact coordinate steps
  // ---------------------------------------------------------------------------------------------

  logic adv;          // the whole pipeline moves
  logic issue;        // a pixel enters S1 in this clock
  logic s1_valid_q, r_valid_q, s2_valid_q, s3_valid_q, s4_valid_q, s5_valid_q;
  assign adv   = !s5_valid_q || out_ready_i;
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

  // Integer parts (floor), rounded weights, and the tap of each parity along each axis.
  logic [IntW-1:0]  xi, yi;
  logic [WeightW:0] wx, wy;
  logic [FracW:0]   fx_rnd, fy_rnd;
  assign xi     = xcur_q[CoordW-1:FracW];
  assign yi     = ycur_q[CoordW-1:FracW];
  assign fx_rnd = {1'b0, xcur_q[FracW-1:0]} + (FracW+1)'(1 << (Drop - 1));
  assign fy_rnd = {1'b0, ycur_q[FracW-1:0]} + (FracW+1)'(1 << (Drop - 1));
  assign wx     = fx_rnd[FracW:Drop];
  assign wy     = fy_rnd[FracW:Drop];

  // xc[c]: the tap among xi, xi + 1 whose parity is c (IntW + 1 bits, signed).
  logic [IntW:0] xs, xs1, ys, ys1;
  logic [IntW:0] xc0, xc1, yc0, yc1;
  assign xs  = {xi[IntW-1], xi};
  assign xs1 = xs + (IntW+1)'(1);
  assign ys  = {yi[IntW-1], yi};
  assign ys1 = ys + (IntW+1)'(1);
  assign xc0 = xi[0] ? xs1 : xs;
  assign xc1 = xi[0] ? xs : xs1;
  assign yc0 = yi[0] ? ys1 : ys;
  assign yc1 = yi[0] ? ys : ys1;

  // Inside the base plane: 0 <= c < Base(W|H) and c < MaxBase.
  logic in_x0, in_x1, in_y0, in_y1;
  assign in_x0 = !xc0[IntW] && (xc0[IntW-1:B] == '0) && ({1'b0, xc0[B-1:0]} < base_w_q);
  assign in_x1 = !xc1[IntW] && (xc1[IntW-1:B] == '0) && ({1'b0, xc1[B-1:0]} < base_w_q);
  assign in_y0 = !yc0[IntW] && (yc0[IntW-1:B] == '0) && ({1'b0, yc0[B-1:0]} < base_h_q);
  assign in_y1 = !yc1[IntW] && (yc1[IntW-1:B] == '0) && ({1'b0, yc1[B-1:0]} < base_h_q);

  logic [3:0]        tap_in;         // by bank {row parity, column parity}
  logic [4*BankAW-1:0] raddr;     // bank k at [k*BankAW +: BankAW]
  always_comb begin
    tap_in[0] = in_y0 && in_x0;
    tap_in[1] = in_y0 && in_x1;
    tap_in[2] = in_y1 && in_x0;
    tap_in[3] = in_y1 && in_x1;
    raddr     = {yc1[B-1:1], xc1[B-1:1], yc1[B-1:1], xc0[B-1:1],
                 yc0[B-1:1], xc1[B-1:1], yc0[B-1:1], xc0[B-1:1]};
  end

  // ---------------------------------------------------------------------------------------------
  // The four banks (block RAM, registered output = S1's texels)
  // ---------------------------------------------------------------------------------------------

  logic [BankAW-1:0] waddr;
  logic [1:0]        wbank;
  logic [4*TexW-1:0] rdata;       // bank k at [k*TexW +: TexW]
  assign waddr = {ty_q[B-1:1], tx_q[B-1:1]};
  assign wbank = {ty_q[0], tx_q[0]};

  for (genvar k = 0; k < 4; k++) begin : gen_bank
    cube5_shader_ram #(
      .Depth(1 << BankAW),
      .Width(TexW),
      .AddrW(BankAW)
    ) u_bank (
      .clk_i  (clk_i),
      .we_i   (tex_we && (wbank == 2'(k))),
      .waddr_i(waddr),
      .wdata_i(payload[TexW-1:0]),
      .re_i   (adv),
      .raddr_i(raddr[k*BankAW +: BankAW]),
      .rdata_o(rdata[k*TexW +: TexW])
    );
  end

  // ---------------------------------------------------------------------------------------------
  // S1: texels read; taps selected by parity, masked, widened
  // ---------------------------------------------------------------------------------------------

  logic             s1_xpar_q, s1_ypar_q, s1_last_q, s1_user_q;
  logic [3:0]       s1_in_q;
  logic [WeightW:0] s1_wx_q, s1_wy_q;

  // The banks' outputs registered once more (S1r), off the block RAM's slow clock-to-output.
  logic [4*TexW-1:0] r_rdata_q;
  logic              r_xpar_q, r_ypar_q, r_last_q, r_user_q;
  logic [3:0]        r_in_q;
  logic [WeightW:0]  r_wx_q, r_wy_q;

  logic [TexW-1:0] bank0, bank1, bank2, bank3;
  assign bank0 = r_in_q[0] ? r_rdata_q[0*TexW +: TexW] : '0;
  assign bank1 = r_in_q[1] ? r_rdata_q[1*TexW +: TexW] : '0;
  assign bank2 = r_in_q[2] ? r_rdata_q[2*TexW +: TexW] : '0;
  assign bank3 = r_in_q[3] ? r_rdata_q[3*TexW +: TexW] : '0;

  // Tap t = x + 2y is the texel of bank {ypar ^ y, xpar ^ x}: plain 4:1 multiplexers.
  logic [4*TexW-1:0] tap;          // tap t at [t*TexW +: TexW]
  always_comb begin
    unique case ({r_ypar_q, r_xpar_q})
      2'b00:   tap = {bank3, bank2, bank1, bank0};
      2'b01:   tap = {bank2, bank3, bank0, bank1};
      2'b10:   tap = {bank1, bank0, bank3, bank2};
      default: tap = {bank0, bank1, bank2, bank3};
    endcase
  end

  logic [12*ValW-1:0] u;           // tap t, channel ch at [(3 t + ch) ValW +: ValW]
  for (genvar t = 0; t < 4; t++) begin : gen_tap
    for (genvar ch = 0; ch < 3; ch++) begin : gen_widen
      cube5_compos_unorm #(
        .W(ColorW),
        .S(UnormW)
      ) u_widen (
        .code_i (tap[t*TexW + ch*ColorW +: ColorW]),
        .value_o(u[(3*t+ch)*ValW +: ValW])
      );
    end
  end

  // ---------------------------------------------------------------------------------------------
  // S2: lerps along x
  // ---------------------------------------------------------------------------------------------

  logic [12*ValW-1:0] s2_u_q;
  logic [WeightW:0]   s2_wx_q, s2_wy_q;
  logic               s2_last_q, s2_user_q;

  logic [3*ValW-1:0] h0, h1;       // channel ch at [ch*ValW +: ValW]
  for (genvar ch = 0; ch < 3; ch++) begin : gen_lerp_x
    cube5_lerp #(
      .ValW(ValW),
      .WeightW(WeightW)
    ) u_h0 (
      .a_i(s2_u_q[ch*ValW +: ValW]),
      .b_i(s2_u_q[(3+ch)*ValW +: ValW]),
      .e_i(s2_wx_q),
      .y_o(h0[ch*ValW +: ValW])
    );
    cube5_lerp #(
      .ValW(ValW),
      .WeightW(WeightW)
    ) u_h1 (
      .a_i(s2_u_q[(6+ch)*ValW +: ValW]),
      .b_i(s2_u_q[(9+ch)*ValW +: ValW]),
      .e_i(s2_wx_q),
      .y_o(h1[ch*ValW +: ValW])
    );
  end

  // ---------------------------------------------------------------------------------------------
  // S3: lerp along y; S4: 8-bit rounding
  // ---------------------------------------------------------------------------------------------

  logic [3*ValW-1:0] s3_h0_q, s3_h1_q;
  logic [WeightW:0]  s3_wy_q;
  logic              s3_last_q, s3_user_q;

  logic [3*ValW-1:0]  v;           // channel ch at [ch*ValW +: ValW]
  logic [3*ValW-1:0]  s4_v_q;
  logic               s4_last_q, s4_user_q;
  logic [3*CodeW-1:0] rgb;
  for (genvar ch = 0; ch < 3; ch++) begin : gen_lerp_y
    logic [ValW-1:0]       vq;
    logic [ValW+CodeW-1:0] scaled;
    cube5_lerp #(
      .ValW(ValW),
      .WeightW(WeightW)
    ) u_v (
      .a_i(s3_h0_q[ch*ValW +: ValW]),
      .b_i(s3_h1_q[ch*ValW +: ValW]),
      .e_i(s3_wy_q),
      .y_o(v[ch*ValW +: ValW])
    );
    // v * 255 + 2^(UnormW - 1): v <= 2^UnormW, so the sum fits ValW + CodeW bits.
    assign vq     = s4_v_q[ch*ValW +: ValW];
    assign scaled = ({vq, CodeW'(0)} - (ValW+CodeW)'(vq)) + (ValW+CodeW)'(1 << (UnormW - 1));
    assign rgb[ch*CodeW +: CodeW] = scaled[UnormW +: CodeW];
    // The discarded fraction and the top bit (always 0: v * 255 + 2^15 < 2^24).
    logic unused_scaled;
    assign unused_scaled = ^{scaled[UnormW-1:0], scaled[ValW+CodeW-1]};
  end

  // ---------------------------------------------------------------------------------------------
  // Pipeline registers
  // ---------------------------------------------------------------------------------------------

  logic [3*CodeW+1:0] s5_data_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      busy_q     <= 1'b0;
      s1_valid_q <= 1'b0;
      s2_valid_q <= 1'b0;
      s3_valid_q <= 1'b0;
      s4_valid_q <= 1'b0;
      s5_valid_q <= 1'b0;
      r_valid_q  <= 1'b0;
      base_w_q   <= '0;
      base_h_q   <= '0;
      out_w_q    <= '0;
      out_h_q    <= '0;
      x0_q       <= '0;
      y0_q       <= '0;
      xpx_q      <= '0;
      ypx_q      <= '0;
      xpy_q      <= '0;
      ypy_q      <= '0;
      tx_q       <= '0;
      ty_q       <= '0;
    end else begin
      busy_q   <= busy_d;
      base_w_q <= base_w_d;
      base_h_q <= base_h_d;
      out_w_q  <= out_w_d;
      out_h_q  <= out_h_d;
      x0_q     <= x0_d;
      y0_q     <= y0_d;
      xpx_q    <= xpx_d;
      ypx_q    <= ypx_d;
      xpy_q    <= xpy_d;
      ypy_q    <= ypy_d;
      tx_q     <= tx_d;
      ty_q     <= ty_d;
      if (adv) begin
        s1_valid_q <= issue;
        r_valid_q  <= s1_valid_q;
        s2_valid_q <= r_valid_q;
        s3_valid_q <= s2_valid_q;
        s4_valid_q <= s3_valid_q;
        s5_valid_q <= s4_valid_q;
      end
    end
  end

  // Datapath: counters and coordinates (set by Go before use), stage contents (qualified by the
  // valids).
  always_ff @(posedge clk_i) begin
    px_q   <= px_d;
    py_q   <= py_d;
    xrow_q <= xrow_d;
    yrow_q <= yrow_d;
    xcur_q <= xcur_d;
    ycur_q <= ycur_d;
    if (adv) begin
      s1_xpar_q <= xi[0];
      s1_ypar_q <= yi[0];
      s1_in_q   <= tap_in;
      s1_wx_q   <= wx;
      s1_wy_q   <= wy;
      s1_last_q <= row_end;
      s1_user_q <= (px_q == '0) && (py_q == '0);
      r_rdata_q <= rdata;
      r_xpar_q  <= s1_xpar_q;
      r_ypar_q  <= s1_ypar_q;
      r_in_q    <= s1_in_q;
      r_wx_q    <= s1_wx_q;
      r_wy_q    <= s1_wy_q;
      r_last_q  <= s1_last_q;
      r_user_q  <= s1_user_q;
      s2_u_q    <= u;
      s2_wx_q   <= r_wx_q;
      s2_wy_q   <= r_wy_q;
      s2_last_q <= r_last_q;
      s2_user_q <= r_user_q;
      s3_h0_q   <= h0;
      s3_h1_q   <= h1;
      s3_wy_q   <= s2_wy_q;
      s3_last_q <= s2_last_q;
      s3_user_q <= s2_user_q;
      s4_v_q    <= v;
      s4_last_q <= s3_last_q;
      s4_user_q <= s3_user_q;
      s5_data_q <= {s4_user_q, s4_last_q, rgb};
    end
  end

  assign out_valid_o = s5_valid_q;
  assign out_data_o  = s5_data_q;

  // Unused: the payload above a texel's codes or a register's width, the discarded fraction bits
  // of the weights and of the 8-bit rounding, bank address bit 0 (the parity).
  logic unused;
  assign unused = ^{payload, fx_rnd[Drop-1:0], fy_rnd[Drop-1:0], xc0[0], xc1[0], yc0[0], yc1[0]};

`ifndef SYNTHESIS
  stalled_output_holds : assert property (@(posedge clk_i) disable iff (!rst_ni)
    out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_warp: a stalled output changed or dropped valid");
`endif

endmodule
