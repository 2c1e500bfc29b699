//! cube5 golden model: a bit-accurate Rust model of every cube5 RTL unit, written from the numeric
//! contract in `docs/numerics.md`, plus f64 reference renderers to measure error against.
//!
//! Pure Rust: builds and tests with no Verilator and no C++ compiler.

pub mod bits;
pub mod blocking;
pub mod camera;
pub mod compos;
pub mod error;
pub mod frame;
pub mod gicube;
pub mod gradient;
pub mod phantom;
pub mod regs;
pub mod render;
pub mod scene;
pub mod shader;
pub mod skewed;
pub mod tradeoff;
pub mod trilin;
pub mod unit;
pub mod volume_io;

pub use error::{ModelError, Result};
