rtl/cube5/cube5_gradient_pkg.sv
rtl/cube5_valid_chain.sv
rtl/cube5/cube5_sepconv.sv
