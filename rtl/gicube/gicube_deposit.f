// gicube_deposit: the splatting unit's energies (no sub-units).
rtl/gicube/gicube_deposit.sv
