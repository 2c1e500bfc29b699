//! The Yosys commands every flow starts with, written once for `tb-rs/build.rs` (gate-level
//! netlists) and `scripts/synth.sh` (cell counts, place and route).

use std::path::{Path, PathBuf};

/// Yosys fails on the warnings that signal a wrong netlist (docs/toolchain.md).
pub const FATAL_WARNINGS: &str = "implicitly declared|Resizing cell port|out of bounds";

/// `read_verilog -sv -I<repo>/rtl FILES; chparam -set K V ... TOP;` for one configuration of
/// `top` (the include folder: [`crate::variants::INCLUDE_DIR`]).
pub fn prelude(repo: &Path, files: &[PathBuf], top: &str, params: &[(String, i64)]) -> String {
    let files: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    let mut s = format!(
        "read_verilog -sv {} {};",
        crate::variants::include_arg(repo),
        files.join(" ")
    );
    if !params.is_empty() {
        s.push_str(" chparam");
        for (k, v) in params {
            s.push_str(&format!(" -set {k} {v}"));
        }
        s.push_str(&format!(" {top};"));
    }
    s
}

/// `cube5-gen yosys TOP CONFIG [--repo DIR]`: prints the prelude; `cube5-gen yosys --fatal`
/// prints the pattern for `yosys -e`.
pub fn main(args: &[String]) -> Result<(), String> {
    let mut repo = PathBuf::from(".");
    let mut pos = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--repo" => repo = it.next().ok_or("--repo needs a directory")?.into(),
            "--fatal" => {
                println!("{FATAL_WARNINGS}");
                return Ok(());
            }
            _ => pos.push(a.clone()),
        }
    }
    let [top_name, config] = pos.as_slice() else {
        return Err("usage: cube5-gen yosys TOP CONFIG | cube5-gen yosys --fatal".into());
    };
    let tops = crate::variants::discover(&repo)?;
    let top = tops
        .iter()
        .find(|t| &t.name == top_name)
        .ok_or_else(|| format!("yosys: no top `{top_name}` in rtl/**/*.variants"))?;
    let line = top
        .variants
        .iter()
        .find(|v| &v.config == config)
        .ok_or_else(|| format!("yosys: {top_name} has no variant `{config}`"))?;
    let files: Vec<PathBuf> = top.files.iter().map(|f| repo.join(f)).collect();
    println!("{}", prelude(&repo, &files, &top.name, &line.params));
    Ok(())
}
