//! Build-time tools of cube5, pure Rust (serde and toml only, for the register descriptions) so
//! that `tb-rs/build.rs` and the scripts share them: the one reader of `rtl/**/<top>.variants`
//! and `<top>.f` filelists ([`variants`]), and the generator of register maps and shared constants ([`regs`]).

pub mod regs;
pub mod variants;
pub mod yosys;
