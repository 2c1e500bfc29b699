//! The one reader of `rtl/**/<top>.variants` (the verified configurations of each top) and of
//! `<top>.f` filelists. `tb-rs/build.rs` calls it as a library; `scripts/lint.sh` and
//! `scripts/synth.sh` call `cube5-gen variants`, which prints the same list as text.
//!
//! A `.variants` line is `name [flag ...] Param=value ...` (`#` starts a comment). Flags:
//! `gate` (also build Yosys's gate-level netlist for the smoke co-simulation), `gatefull` (with
//! `gate`: that netlist is built and run only by `make sim-full`, the RTL line stays in CI),
//! `mutant` (also a
//! gate-level netlist with one injected fault, which the tests must catch), `fmax` / `fmax85`
//! (`make synth` places and routes it on the ECP5 25k / 85k part), `ooc` (with `fmax`/`fmax85`:
//! placed out of context, without I/O pads, for a unit whose ports outnumber the package's pins;
//! inside a design they are internal nets), `sim` (simulation only: left out of `make synth`),
//! `bram` (synthesized by the ECP5 flow alone), `synthfull` (synthesized only by `make synth-full`:
//! minutes of Yosys and place and route beyond CI's synthesis budget; its row of the generated
//! table in docs/measurements.md stays as the full run wrote it).
//!
//! A filelist holds one path per line, relative to the repository, `//` comments, and `-f
//! other.f` lines that include another top's filelist (a file named twice is kept once, at its
//! first place, so packages shared by sub-tops stay first).
//!
//! Variant names follow one rule (docs/adding-a-unit.md, "Naming a variant"): lowercase tokens,
//! each the initial of a parameter on the line followed by that parameter's value (`v8`:
//! VoxelW = 8; `p4m4`: P = 4, MemLatency = 4), or a word for a scheme followed optionally by one
//! parameter value (`slab`, `skew6`). [`check_name`] enforces it.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The flags a `.variants` line may carry. `full`: a configuration only the runs too long for CI
/// use (`make sim-full`); the test bench builds it only when `CUBE5_FULL=1`. `synthfull`: the
/// synthesis counterpart, a configuration `make synth` skips unless `SYNTH_FULL=1` (`make synth-full`).
/// `gatefull`: the line's gate-level netlist is `full` (minutes of Yosys, Verilator and g++ that
/// CI's test budget cannot hold; docs/ci.md), its RTL build is not.
pub const FLAGS: &[&str] = &[
    "gate",
    "gatefull",
    "mutant",
    "fmax",
    "fmax85",
    "ooc",
    "sim",
    "bram",
    "full",
    "synthfull",
];

/// Words allowed as the leading token of a variant name (schemes that no single parameter
/// initial says): the ray-bucketing schemes of `gicube_bucket`.
pub const SCHEME_WORDS: &[&str] = &["slab", "skew", "rep"];

/// One line of a `.variants` file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VariantLine {
    /// The top module (the file's stem).
    pub top: String,
    /// The configuration's name, unique within the top (`v8`).
    pub config: String,
    /// `Param=value` pairs as written, in order.
    pub params: Vec<(String, i64)>,
    pub flags: Vec<String>,
    /// Where the line is, for messages (`rtl/cube5/cube5_trilin.variants:9`).
    pub origin: String,
}

impl VariantLine {
    /// `<top>_<config>`: the name of the RTL build of this configuration.
    pub fn full_name(&self) -> String {
        format!("{}_{}", self.top, self.config)
    }

    pub fn has_flag(&self, flag: &str) -> bool {
        self.flags.iter().any(|f| f == flag)
    }
}

/// The folder (repository-relative) every RTL `` `include `` is found in: the port-list macros
/// of `cube5_axi_ports.svh`. Every tool that reads RTL gets it (`-I`: Verilator in
/// `tb-rs/build.rs` and `scripts/lint.sh`, Yosys through [`crate::yosys::prelude`]); a filelist
/// of a top that includes a header names the header too, so a change to it rebuilds that top.
pub const INCLUDE_DIR: &str = "rtl";

/// `-I<repo>/rtl`: the include folder as Verilator's and Yosys's `read_verilog` option.
pub fn include_arg(repo: &Path) -> String {
    format!("-I{}", repo.join(INCLUDE_DIR).display())
}

