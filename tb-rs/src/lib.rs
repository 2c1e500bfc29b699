//! cube5 co-simulation test bench: Verilator-compiled RTL driven from Rust and compared bit for bit
//! with the golden model (`cube5_model`).

pub mod ffi;
pub mod frame;
pub mod harness;
pub mod rtl;

pub use harness::{check_stream, Mismatch, StreamCheck, StreamReport};
pub use rtl::{RtlError, RtlStream};
