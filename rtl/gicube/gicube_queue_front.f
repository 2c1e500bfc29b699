rtl/gicube/gicube_pkg.sv
rtl/cube5_valid_chain.sv
rtl/cube5_pipe_reg.sv
rtl/cube5/cube5_shader_ram.sv
rtl/gicube/gicube_bucket.sv
rtl/gicube/gicube_ray_queues.sv
rtl/gicube/gicube_sorter.sv
rtl/gicube/gicube_queue_front.sv
