//! Verilates every RTL variant named in `rtl/**/*.variants` (the one list of verified
//! configurations), compiles each with the stream shim in `tb/`, and binds them with cxx.
//!
//! Each variant is cached in OUT_DIR under a hash of everything that feeds it (RTL files,
//! parameters, shim headers, tool versions), so touching one unit rebuilds only that unit.
//! `CUBE5_TOPS=top[,top...]` restricts the build to some tops (for quick iteration on one unit);
//! CI and `make test` leave it unset and build everything.

use sha2::{Digest, Sha256};
use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Bumped when the way a variant is built changes, to invalidate every cached object.
const RECIPE: &str = "cube5-variant-recipe-7";

/// Verilator flags for RTL variants (TOOLCHAIN.md; `--x-initial unique` so randReset(2) applies).
const VERILATE_FLAGS: &[&str] = &[
    "--cc",
    "--no-timing",
    "-O3",
    "--x-assign",
    "fast",
    "--x-initial",
    "unique",
    "--trace",
    "--assert",
];

/// Extra Verilator flags for gate-level netlists: `-O0`, because Verilator 5.006's optimisations
/// mis-simulate some of Yosys's flat netlists. The Yosys script's `splitnets` is the other half of
/// that workaround (docs/architecture.md, RTL conventions).
const GATE_VERILATE_FLAGS: &[&str] = &["-Wno-fatal", "-Wno-lint", "-Wno-style", "-O0"];

/// Yosys fails on the warnings that signal a wrong netlist (TOOLCHAIN.md).
const YOSYS_FATAL: &str = "implicitly declared|Resizing cell port|out of bounds";

/// C++ flags from verilated.mk plus an explicit optimisation level.
const CXX_FLAGS: &[&str] = &[
    "-std=c++17",
    "-O2",
    "-faligned-new",
    "-fcf-protection=none",
    "-DVM_COVERAGE=0",
    "-DVM_SC=0",
    "-DVM_TRACE=1",
    "-DVM_TRACE_FST=0",
    "-DVM_TRACE_VCD=1",
    "-w",
];

#[derive(Debug, Clone)]
struct Variant {
    top: String,
    /// `<top>_<config>` or `<top>_<config>_gate`.
    full_name: String,
    params: Vec<(String, String)>,
    files: Vec<PathBuf>,
    gate: bool,
}

struct Built {
    full_name: String,
    object: PathBuf,
}

fn main() {
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());
    let repo = manifest.parent().unwrap().to_path_buf();
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let tb = repo.join("tb");
    let vlt = repo.join("rtl/lint/verilator.vlt");

    println!("cargo:rerun-if-env-changed=CUBE5_TOPS");
    println!("cargo:rerun-if-changed=src/ffi.rs");
    for f in [
        "dut_core.h",
        "stream_shim.h",
        "stream_dut.h",
        "stream_dut.cpp",
    ] {
        println!("cargo:rerun-if-changed={}", tb.join(f).display());
    }
    println!("cargo:rerun-if-changed={}", vlt.display());

    let verilator_root = tool_output("verilator", &["--getenv", "VERILATOR_ROOT"]);
    let verilator_version = tool_output("verilator", &["--version"]);
    let yosys_version = tool_output("yosys", &["-V"]);
    let vl_include = PathBuf::from(verilator_root.trim()).join("include");

    let variants = discover_variants(&repo);
    let only: Option<Vec<String>> = env::var("CUBE5_TOPS")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.split(',').map(|t| t.trim().to_string()).collect());
    let selected: Vec<Variant> = variants
        .into_iter()
        .filter(|v| {
            only.as_ref()
                .is_none_or(|o| o.iter().any(|t| *t == v.top || *t == v.full_name))
        })
        .collect();

    let shim_text: String = ["dut_core.h", "stream_shim.h"]
        .iter()
        .map(|f| fs::read_to_string(tb.join(f)).unwrap())
        .collect();
    let vlt_text = fs::read_to_string(&vlt).unwrap();

    // Runtime objects, shared by every variant.
    let runtime = build_runtime(&out, &vl_include, &verilator_version);

    // Variants, two at a time (the machine has two cores; cargo's NUM_JOBS says how many).
    let jobs: usize = env::var("NUM_JOBS")
        .ok()
        .and_then(|j| j.parse().ok())
        .unwrap_or(2)
        .max(1);
    let next = AtomicUsize::new(0);
    let built = Mutex::new(Vec::new());
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(selected.len().max(1)) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(v) = selected.get(i) else { break };
                let stamp = variant_stamp(
                    v,
                    &[&verilator_version, &yosys_version, &shim_text, &vlt_text],
                );
                match build_variant(v, &out, &tb, &vl_include, &vlt, &stamp) {
                    Ok(obj) => built.lock().unwrap().push(Built {
                        full_name: v.full_name.clone(),
                        object: obj,
                    }),
                    Err(e) => failures
                        .lock()
                        .unwrap()
                        .push(format!("{}: {e}", v.full_name)),
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    if !failures.is_empty() {
        panic!("RTL variants failed to build:\n{}", failures.join("\n"));
    }
    let mut built = built.into_inner().unwrap();
    built.sort_by(|a, b| a.full_name.cmp(&b.full_name));

    let factory = out.join("duts.cpp");
    write_if_changed(&factory, &factory_source(&built));

    let mut bridge = cxx_build::bridge("src/ffi.rs");
    bridge
        .file(tb.join("stream_dut.cpp"))
        .file(&factory)
        .include(&tb)
        .include(&vl_include)
        .flag("-std=c++17")
        .opt_level(2);
    for o in runtime.iter().chain(built.iter().map(|b| &b.object)) {
        bridge.object(o);
    }
    bridge.compile("cube5_tb_duts");
    println!("cargo:rustc-link-lib=pthread");
    println!("cargo:rustc-link-lib=atomic");
}

