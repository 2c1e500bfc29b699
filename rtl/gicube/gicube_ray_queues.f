rtl/gicube/gicube_pkg.sv
rtl/cube5/cube5_shader_ram.sv
rtl/gicube/gicube_ray_queues.sv
