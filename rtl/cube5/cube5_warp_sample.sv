// cube5_warp_sample: the bilinear stage of cube5_warp and cube5_pwarp (contracts
// docs/numerics/warp.md, "Bilinear filter" and "Block RAM", and docs/numerics/pwarp.md): the base
// plane in four block-RAM banks by texel parity with its size registers (BaseW, BaseH) and texel
// position, and per issued position the four taps read in one clock, widened to U(0.16), three
// rounded lerps per channel, 8-bit RGB. `meta_i` rides along.
//
//   issue (x_i, y_i, bank addresses) -> [banks' output registers, S1] -> [S1r] -> taps by parity,
//   widening [S2] -> two lerps along x [S3] -> lerp along y [S4] -> 8-bit rounding [S5] -> out
//
// `adv_i` moves the whole pipeline (block-RAM output registers included): the caller stalls it
// when its output is full and not taken, so a stalled output holds.
module cube5_warp_sample #(
  /// Bits of a base-plane colour code.
  parameter int unsigned ColorW  = 8,
  /// Fraction bits of a bilinear weight.
  parameter int unsigned WeightW = 8,
  /// Largest base-plane edge held in block RAM (a power of two).
  parameter int unsigned MaxBase = 128,
  /// Bits carried alongside each position.
  parameter int unsigned MetaW   = 2
) (
  input  logic clk_i,
  /// Synchronous, active low: the stage valids and the texel position to 0.
  input  logic rst_ni,

  /// The pipeline moves this clock.
  input  logic                                  adv_i,
  /// A position enters (with adv_i).
  input  logic                                  issue_i,
  /// The position, S(15.20) base-plane texels.
  input  logic [cube5_warp_pkg::CoordW-1:0]     x_i,
  input  logic [cube5_warp_pkg::CoordW-1:0]     y_i,
  /// A register write (`wdata_i` to offset `reg_addr_i`): BaseW and BaseH, the base plane's size,
  /// are kept here (taps outside it read 0); both warps' maps place them at the same offsets.
  input  logic                                  reg_wr_i,
  input  logic [cube5_warp_pkg::RegAddrW-1:0]   reg_addr_i,
  /// Carried with the position to the output.
  input  logic [MetaW-1:0]                      meta_i,

  /// Texel items: `tex_i` stores codes R, G, B (ColorW each, LSB first) at the texel position
  /// (raster order over BaseW; y held at MaxBase once it gets there, and nothing stored) and
  /// advances it; `tex_restart_i` puts the position back to (0, 0). `wdata_i` is also a register
  /// write's data (BaseW and BaseH in its low bits).
  input  logic                                  tex_i,
  input  logic                                  tex_restart_i,
  input  logic [3*ColorW-1:0]                   wdata_i,

  /// S5 holds a pixel.
  output logic                                  valid_o,
  /// Its 8-bit R, G, B (LSB first) and meta.
  output logic [3*cube5_warp_pkg::OutCodeW-1:0] rgb_o,
  output logic [MetaW-1:0]                      meta_o
);

  localparam int unsigned CoordW  = cube5_warp_pkg::CoordW;
  localparam int unsigned FracW   = cube5_warp_pkg::CoordFracW;
  localparam int unsigned IntW    = CoordW - FracW;
  localparam int unsigned UnormW  = cube5_warp_pkg::UnormW;
  localparam int unsigned CodeW   = cube5_warp_pkg::OutCodeW;
  localparam int unsigned B       = $clog2(MaxBase);
  localparam int unsigned TexW    = 3 * ColorW;
  localparam int unsigned BankAW  = 2 * (B - 1);
  localparam int unsigned Drop    = FracW - WeightW;
  localparam int unsigned ValW    = UnormW + 1;

  if (ColorW < 4 || ColorW > 12) begin : gen_bad_color_w
    $fatal(1, "cube5_warp_sample: ColorW must be 4..12");
  end
  if (WeightW < 4 || WeightW > 12) begin : gen_bad_weight_w
    $fatal(1, "cube5_warp_sample: WeightW must be 4..12");
  end
  if (MaxBase < 4 || MaxBase > 1024 || (1 << B) != MaxBase) begin : gen_bad_max_base
    $fatal(1, "cube5_warp_sample: MaxBase must be a power of two in 4..1024");
  end
  if (MetaW < 1) begin : gen_bad_meta_w
    $fatal(1, "cube5_warp_sample: MetaW must be at least 1");
  end

  // ---------------------------------------------------------------------------------------------
  // The base plane's size (BaseW, BaseH)
  // ---------------------------------------------------------------------------------------------

  logic [B:0] base_w_q, base_w_d, base_h_q, base_h_d;

  always_comb begin
    base_w_d = base_w_q;
    base_h_d = base_h_q;
    if (reg_wr_i && 32'(reg_addr_i) == cube5_warp_pkg::RegBaseW) base_w_d = wdata_i[B:0];
    if (reg_wr_i && 32'(reg_addr_i) == cube5_warp_pkg::RegBaseH) base_h_d = wdata_i[B:0];
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      base_w_q <= '0;
      base_h_q <= '0;
    end else begin
      base_w_q <= base_w_d;
      base_h_q <= base_h_d;
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Issue: integer parts, weights, taps
  // ---------------------------------------------------------------------------------------------

  // Integer parts (floor), rounded weights, and the tap of each parity along each axis.
  logic [IntW-1:0]  xi, yi;
  logic [WeightW:0] wx, wy;
  logic [FracW:0]   fx_rnd, fy_rnd;
  assign xi     = x_i[CoordW-1:FracW];
  assign yi     = y_i[CoordW-1:FracW];
  assign fx_rnd = {1'b0, x_i[FracW-1:0]} + (FracW+1)'(1 << (Drop - 1));
  assign fy_rnd = {1'b0, y_i[FracW-1:0]} + (FracW+1)'(1 << (Drop - 1));
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
  // Texel position: raster order over BaseW, y held at MaxBase once it gets there
  // ---------------------------------------------------------------------------------------------

  logic [B:0] tx_q, tx_d, ty_q, ty_d;
  logic       tex_we;
  assign tex_we = tex_i && !tx_q[B] && !ty_q[B];

  always_comb begin
    tx_d = tx_q;
    ty_d = ty_q;
    if (tex_restart_i) begin
      tx_d = '0;
      ty_d = '0;
    end else if (tex_i) begin
      if ((tx_q + (B+1)'(1)) >= base_w_q) begin
        tx_d = '0;
        ty_d = ty_q[B] ? ty_q : ty_q + (B+1)'(1);
      end else begin
        tx_d = tx_q + (B+1)'(1);
      end
    end
  end

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      tx_q <= '0;
      ty_q <= '0;
    end else begin
      tx_q <= tx_d;
      ty_q <= ty_d;
    end
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
      .wdata_i(wdata_i),
      .re_i   (adv_i),
      .raddr_i(raddr[k*BankAW +: BankAW]),
      .rdata_o(rdata[k*TexW +: TexW])
    );
  end

  // ---------------------------------------------------------------------------------------------
  // S1: texels read; taps selected by parity, masked, widened
  // ---------------------------------------------------------------------------------------------

  logic             s1_xpar_q, s1_ypar_q;
  logic [MetaW-1:0] s1_meta_q;
  logic [3:0]       s1_in_q;
  logic [WeightW:0] s1_wx_q, s1_wy_q;

  // The banks' outputs registered once more (S1r), off the block RAM's slow clock-to-output.
  logic [4*TexW-1:0] r_rdata_q;
  logic              r_xpar_q, r_ypar_q;
  logic [MetaW-1:0]  r_meta_q;
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
  logic [MetaW-1:0]   s2_meta_q;

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
  logic [MetaW-1:0]  s3_meta_q;

  logic [3*ValW-1:0]  v;           // channel ch at [ch*ValW +: ValW]
  logic [3*ValW-1:0]  s4_v_q;
  logic [MetaW-1:0]   s4_meta_q;
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

  logic s1_valid_q, r_valid_q, s2_valid_q, s3_valid_q, s4_valid_q, s5_valid_q;
  logic [3*CodeW-1:0] s5_rgb_q;
  logic [MetaW-1:0]   s5_meta_q;

  always_ff @(posedge clk_i) begin
    if (!rst_ni) begin
      s1_valid_q <= 1'b0;
      r_valid_q  <= 1'b0;
      s2_valid_q <= 1'b0;
      s3_valid_q <= 1'b0;
      s4_valid_q <= 1'b0;
      s5_valid_q <= 1'b0;
    end else if (adv_i) begin
      s1_valid_q <= issue_i;
      r_valid_q  <= s1_valid_q;
      s2_valid_q <= r_valid_q;
      s3_valid_q <= s2_valid_q;
      s4_valid_q <= s3_valid_q;
      s5_valid_q <= s4_valid_q;
    end
  end

  // Stage contents, qualified by the valids.
  always_ff @(posedge clk_i) begin
    if (adv_i) begin
      s1_xpar_q <= xi[0];
      s1_ypar_q <= yi[0];
      s1_in_q   <= tap_in;
      s1_wx_q   <= wx;
      s1_wy_q   <= wy;
      s1_meta_q <= meta_i;
      r_rdata_q <= rdata;
      r_xpar_q  <= s1_xpar_q;
      r_ypar_q  <= s1_ypar_q;
      r_in_q    <= s1_in_q;
      r_wx_q    <= s1_wx_q;
      r_wy_q    <= s1_wy_q;
      r_meta_q  <= s1_meta_q;
      s2_u_q    <= u;
      s2_wx_q   <= r_wx_q;
      s2_wy_q   <= r_wy_q;
      s2_meta_q <= r_meta_q;
      s3_h0_q   <= h0;
      s3_h1_q   <= h1;
      s3_wy_q   <= s2_wy_q;
      s3_meta_q <= s2_meta_q;
      s4_v_q    <= v;
      s4_meta_q <= s3_meta_q;
      s5_rgb_q  <= rgb;
      s5_meta_q <= s4_meta_q;
    end
  end

  assign valid_o = s5_valid_q;
  assign rgb_o   = s5_rgb_q;
  assign meta_o  = s5_meta_q;

  // Unused: the discarded fraction bits of the weights, bank address bit 0 (the parity).
  logic unused;
  assign unused = ^{fx_rnd[Drop-1:0], fy_rnd[Drop-1:0], xc0[0], xc1[0], yc0[0], yc1[0]};

endmodule
