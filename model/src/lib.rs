//! cube5 golden model: a bit-accurate Rust model of every cube5 RTL unit, written from the numeric
//! contract in `docs/numerics.md`, plus f64 reference renderers to measure error against.
//!
//! Pure Rust: builds and tests with no Verilator and no C++ compiler.
//!
//! Layering, bottom up: `bits`, `error`, `unit` (the stream trait every unit implements);
//! `regmap` (the register-map types) and `regs` (the generated maps); `volume`, `transfer`,
//! `camera`; `units` (one module per RTL top, named as the top);
//! `phantom`, `volume_io`, `scene`, `render` (scenes, files and renderers that use the units);
//! `scene_render` (what `cube5 render` runs: a scene on the frame model, or a named what-if);
//! `slab_perspective` (a what-if: perspective approximated by parallel slabs);
//! `er_perspective` (ER-perspective: exponential regions, Bartlett ray merging, on the frame's units);
//! `scene_gi` (a scene with `[gi]`: the GI-Cube processor model, lighting and rendering passes).
//! The tradeoff sweeps are not part of the golden model: they are the `cube5-studies` crate.

pub mod accel_host;
pub mod bits;
pub mod camera;
pub mod er_perspective;
pub mod error;
pub mod geometry;
pub mod phantom;
pub mod prefilter;
pub mod regmap;
pub mod regs;
pub mod render;
pub mod scene;
pub mod scene_elab;
pub mod scene_gi;
pub mod scene_render;
pub mod slab_perspective;
pub mod transfer;
pub mod unit;
pub mod units;
pub mod volume;
pub mod volume_io;

pub use error::{ModelError, Result};

/// The repository this crate was built from (`docs/`, `rtl/`, `scenes/`): for the tests and tools
/// that read the repository's own files.
pub fn repo_root() -> std::path::PathBuf {
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    here.parent().unwrap_or(here).to_path_buf()
}
