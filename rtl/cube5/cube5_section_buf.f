// cube5_section_buf: the fetch's package (its item format), its own package, the bank RAMs (cube5_section_buf_ram, cube5_section_buf_eram), the unit.
rtl/cube5/cube5_vol_fetch_pkg.sv
rtl/cube5/cube5_section_buf_pkg.sv
rtl/cube5/cube5_section_buf_ram.sv
rtl/cube5/cube5_section_buf_eram.sv
rtl/cube5/cube5_section_buf.sv
