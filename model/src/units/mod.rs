//! The golden model of every RTL top: one file per top, named exactly as the top
//! (`rtl/cube5/cube5_trilin.sv` is modelled in `units/cube5_trilin.rs`), each written from its
//! contract page in `docs/numerics/`. The table in `docs/architecture.md` ("Where is each top")
//! lists RTL, model, contract, test and bench of each.
//!
//! Slice-order (Cube-5) units first, then the GI-Cube block processor's (patent [25]-[29],
//! [346]-[392]).

pub mod cube5_accel;
pub mod cube5_accel_ctrl;
pub mod cube5_axi_rd;
pub mod cube5_axi_wr;
pub mod cube5_axil;
pub mod cube5_compos;
pub mod cube5_er;
pub mod cube5_frame;
pub mod cube5_gradient;
pub mod cube5_pwarp;
pub mod cube5_rblock;
pub mod cube5_section_buf;
pub mod cube5_sepconv;
pub mod cube5_shader;
pub mod cube5_skewmem;
pub mod cube5_trilin;
pub mod cube5_vol_fetch;
pub mod cube5_warp;
pub mod gicube_bucket;
pub mod gicube_cache;
pub mod gicube_deposit;
pub mod gicube_packet_loop;
pub mod gicube_processor;
pub mod gicube_queue_front;
pub mod gicube_ray_queues;
pub mod gicube_ring;
pub mod gicube_sample;
pub mod gicube_scatter;
pub mod gicube_sorter;
pub mod gicube_step;
