rtl/cube5/cube5_skewmem_pkg.sv
rtl/cube5/cube5_skewmem_bank.sv
rtl/cube5/cube5_skewmem.sv
