rtl/cube5_axi_ports.svh
rtl/cube5/cube5_axi_split.sv
rtl/cube5/cube5_axi_wr.sv
