//! Register maps and shared constants, generated from one description into the SV package, the
//! Rust constants and the docs table (being written).

/// `cube5-gen regs ...`.
pub fn main(_args: &[String]) -> Result<(), String> {
    Err("regs: not written yet".into())
}
