rtl/gicube/gicube_scatter_pkg.sv
rtl/gicube/gicube_scatter_pipe.sv
rtl/gicube/gicube_scatter_hash.sv
rtl/gicube/gicube_scatter_rsqrt.sv
rtl/gicube/gicube_scatter_norm.sv
rtl/gicube/gicube_scatter_trig.sv
rtl/gicube/gicube_scatter.sv
