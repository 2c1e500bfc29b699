// cube5_section_buf: its package, the bank RAM, then the unit.
rtl/cube5/cube5_section_buf_pkg.sv
rtl/cube5/cube5_section_buf_ram.sv
rtl/cube5/cube5_section_buf.sv
