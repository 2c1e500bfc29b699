rtl/gicube/gicube_pkg.sv
rtl/gicube/gicube_packet_loop.sv
