rtl/cube5/cube5_compos_pkg.sv
rtl/cube5/cube5_compos_unorm.sv
rtl/cube5_valid_chain.sv
rtl/cube5/cube5_compos.sv
