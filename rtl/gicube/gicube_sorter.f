rtl/gicube/gicube_pkg.sv
rtl/gicube/gicube_sorter.sv
