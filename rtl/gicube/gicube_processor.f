// gicube_processor: the reused units' filelists (packages first in each), then its own files.
-f rtl/gicube/gicube_queue_front.f
-f rtl/gicube/gicube_sample.f
-f rtl/gicube/gicube_cache.f
-f rtl/gicube/gicube_scatter.f
rtl/gicube/gicube_ring_pkg.sv
rtl/gicube/gicube_step_div.sv
rtl/gicube/gicube_step.sv
rtl/gicube/gicube_deposit.sv
rtl/cube5/cube5_frame_fifo.sv
rtl/gicube/gicube_processor.sv
