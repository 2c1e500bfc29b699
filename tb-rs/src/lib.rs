//! cube5 co-simulation test bench: Verilator-compiled RTL driven from Rust and compared bit for bit
//! with the golden model (`cube5_model`).
//!
//! - [`variants`]: the generated table of every verified configuration (`rtl/**/*.variants`);
//!   a DUT is opened from a `&Variant`, never from a name.
//! - [`rtl`]: one Verilated streaming top behind the model's `StreamUnit` trait.
//! - [`harness`]: the scoreboard (`check_stream`, `must_match`) and the run presets.
//! - [`frame`]: driving `cube5_frame` against the frame model, pixel by pixel.
//! - [`er`]: driving `cube5_er` (ER-Perspective) against `ErJob::render`, coxel by coxel.
//! - [`accel`]: the accelerator top `cube5_accel` driven as a host would, image compared in memory.
//! - [`frame_stream`]: `cube5_frame` fed by a beat stream in sections (`Source = 1`).
//! - [`prefilter`]: the 3-pass pre-filter over a volume through `cube5_sepconv`.
//! - [`error`]: the one error type, `TbError` (`Setup | Protocol | Deadlock | Mismatch`).

pub mod accel;
pub mod axil;
pub mod er;
pub mod error;
pub mod ffi;
pub mod frame;
pub mod frame_stream;
pub mod harness;
pub mod prefilter;
pub mod rtl;
pub mod variants;

pub use error::{Mismatch, TbError};
pub use harness::{check_stream, must_match, StreamCheck, StreamReport};
pub use rtl::RtlStream;
pub use variants::{gate_variants_of, variants_of, Variant, VARIANTS};
