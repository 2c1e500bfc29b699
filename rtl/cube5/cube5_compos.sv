// cube5_compos: one sample meets the coxel of its ray; the updated coxel leaves (patent [240]: the
// compositing buffer is a FIFO of coxels; cube3-paper §2). docs/numerics/compos.md is the contract.
//
// Modes per item: front-to-back and back-to-front over, maximum, minimum, saturating X-ray sum,
// first opaque, and the end-of-ray flush that composites the preloaded opaque geometry under the
// volume ([62], [217]-[218]). The sample's alpha is opacity-corrected by a LUT loaded through the
// configuration port ([59], [213]-[214]); samples at or behind the geometry depth are dropped;
// front-to-back rays terminate early at a threshold.
//
// Six register stages, one item per clock when never stalled, latency 6:
//   decode (depth test, early-termination compare, synchronous LUT read) -> alpha select
//   -> weight w = rnd(T a, Q) and compares -> decision (new A, terminated, channel operations)
//   -> colour product (one signed multiplier per channel, shared by both over modes and the flush)
//   -> colour sum (round, add, saturate, select).
module cube5_compos #(
  /// Colour code width (sample and geometry R, G, B), 4..12.
  parameter int unsigned ColorW = 8,
  /// Sample alpha code width, 4..12; the opacity LUT has 2^AlphaW entries.
  parameter int unsigned AlphaW = 12,
  /// Corrected-alpha fraction bits beyond AlphaW, 0..6.
  parameter int unsigned ExtraW = 4,
  /// Coxel channel fraction bits, max(ColorW, AlphaW + ExtraW)..28; channels are U(1.AccW).
  parameter int unsigned AccW   = 20,
  /// Depth width (sample slice index and geometry Z), 1..16.
  parameter int unsigned ZW     = 12
) (
  input  logic clk_i,
  input  logic rst_ni,

  /// Configuration write this cycle.
  input  logic                 cfg_valid_i,
  /// LUT entry (bit AlphaW clear) or register 2^AlphaW + {0: Ctrl, 1: EtThreshold, 2: FoThreshold}.
  input  logic [AlphaW:0]      cfg_addr_i,
  /// Write data, fields LSB-aligned.
  input  logic [AccW:0]        cfg_data_i,

  /// Input item valid.
  input  logic in_valid_i,
  /// Unit can take an input item this cycle.
  output logic in_ready_o,
  /// Coxel (R, G, B, A, Z, geometry R, G, B, terminated) then sample (r, g, b, alpha, depth, mode).
  input  logic [cube5_compos_pkg::in_w(ColorW, AlphaW, AccW, ZW)-1:0] in_data_i,

  /// Output coxel valid.
  output logic out_valid_o,
  /// Consumer takes the coxel this cycle.
  input  logic out_ready_i,
  /// The updated coxel, same packing as the input coxel.
  output logic [cube5_compos_pkg::coxel_w(ColorW, AccW, ZW)-1:0] out_data_o
);

  localparam int unsigned Q       = AlphaW + ExtraW;  // corrected-alpha fraction bits
  localparam int unsigned F       = AccW;             // coxel fraction bits
  localparam int unsigned ChanW   = F + 1;            // one coxel channel, U(1.F)
  localparam int unsigned CorrW   = Q + 1;            // corrected alpha, U(1.Q)
  localparam int unsigned CoxelW  = cube5_compos_pkg::coxel_w(ColorW, AccW, ZW);
  // Colours and alpha carry no bits below 2^-P on the coxel scale (c_w = U(c, ColorW, P) << (F-P),
  // a_w = a << (F-Q)), so the colour multipliers take them on the scale 2^P: P+1 bits, not F+1.
  localparam int unsigned P       = cube5_compos_pkg::mul_scale(ColorW, AlphaW + ExtraW, AccW);
  localparam int unsigned VW      = P + 1;            // multiplier operand v, U(1.P)

  // Field positions, LSB first (contract: Stream items).
  localparam int unsigned ALsb     = 3 * ChanW;
  localparam int unsigned ZLsb     = 4 * ChanW;
  localparam int unsigned GeoLsb   = ZLsb + ZW;
  localparam int unsigned TermBit  = GeoLsb + 3 * ColorW;
  localparam int unsigned RgbLsb   = CoxelW;
  localparam int unsigned AlphaLsb = RgbLsb + 3 * ColorW;
  localparam int unsigned DepthLsb = AlphaLsb + AlphaW;
  localparam int unsigned ModeLsb  = DepthLsb + ZW;

  // All-ones constants by replication: Yosys 0.23 reads a typed localparam initialised with '1 as
  // the value 1 (Verilator reads all ones), which the gate-level co-simulation caught.
  localparam logic [ChanW-1:0] One      = ChanW'(1) << F;
  localparam logic [ChanW-1:0] ChanMax  = {ChanW{1'b1}};
  localparam logic [CorrW-1:0] AlphaOne = CorrW'(1) << Q;
  localparam logic [ZW-1:0]    ZNone    = {ZW{1'b1}};

  // Per-channel operation of the colour stage.
  localparam logic [1:0] OpKeep = 2'd0;  // C
  localparam logic [1:0] OpMul  = 2'd1;  // sat(C + rnd(u * v, F)), u signed
  localparam logic [1:0] OpSet  = 2'd2;  // alt
  localparam logic [1:0] OpAdd  = 2'd3;  // sat(C + alt)

  // Elaboration checks mirror ComposConfig::validate in the model.
  if (ColorW < 4 || ColorW > 12) begin : gen_bad_color_w
    $fatal(1, "cube5_compos: ColorW must be 4..12");
  end
  if (AlphaW < 4 || AlphaW > 12) begin : gen_bad_alpha_w
    $fatal(1, "cube5_compos: AlphaW must be 4..12");
  end
  if (ExtraW > 6) begin : gen_bad_extra_w
    $fatal(1, "cube5_compos: ExtraW must be 0..6");
  end
  if (AccW < AlphaW + ExtraW || AccW < ColorW || AccW > 28) begin : gen_bad_acc_w
    $fatal(1, "cube5_compos: AccW must be max(ColorW, AlphaW + ExtraW)..28");
  end
  if (ZW < 1 || ZW > 16) begin : gen_bad_z_w
    $fatal(1, "cube5_compos: ZW must be 1..16");
  end

  // rnd(x, s) for a run-time shift s (the X-ray divisor), x <= 2^F.
  function automatic logic [ChanW-1:0] rnd_shift(logic [ChanW-1:0] x, logic [3:0] s);
    logic [ChanW:0] biased;
    biased = {1'b0, x};
    if (s != 4'd0) begin
      biased = biased + ((ChanW+1)'(1) << (s - 4'd1));
    end
    rnd_shift = ChanW'(biased >> s);
  endfunction

  // ---------------------------------------------------------------------------
  // Configuration port: the opacity LUT and three registers (not reset: datapath state)
  // ---------------------------------------------------------------------------
  logic              cfg_lut_we;
  logic              cfg_reg_sel;
  logic [4:0]        ctrl_d, ctrl_q;         // {XrayShift, LutBypass}
  logic [ChanW-1:0]  et_d, et_q;             // EtThreshold
  logic [CorrW-1:0]  fo_d, fo_q;             // FoThreshold

  assign cfg_lut_we  = cfg_valid_i && !cfg_addr_i[AlphaW];
  assign cfg_reg_sel = cfg_valid_i && cfg_addr_i[AlphaW];

  always_comb begin
    ctrl_d = ctrl_q;
    et_d   = et_q;
    fo_d   = fo_q;
    if (cfg_reg_sel) begin
      unique case (cfg_addr_i[AlphaW-1:0])
        AlphaW'(cube5_compos_pkg::RegCtrl):        ctrl_d = cfg_data_i[4:0];
        AlphaW'(cube5_compos_pkg::RegEtThreshold): et_d   = cfg_data_i[ChanW-1:0];
        AlphaW'(cube5_compos_pkg::RegFoThreshold): fo_d   = cfg_data_i[CorrW-1:0];
        default: ;
      endcase
    end
  end

  always_ff @(posedge clk_i) begin
    ctrl_q <= ctrl_d;
    et_q   <= et_d;
    fo_q   <= fo_d;
  end

  // The table: one write port (config), one synchronous read port (stage 1), so FPGA flows map it
  // to block RAM. A memory write is the one place an always_ff indexes its target.
  logic [CorrW-1:0] lut_q [2**AlphaW];

  always_ff @(posedge clk_i) begin
    if (cfg_lut_we) begin
      lut_q[cfg_addr_i[AlphaW-1:0]] <= cfg_data_i[CorrW-1:0];
    end
  end

  // ---------------------------------------------------------------------------
  // Stage handshakes: a stage takes a new item when it is empty or its item moves on
  // ---------------------------------------------------------------------------
  // The stages' valids and enables (cube5_valid_chain: no vector whose bits feed each other).
  logic ready_1, ready_2, ready_3, ready_4, ready_5, ready_6;

  cube5_valid_chain #(
    .Stages (6)
  ) u_valid (
    .clk_i       (clk_i),
    .rst_ni      (rst_ni),
    .in_valid_i  (in_valid_i),
    .out_ready_i (out_ready_i),
    .ready_o     ({ready_6, ready_5, ready_4, ready_3, ready_2, ready_1}),
    .out_valid_o (out_valid_o)
  );
  assign in_ready_o = ready_1;

  // ---------------------------------------------------------------------------
  // Stage 1, decode: depth test, LUT read
  // ---------------------------------------------------------------------------
  logic [ZW-1:0]       in_z, in_depth;
  logic [AlphaW-1:0]   in_alpha;
  logic [CorrW-1:0]    lut_rd_d;
  logic                depth_pass_d1;

  assign in_z     = in_data_i[ZLsb +: ZW];
  assign in_depth = in_data_i[DepthLsb +: ZW];
  assign in_alpha = in_data_i[AlphaLsb +: AlphaW];
  assign lut_rd_d = lut_q[in_alpha];
  assign depth_pass_d1 = in_depth < in_z;   // in front of the geometry

  logic [CoxelW-1:0]   coxel_q1;
  logic [3*ColorW-1:0] rgb_q1;
  logic [AlphaW-1:0]   alpha_q1;
  logic [2:0]          mode_q1;
  logic                depth_pass_q1;
  logic [CorrW-1:0]    lut_rd_q1;

  always_ff @(posedge clk_i) begin
    if (ready_1) begin
      coxel_q1      <= in_data_i[CoxelW-1:0];
      rgb_q1        <= in_data_i[RgbLsb +: 3*ColorW];
      alpha_q1      <= in_alpha;
      mode_q1       <= in_data_i[ModeLsb +: 3];
      depth_pass_q1 <= depth_pass_d1;
      lut_rd_q1     <= lut_rd_d;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 2, alpha select: the early-termination compare, corrected alpha, transparency, colour
  // codes, which case applies (the compare reads the registered coxel: in a frame the coxel
  // comes from the compositing buffer's block RAM, whose slow output then ends in stage 1's
  // register; docs/accel.md, *Synthesis*)
  // ---------------------------------------------------------------------------
  logic [ChanW-1:0] a1;
  logic             et_hit;
  logic [CorrW-1:0] a_bypass, a_corr_d2;
  logic [ChanW-1:0] t_d2;
  logic [3*VW-1:0]  c_p_d2, g_p_d2;
  logic             contrib_d2, flush_geo_d2, mark_term_d2;

  assign a1     = coxel_q1[ALsb +: ChanW];
  assign et_hit = a1 >= et_q;

  cube5_compos_unorm #(
    .W (AlphaW),
    .S (Q)
  ) u_alpha_bypass (
    .code_i  (alpha_q1),
    .value_o (a_bypass)
  );

  for (genvar i = 0; i < 3; i++) begin : gen_codes
    cube5_compos_unorm #(
      .W (ColorW),
      .S (P)
    ) u_color (
      .code_i  (rgb_q1[i*ColorW +: ColorW]),
      .value_o (c_p_d2[i*VW +: VW])
    );
    cube5_compos_unorm #(
      .W (ColorW),
      .S (P)
    ) u_geo (
      .code_i  (coxel_q1[GeoLsb + i*ColorW +: ColorW]),
      .value_o (g_p_d2[i*VW +: VW])
    );
  end

  always_comb begin
    if (ctrl_q[0]) begin
      a_corr_d2 = a_bypass;
    end else begin
      a_corr_d2 = (lut_rd_q1 > AlphaOne) ? AlphaOne : lut_rd_q1;
    end
    t_d2 = (a1 >= One) ? '0 : One - a1;

    // Contract cases 1-4 decide here; case 5 (the sample contributes) is contrib.
    contrib_d2   = 1'b0;
    flush_geo_d2 = 1'b0;
    mark_term_d2 = 1'b0;
    if (mode_q1 == cube5_compos_pkg::ModeReserved || coxel_q1[TermBit]) begin
      // 1. passes unchanged
    end else if (mode_q1 == cube5_compos_pkg::ModeFlush) begin
      // 2. end of the ray: geometry (if any) under the coxel
      mark_term_d2 = 1'b1;
      flush_geo_d2 = coxel_q1[ZLsb +: ZW] != ZNone;
    end else if (mode_q1 == cube5_compos_pkg::ModeFrontToBack && et_hit) begin
      // 3. early termination
      mark_term_d2 = 1'b1;
    end else begin
      // 4. hidden by the geometry, or 5. contributes
      contrib_d2 = depth_pass_q1;
    end
  end

  logic [CoxelW-1:0] coxel_q2;
  logic [2:0]        mode_q2;
  logic              contrib_q2, flush_geo_q2, mark_term_q2;
  logic [CorrW-1:0]  a_corr_q2;
  logic [ChanW-1:0]  t_q2;
  logic [3*VW-1:0]   c_p_q2, g_p_q2;

  always_ff @(posedge clk_i) begin
    if (ready_2) begin
      coxel_q2     <= coxel_q1;
      mode_q2      <= mode_q1;
      contrib_q2   <= contrib_d2;
      flush_geo_q2 <= flush_geo_d2;
      mark_term_q2 <= mark_term_d2;
      a_corr_q2    <= a_corr_d2;
      t_q2         <= t_d2;
      c_p_q2       <= c_p_d2;
      g_p_q2       <= g_p_d2;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 3, weight: w = rnd(T a, Q) <= T, the X-ray addends, the Max/Min/FirstOpaque compares
  // ---------------------------------------------------------------------------
  logic [ChanW+CorrW-1:0] ta;
  logic [ChanW-1:0]       w_d3, a_w, a2;
  logic [3*ChanW-1:0]     xadd_d3;
  logic [ChanW-1:0]       xadd_a_d3;
  logic                   win_d3;

  assign a2   = coxel_q2[ALsb +: ChanW];
  assign ta   = (ChanW+CorrW)'(t_q2) * (ChanW+CorrW)'(a_corr_q2) + ((ChanW+CorrW)'(1) << (Q - 1));
  assign w_d3 = ta[Q +: ChanW];
  assign a_w  = ChanW'(a_corr_q2) << (F - Q);

  for (genvar i = 0; i < 3; i++) begin : gen_xadd
    assign xadd_d3[i*ChanW +: ChanW] = rnd_shift(ChanW'(c_p_q2[i*VW +: VW]) << (F - P),
                                                 ctrl_q[4:1]);
  end
  assign xadd_a_d3 = rnd_shift(a_w, ctrl_q[4:1]);

  always_comb begin
    unique case (mode_q2)
      cube5_compos_pkg::ModeMax:         win_d3 = a_w > a2;
      cube5_compos_pkg::ModeMin:         win_d3 = a_w < a2;
      cube5_compos_pkg::ModeFirstOpaque: win_d3 = a_corr_q2 >= fo_q;
      default:                           win_d3 = 1'b0;
    endcase
  end

  logic [CoxelW-1:0]  coxel_q3;
  logic [2:0]         mode_q3;
  logic               contrib_q3, flush_geo_q3, mark_term_q3, win_q3;
  logic [ChanW-1:0]   t_q3, w_q3, xadd_a_q3;
  logic [CorrW-1:0]   a_corr_q3;
  logic [3*VW-1:0]    c_p_q3, g_p_q3;
  logic [3*ChanW-1:0] xadd_q3;

  always_ff @(posedge clk_i) begin
    if (ready_3) begin
      coxel_q3     <= coxel_q2;
      mode_q3      <= mode_q2;
      contrib_q3   <= contrib_q2;
      flush_geo_q3 <= flush_geo_q2;
      mark_term_q3 <= mark_term_q2;
      win_q3       <= win_d3;
      t_q3         <= t_q2;
      w_q3         <= w_d3;
      xadd_a_q3    <= xadd_a_d3;
      a_corr_q3    <= a_corr_q2;
      c_p_q3       <= c_p_q2;
      g_p_q3       <= g_p_q2;
      xadd_q3      <= xadd_d3;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 4, decision: the new A and terminated, each channel's operation and operands
  // ---------------------------------------------------------------------------
  logic [ChanW-1:0] a3, a_w3;
  logic [ChanW:0]   a_plus_w, a_plus_t, a_plus_x;
  logic [VW-1:0]    a_p3;

  assign a3       = coxel_q3[ALsb +: ChanW];
  assign a_w3     = ChanW'(a_corr_q3) << (F - Q);
  assign a_p3     = VW'(a_corr_q3) << (P - Q);
  // A + w and A + T never pass max(A, 2^F): their carries are always 0.
  assign a_plus_w = {1'b0, a3} + {1'b0, w_q3};
  assign a_plus_t = {1'b0, a3} + {1'b0, t_q3};
  assign a_plus_x = {1'b0, a3} + {1'b0, xadd_a_q3};

  logic [ChanW-1:0] a_d4;
  logic             term_d4;
  logic [1:0]       op_d4;
  logic             mul_geo, mul_lerp;   // which operands feed the multipliers

  always_comb begin
    a_d4     = a3;
    term_d4  = coxel_q3[TermBit] || mark_term_q3;
    op_d4    = OpKeep;
    mul_geo  = 1'b0;
    mul_lerp = 1'b0;
    if (flush_geo_q3) begin
      a_d4    = a_plus_t[ChanW-1:0];
      op_d4   = OpMul;
      mul_geo = 1'b1;
    end else if (contrib_q3) begin
      unique case (mode_q3)
        cube5_compos_pkg::ModeFrontToBack: begin
          a_d4    = a_plus_w[ChanW-1:0];
          term_d4 = a_plus_w[ChanW-1:0] >= et_q;
          op_d4   = OpMul;
        end
        cube5_compos_pkg::ModeBackToFront: begin
          a_d4     = a_plus_w[ChanW-1:0];
          op_d4    = OpMul;
          mul_lerp = 1'b1;
        end
        cube5_compos_pkg::ModeMax, cube5_compos_pkg::ModeMin: begin
          if (win_q3) begin
            a_d4  = a_w3;
            op_d4 = OpSet;
          end
        end
        cube5_compos_pkg::ModeXraySum: begin
          a_d4  = a_plus_x[ChanW] ? ChanMax : a_plus_x[ChanW-1:0];
          op_d4 = OpAdd;
        end
        cube5_compos_pkg::ModeFirstOpaque: begin
          if (win_q3) begin
            a_d4    = One;
            term_d4 = 1'b1;
            op_d4   = OpSet;
          end
        end
        default: ;  // Flush and Reserved never contribute
      endcase
    end
  end

  // Operands of the colour stages, per channel: multiplier u (signed) and v, or the value to
  // set or add.
  logic [3*(ChanW+1)-1:0] mul_u_d4;
  logic [3*VW-1:0]        mul_v_d4;
  logic [3*ChanW-1:0]     alt_d4;

  always_comb begin
    for (int unsigned i = 0; i < 3; i++) begin
      if (mul_lerp) begin
        // back to front: C + rnd(a_p (c_w - C), P)
        mul_u_d4[i*(ChanW+1) +: ChanW+1] = {1'b0, ChanW'(c_p_q3[i*VW +: VW]) << (F - P)}
                                           - {1'b0, coxel_q3[i*ChanW +: ChanW]};
        mul_v_d4[i*VW +: VW]             = a_p3;
      end else if (mul_geo) begin
        // flush: C + rnd(T g_p, P)
        mul_u_d4[i*(ChanW+1) +: ChanW+1] = {1'b0, t_q3};
        mul_v_d4[i*VW +: VW]             = g_p_q3[i*VW +: VW];
      end else begin
        // front to back: C + rnd(w c_p, P)
        mul_u_d4[i*(ChanW+1) +: ChanW+1] = {1'b0, w_q3};
        mul_v_d4[i*VW +: VW]             = c_p_q3[i*VW +: VW];
      end
      alt_d4[i*ChanW +: ChanW] = (op_d4 == OpAdd) ? xadd_q3[i*ChanW +: ChanW]
                                                  : ChanW'(c_p_q3[i*VW +: VW]) << (F - P);
    end
  end

  logic [3*ChanW-1:0]     rgb_q4, alt_q4;
  logic [ChanW-1:0]       a_q4;
  logic                   term_q4;
  logic [ZW+3*ColorW-1:0] zgeo_q4;
  logic [1:0]             op_q4;
  logic [3*(ChanW+1)-1:0] mul_u_q4;
  logic [3*VW-1:0]        mul_v_q4;

  always_ff @(posedge clk_i) begin
    if (ready_4) begin
      rgb_q4   <= coxel_q3[0 +: 3*ChanW];
      alt_q4   <= alt_d4;
      a_q4     <= a_d4;
      term_q4  <= term_d4;
      zgeo_q4  <= coxel_q3[ZLsb +: ZW+3*ColorW];
      op_q4    <= op_d4;
      mul_u_q4 <= mul_u_d4;
      mul_v_q4 <= mul_v_d4;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 5, colour product: u * v per channel (one signed multiplier each)
  // ---------------------------------------------------------------------------
  localparam int unsigned ProdW = ChanW + VW + 2;
  // floor(u v / 2^(P-1)): the product from its rounding bit up (the bits below cannot carry
  // into the rounded result).
  localparam int unsigned KeepW = ProdW - (P - 1);

  logic [3*KeepW-1:0] prod_d5;

  for (genvar i = 0; i < 3; i++) begin : gen_product
    logic signed [ChanW:0]   u;
    logic signed [VW:0]      v;
    logic signed [ProdW-1:0] prod;
    assign u    = $signed(mul_u_q4[i*(ChanW+1) +: ChanW+1]);
    assign v    = $signed({1'b0, mul_v_q4[i*VW +: VW]});
    assign prod = u * v;
    assign prod_d5[i*KeepW +: KeepW] = prod[P-1 +: KeepW];
    // The fraction below the rounding bit.
    if (P >= 2) begin : gen_unused_fraction
      logic unused_fraction;
      assign unused_fraction = ^prod[P-2:0];
    end
  end

  logic [3*ChanW-1:0]     rgb_q5, alt_q5;
  logic [ChanW-1:0]       a_q5;
  logic                   term_q5;
  logic [ZW+3*ColorW-1:0] zgeo_q5;
  logic [1:0]             op_q5;
  logic [3*KeepW-1:0]     prod_q5;

  always_ff @(posedge clk_i) begin
    if (ready_5) begin
      rgb_q5  <= rgb_q4;
      alt_q5  <= alt_q4;
      a_q5    <= a_q4;
      term_q5 <= term_q4;
      zgeo_q5 <= zgeo_q4;
      op_q5   <= op_q4;
      prod_q5 <= prod_d5;
    end
  end

  // ---------------------------------------------------------------------------
  // Stage 6, colour sum: C + rnd(u v, P) (the rounding bit as a carry in), saturate, select
  // ---------------------------------------------------------------------------
  logic [3*ChanW-1:0] rgb_d6;

  for (genvar i = 0; i < 3; i++) begin : gen_colour
    logic [ChanW-1:0] c_in, alt, res;
    logic [KeepW-1:0] kept;
    logic [ChanW+2:0] sum_mul;   // C + floor((u v + 2^(P-1)) / 2^P), never negative
    logic [ChanW:0]   sum_add;

    assign c_in    = rgb_q5[i*ChanW +: ChanW];
    assign alt     = alt_q5[i*ChanW +: ChanW];
    assign kept    = prod_q5[i*KeepW +: KeepW];
    assign sum_mul = {3'b000, c_in} + kept[1 +: ChanW+3] + (ChanW+3)'(kept[0]);
    assign sum_add = {1'b0, c_in} + {1'b0, alt};

    always_comb begin
      unique case (op_q5)
        OpMul:   res = (sum_mul[ChanW+2:ChanW] != 3'b000) ? ChanMax : sum_mul[ChanW-1:0];
        OpSet:   res = alt;
        OpAdd:   res = sum_add[ChanW] ? ChanMax : sum_add[ChanW-1:0];
        default: res = c_in;
      endcase
    end
    assign rgb_d6[i*ChanW +: ChanW] = res;
  end

  logic [CoxelW-1:0] coxel_q6;

  always_ff @(posedge clk_i) begin
    if (ready_6) begin
      coxel_q6 <= {term_q5, zgeo_q5, a_q5, rgb_d6};
    end
  end

  assign out_data_o  = coxel_q6;

  // Carries that are always 0 (see above) and the discarded fraction of the weight.
  logic unused_carry;
  assign unused_carry = ^{a_plus_w[ChanW], a_plus_t[ChanW], ta[ChanW+CorrW-1], ta[Q-1:0]};

`ifndef SYNTHESIS
  // A stalled output holds its item (STYLE.md rule 3).
  OutputHoldsWhileStalled: assert property (@(posedge clk_i) disable iff (!rst_ni)
      out_valid_o && !out_ready_i |=> out_valid_o && $stable(out_data_o))
    else $error("cube5_compos: output changed while stalled");
`endif

endmodule
