rtl/cube5/cube5_rblock.sv
