// gicube_cache: the block RAM it reuses, the burst reader (with its splitter), the burst writer
// (the splitter shared), then the unit.
rtl/cube5/cube5_shader_ram.sv
-f rtl/cube5/cube5_axi_rd.f
rtl/cube5/cube5_axi_wr.sv
rtl/gicube/gicube_cache.sv
