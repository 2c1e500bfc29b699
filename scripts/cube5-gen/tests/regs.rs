//! The generated register maps and constants in the repository match their descriptions
//! (`rtl/**/*.regs.toml`): `cargo test` fails on a stale file; `make regs` rewrites them.

use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn generated_files_are_current() {
    let root = root();
    let stale = cube5_gen::regs::check(&root).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        stale.is_empty(),
        "stale generated files (run `make regs`): {}",
        stale
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
}

#[test]
fn every_description_found() {
    let found = cube5_gen::regs::descriptions(&root()).unwrap_or_else(|e| panic!("{e}"));
    for want in [
        "rtl/cube5/cube5_compos.regs.toml",
        "rtl/cube5/cube5_frame.regs.toml",
    ] {
        assert!(
            found.iter().any(|p| p == std::path::Path::new(want)),
            "{want} not found in {found:?}"
        );
    }
}
