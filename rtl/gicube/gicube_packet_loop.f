rtl/gicube/gicube_pkg.sv
rtl/cube5_valid_chain.sv
rtl/cube5_pipe_reg.sv
rtl/gicube/gicube_packet_loop.sv