fn tool_output(tool: &str, args: &[&str]) -> String {
    let out = Command::new(tool).args(args).output().unwrap_or_else(|e| {
        panic!("cannot run `{tool}` ({e}): install it with `make setup` (Verilator and Yosys from apt)")
    });
    assert!(out.status.success(), "`{tool} {}` failed", args.join(" "));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Every `rtl/**/<top>.variants` with its filelist `<top>.f` beside it.
fn discover_variants(repo: &Path) -> Vec<Variant> {
    let rtl = repo.join("rtl");
    println!("cargo:rerun-if-changed={}", rtl.display());
    let mut found = Vec::new();
    let mut dirs = vec![rtl];
    while let Some(dir) = dirs.pop() {
        println!("cargo:rerun-if-changed={}", dir.display());
        let mut entries: Vec<_> = fs::read_dir(&dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "variants") {
                found.extend(parse_variants(repo, &path));
            }
        }
    }
    found
}

fn parse_variants(repo: &Path, path: &Path) -> Vec<Variant> {
    println!("cargo:rerun-if-changed={}", path.display());
    let top = path.file_stem().unwrap().to_string_lossy().into_owned();
    let filelist = path.with_extension("f");
    println!("cargo:rerun-if-changed={}", filelist.display());
    let files: Vec<PathBuf> = fs::read_to_string(&filelist)
        .unwrap_or_else(|e| panic!("{}: {e}", filelist.display()))
        .lines()
        .map(|l| l.split("//").next().unwrap().trim())
        .filter(|l| !l.is_empty())
        .map(|l| repo.join(l))
        .collect();
    for f in &files {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    let mut out = Vec::new();
    for line in fs::read_to_string(path).unwrap().lines() {
        let line = line.split('#').next().unwrap().trim();
        if line.is_empty() {
            continue;
        }
        let mut words = line.split_whitespace();
        let name = words.next().unwrap();
        let mut params = Vec::new();
        let mut gate = false;
        for w in words {
            match w.split_once('=') {
                Some((k, v)) => params.push((k.to_string(), v.to_string())),
                None if w == "gate" => gate = true,
                // Read by scripts/synth.sh only.
                None if matches!(w, "fmax" | "fmax85" | "sim") => {}
                None => panic!("{}: unknown flag `{w}`", path.display()),
            }
        }
        let base = Variant {
            top: top.clone(),
            full_name: format!("{top}_{name}"),
            params,
            files: files.clone(),
            gate: false,
        };
        if gate {
            out.push(Variant {
                full_name: format!("{top}_{name}_gate"),
                gate: true,
                ..base.clone()
            });
        }
        out.push(base);
    }
    out
}

fn variant_stamp(v: &Variant, extra: &[&str]) -> String {
    let mut h = Sha256::new();
    h.update(RECIPE);
    h.update(format!("{v:?}"));
    for e in extra {
        h.update(e);
    }
    for f in &v.files {
        h.update(fs::read(f).unwrap_or_else(|e| panic!("{}: {e}", f.display())));
    }
    h.update(VERILATE_FLAGS.join(" "));
    h.update(CXX_FLAGS.join(" "));
    if v.gate {
        h.update(GATE_VERILATE_FLAGS.join(" "));
    }
    format!("{:x}", h.finalize())
}

fn run(cmd: &mut Command, what: &str) -> Result<(), String> {
    let out = cmd.output().map_err(|e| format!("{what}: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "{what} failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

fn build_variant(
    v: &Variant,
    out: &Path,
    tb: &Path,
    vl_include: &Path,
    vlt: &Path,
    stamp: &str,
) -> Result<PathBuf, String> {
    let dir = out.join("variants").join(&v.full_name);
    let object = dir.join("variant.o");
    let stamp_file = dir.join("stamp");
    if object.exists() && fs::read_to_string(&stamp_file).ok().as_deref() == Some(stamp) {
        return Ok(object);
    }
    let _ = fs::remove_dir_all(&dir); // generated names carry hashes: never reuse stale files
    let mdir = dir.join("obj");
    fs::create_dir_all(&mdir).map_err(|e| e.to_string())?;
    let prefix = format!("V{}", v.full_name);

    let mut verilate = Command::new("verilator");
    verilate
        .args(VERILATE_FLAGS)
        .arg("--top-module")
        .arg(&v.top)
        .arg("--prefix")
        .arg(&prefix)
        .arg("--Mdir")
        .arg(&mdir);
    if v.gate {
        let netlist = dir.join("netlist.v");
        let reads: Vec<String> = v.files.iter().map(|f| f.display().to_string()).collect();
        let chparam: String = v
            .params
            .iter()
            .map(|(k, val)| format!(" -set {k} {val}"))
            .collect();
        let script = format!(
            "read_verilog -sv {}; {} synth -flatten -top {}; splitnets; opt_clean; write_verilog -noattr {}",
            reads.join(" "),
            if chparam.is_empty() {
                String::new()
            } else {
                format!("chparam{chparam} {};", v.top)
            },
            v.top,
            netlist.display()
        );
        run(
            Command::new("yosys").args(["-q", "-e", YOSYS_FATAL, "-p", &script]),
            "yosys",
        )?;
        verilate.args(GATE_VERILATE_FLAGS).arg(&netlist);
    } else {
        verilate.arg("-Wall").arg(vlt);
        for (k, val) in &v.params {
            verilate.arg(format!("-G{k}={val}"));
        }
        verilate.args(&v.files);
    }
    run(&mut verilate, "verilator")?;

    let header = fs::read_to_string(mdir.join(format!("{prefix}.h"))).map_err(|e| e.to_string())?;
    let in_bits = port_width(&header, "in_data_i")?;
    let out_bits = port_width(&header, "out_data_o")?;

    let mut cpps: Vec<String> = fs::read_dir(&mdir)
        .map_err(|e| e.to_string())?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".cpp"))
        .collect();
    cpps.sort();
    let mut unity = String::new();
    for c in &cpps {
        unity.push_str(&format!("#include \"{c}\"\n"));
    }
    unity.push_str(&format!(
        "#include \"stream_shim.h\"\nnamespace cube5 {{\nDutCore* make_{name}(uint32_t seed) {{\n  \
         return new StreamShim<{prefix}>(seed, PortWidths{{{in_bits}, {out_bits}}});\n}}\n}}\n",
        name = v.full_name
    ));
    let unity_path = dir.join("unity.cpp");
    fs::write(&unity_path, unity).map_err(|e| e.to_string())?;

    let compiler = cc::Build::new().cpp(true).get_compiler();
    run(
        Command::new(compiler.path())
            .args(CXX_FLAGS)
            .arg("-I")
            .arg(vl_include)
            .arg("-I")
            .arg(vl_include.join("vltstd"))
            .arg("-I")
            .arg(&mdir)
            .arg("-I")
            .arg(tb)
            .arg("-c")
            .arg(&unity_path)
            .arg("-o")
            .arg(&object),
        "c++",
    )?;
    fs::write(&stamp_file, stamp).map_err(|e| e.to_string())?;
    Ok(object)
}

/// The bit width of a port from Verilator's header: `VL_IN*(&name,MSB,LSB...)` declarations.
fn port_width(header: &str, port: &str) -> Result<u32, String> {
    let needle = format!("(&{port},");
    let at = header
        .find(&needle)
        .ok_or_else(|| format!("port {port} not found in the Verilated header"))?;
    let rest = &header[at + needle.len()..];
    let msb: u32 = rest
        .split(',')
        .next()
        .and_then(|m| m.trim().parse().ok())
        .ok_or_else(|| format!("cannot read the width of {port}"))?;
    Ok(msb + 1)
}

fn build_runtime(out: &Path, vl_include: &Path, version: &str) -> Vec<PathBuf> {
    let dir = out.join("verilated-runtime");
    let stamp_file = dir.join("stamp");
    let sources = [
        "verilated.cpp",
        "verilated_threads.cpp",
        "verilated_vcd_c.cpp",
    ];
    let objects: Vec<PathBuf> = sources
        .iter()
        .map(|s| dir.join(s.replace(".cpp", ".o")))
        .collect();
    let stamp = format!("{RECIPE}{version}{}", CXX_FLAGS.join(" "));
    if objects.iter().all(|o| o.exists())
        && fs::read_to_string(&stamp_file).ok().as_deref() == Some(stamp.as_str())
    {
        return objects;
    }
    fs::create_dir_all(&dir).unwrap();
    let compiler = cc::Build::new().cpp(true).get_compiler();
    for (src, obj) in sources.iter().zip(&objects) {
        run(
            Command::new(compiler.path())
                .args(CXX_FLAGS)
                .arg("-I")
                .arg(vl_include)
                .arg("-I")
                .arg(vl_include.join("vltstd"))
                .arg("-c")
                .arg(vl_include.join(src))
                .arg("-o")
                .arg(obj),
            "c++ (Verilator runtime)",
        )
        .unwrap_or_else(|e| panic!("{e}"));
    }
    fs::write(&stamp_file, stamp).unwrap();
    objects
}

fn factory_source(built: &[Built]) -> String {
    let mut s = String::from(
        "// Generated by tb-rs/build.rs from rtl/**/*.variants. Do not edit.\n\
         #include \"stream_dut.h\"\n#include \"cube5-tb/src/ffi.rs.h\"\n#include <string>\n\
         namespace cube5 {\n",
    );
    for b in built {
        s.push_str(&format!("DutCore* make_{}(uint32_t seed);\n", b.full_name));
    }
    s.push_str(
        "std::unique_ptr<StreamDut> new_stream_dut(rust::Str name, uint32_t seed) {\n  \
         const std::string n(name);\n  DutCore* core = nullptr;\n  (void)seed;\n",
    );
    for b in built {
        s.push_str(&format!(
            "  if (n == \"{0}\") core = make_{0}(seed);\n",
            b.full_name
        ));
    }
    s.push_str(
        "  if (!core) return nullptr;\n  return std::make_unique<StreamDut>(std::unique_ptr<DutCore>(core));\n}\n\
         rust::Vec<rust::String> built_variants() {\n  rust::Vec<rust::String> v;\n",
    );
    for b in built {
        s.push_str(&format!(
            "  v.push_back(rust::String(\"{}\"));\n",
            b.full_name
        ));
    }
    s.push_str("  return v;\n}\n}  // namespace cube5\n");
    s
}

fn write_if_changed(path: &Path, text: &str) {
    if fs::read_to_string(path).ok().as_deref() != Some(text) {
        fs::write(path, text).unwrap();
    }
}
