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

/// The example of the format in docs/adding-a-unit.md is a valid description.
#[test]
fn documented_example_parses() {
    let page = std::fs::read_to_string(root().join("docs/adding-a-unit.md")).unwrap();
    let section = page
        .split("## Registers and shared constants")
        .nth(1)
        .expect("section in docs/adding-a-unit.md");
    let toml = section
        .split("```toml\n")
        .nth(1)
        .and_then(|s| s.split("```").next())
        .expect("a toml example");
    let path = std::path::Path::new("rtl/cube5/cube5_x.regs.toml");
    let b = cube5_gen::regs::desc::parse(toml, path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(b.desc.register.len(), 1);
}
