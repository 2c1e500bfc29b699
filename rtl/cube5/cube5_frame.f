// cube5_frame: the sub-tops' filelists (packages first in each), then the frame's own files.
-f rtl/cube5/cube5_skewmem.f
-f rtl/cube5/cube5_trilin.f
-f rtl/cube5/cube5_gradient.f
-f rtl/cube5/cube5_shader.f
-f rtl/cube5/cube5_compos.f
rtl/cube5/cube5_frame_pkg.sv
rtl/cube5/cube5_frame_delay.sv
rtl/cube5/cube5_frame_fifo.sv
rtl/cube5/cube5_axi_slice.sv
rtl/cube5/cube5_frame_pos.sv
rtl/cube5/cube5_frame_agen.sv
rtl/cube5/cube5_frame_vwin.sv
rtl/cube5/cube5_frame_interp.sv
rtl/cube5/cube5_frame_swin.sv
rtl/cube5/cube5_frame_shade.sv
rtl/cube5/cube5_frame_class.sv
rtl/cube5/cube5_frame_cbuf.sv
rtl/cube5/cube5_frame_win.sv
rtl/cube5/cube5_frame.sv
