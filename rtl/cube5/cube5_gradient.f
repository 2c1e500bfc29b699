rtl/cube5_pkg.sv
rtl/cube5/cube5_gradient_pkg.sv
rtl/cube5/cube5_gradient_lerp.sv
rtl/cube5_valid_chain.sv
rtl/cube5/cube5_gradient.sv
