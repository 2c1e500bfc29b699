// gicube_ring: the processor's filelist (packages first), then the ring.
-f rtl/gicube/gicube_processor.f
rtl/gicube/gicube_ring.sv