/// `text` (a module's source) with every line that invokes a port-list macro of `header` (the text
/// of `cube5_axi_ports.svh`, say) replaced by the port declarations it expands to, so that a reader
/// that looks for a port's declaration line (`tb-rs/build.rs` choosing a top's shim) sees it. Only
/// the prefix, the macro's first argument, is substituted (`PFX``araddr_o` -> `m_axi_araddr_o`);
/// widths stay as written. A macro inside a macro is expanded too.
pub fn expand_port_macros(text: &str, header: &str) -> String {
    // name -> (first formal, body lines)
    let mut macros: Vec<(String, String, Vec<String>)> = Vec::new();
    let mut lines = header.lines();
    while let Some(line) = lines.next() {
        let Some(rest) = line.trim_start().strip_prefix("`define ") else {
            continue;
        };
        let Some((name, formals)) = rest.split_once('(') else {
            continue;
        };
        let formal = formals.split([',', ')']).next().unwrap_or("").trim();
        let mut body = Vec::new();
        let mut more = line.trim_end().ends_with('\\');
        while more {
            let Some(b) = lines.next() else { break };
            more = b.trim_end().ends_with('\\');
            body.push(b.trim_end().trim_end_matches('\\').trim_end().to_string());
        }
        macros.push((name.trim().to_string(), formal.to_string(), body));
    }
    fn expand(line: &str, macros: &[(String, String, Vec<String>)], out: &mut String, depth: u32) {
        let call = line.trim_start().strip_prefix('`').and_then(|r| {
            let (name, args) = r.split_once('(')?;
            let m = macros.iter().find(|m| m.0 == name.trim())?;
            Some((m, args.split([',', ')']).next().unwrap_or("").trim()))
        });
        match call {
            Some(((_, formal, body), prefix)) if depth < 8 => {
                for b in body {
                    let b = b
                        .replace(&format!("{formal}``"), prefix)
                        .replace(&format!("({formal},"), &format!("({prefix},"));
                    expand(&b, macros, out, depth + 1);
                }
            }
            _ => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    let mut out = String::new();
    for line in text.lines() {
        expand(line, &macros, &mut out, 0);
    }
    out
}

/// A top with its filelist (resolved, repository-relative, packages first) and its variants.
#[derive(Debug, Clone)]
pub struct Top {
    pub name: String,
    /// `rtl/.../<top>.variants`, repository-relative.
    pub variants_file: PathBuf,
    /// `rtl/.../<top>.f`, repository-relative.
    pub filelist: PathBuf,
    /// Every RTL file, repository-relative, with `-f` includes expanded.
    pub files: Vec<PathBuf>,
    pub variants: Vec<VariantLine>,
}

/// Every top under `repo/rtl`, sorted by path. Errors name the file and line.
pub fn discover(repo: &Path) -> Result<Vec<Top>, String> {
    let mut found = Vec::new();
    let mut dirs = vec![repo.join("rtl")];
    while let Some(dir) = dirs.pop() {
        let mut entries: Vec<PathBuf> = fs::read_dir(&dir)
            .map_err(|e| format!("{}: {e}", dir.display()))?
            .flatten()
            .map(|e| e.path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "variants") {
                found.push(read_top(repo, &path)?);
            }
        }
    }
    found.sort_by(|a, b| a.variants_file.cmp(&b.variants_file));
    Ok(found)
}

/// The directories and files `discover` reads (for `cargo:rerun-if-changed`).
pub fn inputs(repo: &Path, tops: &[Top]) -> Vec<PathBuf> {
    let mut set = BTreeSet::new();
    set.insert(repo.join("rtl"));
    for t in tops {
        set.insert(repo.join(&t.variants_file));
        set.insert(repo.join(&t.filelist));
        if let Some(dir) = repo.join(&t.variants_file).parent() {
            set.insert(dir.to_path_buf());
        }
        for f in &t.files {
            set.insert(repo.join(f));
        }
    }
    set.into_iter().collect()
}

fn rel(repo: &Path, p: &Path) -> PathBuf {
    p.strip_prefix(repo).unwrap_or(p).to_path_buf()
}

fn read_top(repo: &Path, path: &Path) -> Result<Top, String> {
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let filelist = path.with_extension("f");
    let files = read_filelist(repo, &filelist)?;
    let text = fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let shown = rel(repo, path);
    let mut variants: Vec<VariantLine> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let origin = format!("{}:{}", shown.display(), i + 1);
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut words = line.split_whitespace();
        let config = words.next().unwrap_or_default().to_string();
        let mut params = Vec::new();
        let mut flags = Vec::new();
        for w in words {
            match w.split_once('=') {
                Some((k, v)) => {
                    let value: i64 = v
                        .parse()
                        .map_err(|_| format!("{origin}: {k}={v}: the value is not an integer"))?;
                    if params.iter().any(|(p, _)| p == k) {
                        return Err(format!("{origin}: parameter {k} given twice"));
                    }
                    params.push((k.to_string(), value));
                }
                None if FLAGS.contains(&w) => flags.push(w.to_string()),
                None => {
                    return Err(format!(
                        "{origin}: unknown flag `{w}` (known: {})",
                        FLAGS.join(", ")
                    ))
                }
            }
        }
        let v = VariantLine {
            top: name.clone(),
            config,
            params,
            flags,
            origin,
        };
        check_name(&v)?;
        if variants.iter().any(|o| o.config == v.config) {
            return Err(format!("{}: variant `{}` named twice", v.origin, v.config));
        }
        variants.push(v);
    }
    if variants.is_empty() {
        return Err(format!("{}: no variants", shown.display()));
    }
    Ok(Top {
        name,
        variants_file: shown,
        filelist: rel(repo, &filelist),
        files,
        variants,
    })
}

