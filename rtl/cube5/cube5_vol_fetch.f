// cube5_vol_fetch: its package, the burst reader and the tag FIFO it instantiates, then the unit.
rtl/cube5/cube5_vol_fetch_pkg.sv
-f rtl/cube5/cube5_axi_rd.f
rtl/cube5/cube5_frame_fifo.sv
rtl/cube5/cube5_vol_fetch.sv
