rtl/cube5_axi_ports.svh
rtl/cube5/cube5_accel_regs_pkg.sv
rtl/cube5/cube5_axil_regs_pkg.sv
rtl/cube5/cube5_axil_regs.sv
rtl/cube5/cube5_axil.sv
