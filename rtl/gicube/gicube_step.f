rtl/gicube/gicube_pkg.sv
rtl/cube5_valid_chain.sv
rtl/gicube/gicube_step_div.sv
rtl/gicube/gicube_step.sv
