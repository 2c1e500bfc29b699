rtl/cube5_pkg.sv
rtl/cube5/cube5_lerp.sv
rtl/cube5/cube5_lerp_pipe.sv
rtl/cube5_valid_chain.sv
rtl/cube5/cube5_trilin.sv
