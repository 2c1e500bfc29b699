// cube5_er: the units' filelists (packages first in each), then the top's own files.
-f rtl/cube5/cube5_trilin.f
-f rtl/cube5/cube5_gradient.f
-f rtl/cube5/cube5_shader.f
-f rtl/cube5/cube5_compos.f
rtl/cube5/cube5_er_pkg.sv
rtl/cube5/cube5_section_buf_ram.sv
rtl/cube5/cube5_frame_fifo.sv
rtl/cube5/cube5_frame_shade.sv
rtl/cube5/cube5_er.sv
