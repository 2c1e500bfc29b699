rtl/cube5/cube5_warp_pkg.sv
rtl/cube5/cube5_shader_ram.sv
rtl/cube5/cube5_compos_unorm.sv
rtl/cube5/cube5_lerp.sv
rtl/cube5/cube5_warp_sample.sv
rtl/cube5/cube5_warp.sv
