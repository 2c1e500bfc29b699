rtl/cube5/cube5_shader_pkg.sv
rtl/cube5/cube5_shader_ram.sv
rtl/cube5/cube5_shader_ram2.sv
rtl/cube5/cube5_shader_lerp.sv
rtl/cube5_valid_chain.sv
rtl/cube5_delay_regs.sv
rtl/cube5/cube5_shader.sv
