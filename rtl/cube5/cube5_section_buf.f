// cube5_section_buf: the fetch's package (its item format), its own package, the bank RAM (cube5_section_buf_ram), the unit.
rtl/cube5/cube5_vol_fetch_pkg.sv
rtl/cube5/cube5_section_buf_pkg.sv
rtl/cube5/cube5_section_buf_ram.sv
rtl/cube5/cube5_section_buf.sv