/// The files of a filelist, repository-relative, `-f` includes expanded, each file once.
pub fn read_filelist(repo: &Path, filelist: &Path) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    let mut stack = Vec::new();
    expand(repo, filelist, &mut out, &mut stack)?;
    Ok(out)
}

fn expand(
    repo: &Path,
    filelist: &Path,
    out: &mut Vec<PathBuf>,
    stack: &mut Vec<PathBuf>,
) -> Result<(), String> {
    let shown = rel(repo, filelist);
    if stack.contains(&shown) {
        return Err(format!("{}: includes itself (-f loop)", shown.display()));
    }
    stack.push(shown.clone());
    let text = fs::read_to_string(filelist).map_err(|e| format!("{}: {e}", shown.display()))?;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split("//").next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if let Some(inc) = line.strip_prefix("-f") {
            expand(repo, &repo.join(inc.trim()), out, stack)?;
            continue;
        }
        let file = PathBuf::from(line);
        if !repo.join(&file).is_file() {
            return Err(format!(
                "{}:{}: {line}: no such file",
                shown.display(),
                i + 1
            ));
        }
        if !out.contains(&file) {
            out.push(file);
        }
    }
    stack.pop();
    Ok(())
}

/// The naming rule (module comment): each token is a parameter initial and that parameter's
/// value on this line, or a scheme word optionally followed by one parameter's value.
pub fn check_name(v: &VariantLine) -> Result<(), String> {
    let bad = |why: &str| {
        Err(format!(
            "{}: variant name `{}` breaks the naming rule (docs/adding-a-unit.md, \"Naming a variant\"): {why}",
            v.origin, v.config
        ))
    };
    let name = v.config.as_str();
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit())
    {
        return bad("lowercase letters and digits only");
    }
    // Split into tokens of letters followed by digits.
    let mut tokens: Vec<(String, String)> = Vec::new();
    for c in name.chars() {
        let new_token = c.is_ascii_lowercase() && tokens.last().is_none_or(|(_, d)| !d.is_empty());
        if new_token {
            tokens.push((String::new(), String::new()));
        }
        let Some(t) = tokens.last_mut() else {
            return bad("starts with a digit");
        };
        if c.is_ascii_lowercase() {
            t.0.push(c);
        } else {
            t.1.push(c);
        }
    }
    let value_of_some_param = |digits: &str| v.params.iter().any(|(_, x)| x.to_string() == digits);
    for (i, (letters, digits)) in tokens.iter().enumerate() {
        if letters.len() == 1 {
            let ok = v.params.iter().any(|(p, x)| {
                p.to_ascii_lowercase().starts_with(letters.as_str()) && x.to_string() == *digits
            });
            if !ok {
                return bad(&format!(
                    "`{letters}{digits}` is not the initial and value of a parameter on the line"
                ));
            }
        } else if i == 0 && SCHEME_WORDS.contains(&letters.as_str()) {
            if !digits.is_empty() && !value_of_some_param(digits) {
                return bad(&format!(
                    "`{digits}` is not the value of a parameter on the line"
                ));
            }
        } else {
            return bad(&format!(
                "`{letters}` is neither a parameter initial nor a scheme word ({})",
                SCHEME_WORDS.join(", ")
            ));
        }
    }
    Ok(())
}

