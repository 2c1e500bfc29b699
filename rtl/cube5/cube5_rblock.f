rtl/cube5_valid_chain.sv
rtl/cube5_pipe_reg.sv
rtl/cube5/cube5_rblock.sv
