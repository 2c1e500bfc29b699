// cube5_accel: the sub-tops' filelists (each brings its packages first), then the top.
-f rtl/cube5/cube5_accel_ctrl.f
-f rtl/cube5/cube5_vol_fetch.f
-f rtl/cube5/cube5_section_buf.f
-f rtl/cube5/cube5_frame.f
-f rtl/cube5/cube5_axi_wr.f
rtl/cube5/cube5_axi_arb.sv
rtl/cube5/cube5_axi_slice.sv
rtl/cube5/cube5_accel_pix.sv
rtl/cube5/cube5_accel_win.sv
rtl/cube5/cube5_accel.sv