/// `cube5-gen variants [--repo DIR]`: one line per variant for the scripts:
/// `TOP NAME FLAGS FILES [Param=value ...]`, FLAGS comma-joined or `-`, FILES comma-joined
/// repository-relative paths (packages first).
pub fn main(args: &[String]) -> Result<(), String> {
    let mut repo = PathBuf::from(".");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--repo" => {
                repo = PathBuf::from(it.next().ok_or("--repo needs a directory")?);
            }
            other => return Err(format!("variants: unknown argument `{other}`")),
        }
    }
    for top in discover(&repo)? {
        let files: Vec<String> = top.files.iter().map(|f| f.display().to_string()).collect();
        for v in &top.variants {
            let flags = if v.flags.is_empty() {
                "-".to_string()
            } else {
                v.flags.join(",")
            };
            let params: Vec<String> = v.params.iter().map(|(k, x)| format!("{k}={x}")).collect();
            println!(
                "{} {} {} {} {}",
                top.name,
                v.config,
                flags,
                files.join(","),
                params.join(" ")
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_macros_expand_to_their_declarations() {
        let header = "`define RD(PFX, W) \\\n  output logic [(W)-1:0] PFX``araddr_o, \\\n  \
                      output logic PFX``arvalid_o\n`define BOTH(PFX, W) \\\n  `RD(PFX, W), \\\n  \
                      input logic PFX``bvalid_i\n";
        let text = "module m (\n  input logic clk_i,\n  `BOTH(m_axi_, 32)\n);\n";
        let got = expand_port_macros(text, header);
        assert!(
            got.contains("  output logic [(W)-1:0] m_axi_araddr_o,\n"),
            "{got}"
        );
        assert!(got.contains("output logic m_axi_arvalid_o"), "{got}");
        assert!(got.contains("input logic m_axi_bvalid_i"), "{got}");
        assert!(!got.contains('`'), "{got}");
        let real = include_str!("../../../rtl/cube5_axi_ports.svh");
        let got = expand_port_macros("  `CUBE5_AXI4_MGR_PORTS(m_axi_, AddrW, DataW, IdW)\n", real);
        assert_eq!(got.lines().count(), 29, "{got}");
        assert!(
            got.contains("output logic                  m_axi_bready_o"),
            "{got}"
        );
        let got = expand_port_macros("  `CUBE5_AXIL_SUB_PORTS(s_axil_, 10),\n", real);
        assert_eq!(got.lines().count(), 17, "{got}");
        assert!(
            got.contains("input  logic                  s_axil_awvalid_i,"),
            "{got}"
        );
    }

    fn line(config: &str, params: &[(&str, i64)]) -> VariantLine {
        VariantLine {
            top: "t".into(),
            config: config.into(),
            params: params.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            flags: vec![],
            origin: "t.variants:1".into(),
        }
    }

    #[test]
    fn names_follow_the_rule() {
        assert!(check_name(&line("v8", &[("VoxelW", 8)])).is_ok());
        assert!(check_name(&line("p4m4", &[("P", 4), ("MemLatency", 4)])).is_ok());
        assert!(check_name(&line("slab", &[("Dist", 0)])).is_ok());
        assert!(check_name(&line("skew6", &[("VolBlocks", 6)])).is_ok());
        assert!(check_name(&line("v9", &[("VoxelW", 8)])).is_err());
        assert!(check_name(&line("c8", &[("VoxelW", 8)])).is_err());
        assert!(check_name(&line("Big", &[])).is_err());
        assert!(check_name(&line("wide", &[])).is_err());
    }
}
