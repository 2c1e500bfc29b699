// cube5_pwarp: the perspective warp of the base-plane image onto the final image along
// parallel-preserving scanlines (patent [66]-[94]; contract docs/numerics/pwarp.md).
//
// Under a projective map the homogeneous coordinate w is constant along one family of parallel
// lines of the output image (the PP scanlines, [70]-[72]); along such a line the base-plane
// position is affine in the column, so the host projects each line's two ends (two divisions per
// scanline, [69]) and the unit steps between them with integer adds, one sample per clock. A
// sample's row is the line's, rounded: the write template ([94]), stepped here by a phase
// accumulator (`Slope`, `Phase`). Each output item carries its pixel address (a forward warp
// writes the frame buffer in scanline order, not raster order).
//
//   Line (U0, V0, N; X, Y, XS, YS, Phase) -> issue: coordinate steps, template step
//     -> cube5_warp_sample (four parity banks, bilinear, 8-bit RGB; six stages) -> out
//
// Register writes to the next line's registers are taken while a line is issued, and a `Line`
// in the clock of the current line's last issue, so back-to-back lines leave one sample per
// clock. Back-pressure stalls the whole pipeline through one enable (`adv`).
module cube5_pwarp #(
  /// Bits of a base-plane colour code (the frame's ColorW).
  parameter int unsigned ColorW  = 8,
  /// Fraction bits of a bilinear weight.
  parameter int unsigned WeightW = 8,
  /// Largest base-plane edge held in block RAM (a power of two).
  parameter int unsigned MaxBase = 128,
  /// Largest output edge (a power of two, at most 2048).
  parameter int unsigned MaxOut  = 512
) (
  input  logic clk_i,
  /// Synchronous, active low: registers and texel position to 0, emission stopped.
  input  logic rst_ni,

  /// Items: payload, addr, op (LSB first; docs/numerics/pwarp.md, "Input item").
  input  logic                                                             in_valid_i,
  output logic                                                             in_ready_o,
  input  logic [cube5_warp_pkg::pay_w(ColorW)+cube5_warp_pkg::RegAddrW+1:0] in_data_i,

  /// Samples: R, G, B (8 bits each), px, py (log2 MaxOut each), last (the line's last), LSB first.
  output logic                                                           out_valid_o,
  input  logic                                                           out_ready_i,
  output logic [3*cube5_warp_pkg::OutCodeW+2*$clog2(MaxOut):0]           out_data_o
);

  localparam int unsigned PayW    = cube5_warp_pkg::pay_w(ColorW);
  localparam int unsigned AddrW   = cube5_warp_pkg::RegAddrW;
  localparam int unsigned CoordW  = cube5_warp_pkg::CoordW;
  localparam int unsigned CodeW   = cube5_warp_pkg::OutCodeW;
  localparam int unsigned KF      = cube5_pwarp_pkg::SlopeFracW;
  localparam int unsigned O       = $clog2(MaxOut);
  localparam int unsigned TexW    = 3 * ColorW;
  localparam int unsigned MetaW   = 2 * O + 1;

  // ColorW, WeightW and MaxBase are checked by cube5_warp_sample.
  if (MaxOut < 4 || MaxOut > 2048 || (1 << O) != MaxOut) begin : gen_bad_max_out
    $fatal(1, "cube5_pwarp: MaxOut must be a power of two in 4..2048 (U0, V0, N fit a payload)");
  end
  // BaseW and BaseH are kept by cube5_warp_sample at cube5_warp's offsets.
  if (cube5_pwarp_pkg::RegBaseW != cube5_warp_pkg::RegBaseW
      || cube5_pwarp_pkg::RegBaseH != cube5_warp_pkg::RegBaseH) begin : gen_bad_base_regs
    $fatal(1, "cube5_pwarp: BaseW and BaseH must sit at cube5_warp's offsets");
  end

  // ---------------------------------------------------------------------------------------------
  // Input items: registers, texel writes, Line
  // ---------------------------------------------------------------------------------------------

  logic [1:0]       op;
  logic [AddrW-1:0] addr;
  logic [PayW-1:0]  payload;
  assign payload = in_data_i[PayW-1:0];
  assign addr    = in_data_i[PayW +: AddrW];
  assign op      = in_data_i[PayW+AddrW +: 2];

  logic adv;          // the whole pipeline moves
  logic issue;        // a sample enters the sampler in this clock
  logic out_valid;    // the sampler's last stage holds a sample
  logic busy_q, busy_d;
  logic [O:0] cnt_q, cnt_d;
  logic line_end, line_free;
  assign adv       = !out_valid || out_ready_i;
  assign issue     = busy_q && adv;
  assign line_end  = (cnt_q == (O+1)'(1));
  assign line_free = !busy_q || (issue && line_end);

  // The next line's registers may be written while a line is issued; everything else waits.
  logic line_reg;
  assign line_reg = (addr == AddrW'(cube5_pwarp_pkg::RegX)) || (addr == AddrW'(cube5_pwarp_pkg::RegY))
                 || (addr == AddrW'(cube5_pwarp_pkg::RegXS)) || (addr == AddrW'(cube5_pwarp_pkg::RegYS))
                 || (addr == AddrW'(cube5_pwarp_pkg::RegPhase));
  always_comb begin
    unique case (op)
      cube5_pwarp_pkg::OpWrite: in_ready_o = !busy_q || line_reg;
      cube5_pwarp_pkg::OpLine:  in_ready_o = line_free;
      default:                  in_ready_o = !busy_q;
    endcase
  end

  logic in_fire, is_write, is_texel, is_line;
  assign in_fire  = in_valid_i & in_ready_o;
  assign is_write = in_fire && (op == cube5_pwarp_pkg::OpWrite);
  assign is_texel = in_fire && (op == cube5_pwarp_pkg::OpTexel);
  assign is_line  = in_fire && (op == cube5_pwarp_pkg::OpLine);

  logic [KF:0]       slope_q, slope_d;
  logic              neg_q, neg_d, tr_q, tr_d;
  logic [CoordW-1:0] xr_q, xr_d, yr_q, yr_d, xsr_q, xsr_d, ysr_q, ysr_d;
  logic [KF-1:0]     phr_q, phr_d;

  always_comb begin
    slope_d  = slope_q;
    neg_d    = neg_q;
    tr_d     = tr_q;
    xr_d     = xr_q;
    yr_d     = yr_q;
    xsr_d    = xsr_q;
    ysr_d    = ysr_q;
    phr_d    = phr_q;
    if (is_write) begin
      if (addr == AddrW'(cube5_pwarp_pkg::RegSlope)) slope_d  = payload[KF:0];
      if (addr == AddrW'(cube5_pwarp_pkg::RegMode)) begin
        neg_d = payload[cube5_pwarp_pkg::RegModeNegLsb];
        tr_d  = payload[cube5_pwarp_pkg::RegModeTransposeLsb];
      end
      if (addr == AddrW'(cube5_pwarp_pkg::RegX))     xr_d  = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_pwarp_pkg::RegY))     yr_d  = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_pwarp_pkg::RegXS))    xsr_d = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_pwarp_pkg::RegYS))    ysr_d = payload[CoordW-1:0];
      if (addr == AddrW'(cube5_pwarp_pkg::RegPhase)) phr_d = payload[KF-1:0];
    end
  end

  // ---------------------------------------------------------------------------------------------
  // Issue: the line's samples, exact coordinate steps, the write template's row steps
  // ---------------------------------------------------------------------------------------------

  logic [O-1:0]      u_q, u_d, v_q, v_d;
  logic [KF-1:0]     ph_q, ph_d;
  logic [CoordW-1:0] xcur_q, xcur_d, ycur_q, ycur_d, xs_q, xs_d, ys_q, ys_d;
  logic [KF+1:0]     ph_sum;
  logic              row_step;
  assign ph_sum   = {2'b00, ph_q} + {1'b0, slope_q};
  assign row_step = ph_sum[KF+1:KF] != 2'b00;

  always_comb begin
    busy_d = busy_q;
    cnt_d  = cnt_q;
    u_d    = u_q;
    v_d    = v_q;
    ph_d   = ph_q;
    xcur_d = xcur_q;
    ycur_d = ycur_q;
    xs_d   = xs_q;
    ys_d   = ys_q;
    if (is_line) begin
      busy_d = payload[2*O +: O+1] != '0;
      cnt_d  = payload[2*O +: O+1];
      u_d    = payload[0 +: O];
      v_d    = payload[O +: O];
      ph_d   = phr_q;
      xcur_d = xr_q;
      ycur_d = yr_q;
      xs_d   = xsr_q;
      ys_d   = ysr_q;
    end else if (issue) begin
      busy_d = !line_end;
      cnt_d  = cnt_q - (O+1)'(1);
      u_d    = u_q + O'(1);
      ph_d   = ph_sum[KF-1:0];
      if (row_step) v_d = neg_q ? v_q - O'(1) : v_q + O'(1);
      xcur_d = xcur_q + xs_q;
      ycur_d = ycur_q + ys_q;
    end
  end

  logic [MetaW-1:0] meta_in, meta;
  assign meta_in = tr_q ? {line_end, u_q, v_q} : {line_end, v_q, u_q};

  // ---------------------------------------------------------------------------------------------
  // The banks and the bilinear filter (shared with cube5_warp)
  // ---------------------------------------------------------------------------------------------

  logic [3*CodeW-1:0] rgb;
  cube5_warp_sample #(
    .ColorW (ColorW),
    .WeightW(WeightW),
    .MaxBase(MaxBase),
    .MetaW  (MetaW)
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
    .tex_restart_i (is_write || is_line),
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
      cnt_q    <= '0;
      slope_q  <= '0;
      neg_q    <= 1'b0;
      tr_q     <= 1'b0;
      xr_q     <= '0;
      yr_q     <= '0;
      xsr_q    <= '0;
      ysr_q    <= '0;
      phr_q    <= '0;
    end else begin
      busy_q   <= busy_d;
      cnt_q    <= cnt_d;
      slope_q  <= slope_d;
      neg_q    <= neg_d;
      tr_q     <= tr_d;
      xr_q     <= xr_d;
      yr_q     <= yr_d;
      xsr_q    <= xsr_d;
      ysr_q    <= ysr_d;
      phr_q    <= phr_d;
    end
  end

  // Datapath: the line's position and steps (set by Line before use).
  always_ff @(posedge clk_i) begin
    u_q    <= u_d;
    v_q    <= v_d;
    ph_q   <= ph_d;
    xcur_q <= xcur_d;
    ycur_q <= ycur_d;
    xs_q   <= xs_d;
    ys_q   <= ys_d;
  end

  assign out_valid_o = out_valid;
  assign out_data_o  = {meta, rgb};

  // Unused: the payload above a texel's codes, a register's width or the Line fields.
  logic unused;
  assign unused = ^payload;

`ifndef SYNTHESIS
  stalled_output_holds : assert property (@(posedge clk_i) disable iff (!rst_ni)
    out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_pwarp: a stalled output changed or dropped valid");
`endif

endmodule
