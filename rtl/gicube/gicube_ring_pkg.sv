// A ring of GI-Cube processors (docs/numerics/gicube_ring.md): the constants and the slab owner
// that gicube_processor's neighbour ports and gicube_ring share. A package of its own so that the
// units that import gicube_pkg alone do not change with the ring.
package gicube_ring_pkg;

  /// Counts per processor a ring reports (rays_in ... cache_misses, nb_in, nb_out).
  localparam int unsigned RingCounts = 10;

  /// The processor that owns the block of integer x coordinate ix: slabs of `slab` blocks of
  /// 2^block_log2 voxels along x, `procs` (1..4) processors; floor((ix >> block_log2) / slab).
  function automatic logic [1:0] ring_owner(logic [gicube_pkg::PosIntW-1:0] ix,
                                            int unsigned block_log2, int unsigned slab,
                                            int unsigned procs);
    ring_owner = 2'd0;
    for (int unsigned k = 1; k < 4; k++) begin
      if (k < procs && 32'(ix) >= ((k * slab) << block_log2)) begin
        ring_owner = ring_owner + 2'd1;
      end
    end
  endfunction

endpackage
