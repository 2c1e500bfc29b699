// gicube_sample: the reused units' filelists (packages first in each), then its own files.
-f rtl/cube5/cube5_trilin.f
-f rtl/cube5/cube5_shader.f
-f rtl/cube5/cube5_compos.f
rtl/gicube/gicube_sample_pkg.sv
rtl/gicube/gicube_sample.sv
