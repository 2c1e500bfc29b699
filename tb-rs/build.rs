//! Verilates every RTL variant named in `rtl/**/*.variants` (the one list of verified
//! configurations), compiles each with the stream shim in `tb/`, and binds them with cxx.
//!
//! Each variant's object is kept in a content-addressed cache outside `target/`
//! (`$CUBE5_CACHE`, else `$XDG_CACHE_HOME/cube5`, else `~/.cache/cube5`), keyed on a hash of
//! everything that feeds it (RTL files, parameters, flags, shim headers, tool versions, this
//! recipe). An unchanged variant is never compiled twice on a machine: across clones, branches and
//! `cargo clean`. Entries are built in a private temporary directory and renamed into place, so
//! two builds can share the cache. `make clean-cache` empties it.
//! `CUBE5_TOPS=entry[,entry...]` restricts the build (for quick iteration on one unit): an entry
//! is a top, a build name, or a top with parameter values (`cube5_frame:P=4`); CI and `make
//! test` leave it unset and build everything but the `full` lines (`CUBE5_FULL=1`: those too).

use sha2::{Digest, Sha256};
use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Bumped when the way a variant is built changes, to invalidate every cached object.
const RECIPE: &str = "cube5-variant-recipe-9";

/// Layout version of the cache directory (bump when the entry layout changes).
const CACHE_LAYOUT: &str = "v1";

/// Verilator flags for RTL variants (docs/toolchain.md; `--x-initial unique` so randReset(2) applies).
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

/// The gate-level netlist: Yosys's `synth -flatten` script from its `fine:` label on, without
/// `memory_map`. Memories stay memories (written as arrays, as an FPGA flow keeps them in block
/// RAM) instead of becoming flip-flops and read multiplexers that no FPGA build would contain;
/// every other cell is a gate, mapped by ABC. This halves the netlist of `cube5_frame` `s1` and
/// cuts its build from 195 s to 70 s (docs/ci.md).
const GATE_FINE: &str = "opt -fast -full; opt -full; techmap; opt -fast; abc -fast; opt -fast; \
                         hierarchy -check; check;";

/// C++ optimisation level for RTL variants, unless `CUBE5_RTL_CXX_OPT` says otherwise. `-O1`
/// compiles the large tops in half the time of `-O2` (`cube5_frame` `p8`: 52 s against 96 s) and
/// simulates about a quarter slower; `make bench` builds at `-O2` for the simulation-speed figures.
const CXX_OPT_RTL_DEFAULT: &str = "-O1";

/// The C++ level of RTL variants for this build (read once).
fn rtl_opt() -> &'static str {
    static OPT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    OPT.get_or_init(cxx_opt_rtl)
}

fn cxx_opt_rtl() -> String {
    println!("cargo:rerun-if-env-changed=CUBE5_RTL_CXX_OPT");
    match env::var("CUBE5_RTL_CXX_OPT") {
        Ok(o) if !o.trim().is_empty() => {
            let o = o.trim().to_string();
            assert!(
                matches!(o.as_str(), "-O0" | "-O1" | "-O2" | "-O3" | "-Os"),
                "CUBE5_RTL_CXX_OPT must be one of -O0, -O1, -O2, -O3, -Os (got `{o}`)"
            );
            o
        }
        _ => CXX_OPT_RTL_DEFAULT.to_string(),
    }
}

/// C++ optimisation level for gate-level netlists. Verilator's `-O0` output of a flat netlist is
/// one huge function that g++ takes 13-17 minutes to compile at `-O2`; the gate tests are short
/// smoke runs, so compile time dominates (measured in docs/ci.md).
const CXX_OPT_GATE: &str = "-O0";

/// C++ flags from verilated.mk; the optimisation level comes from `CXX_OPT_*`.
const CXX_FLAGS: &[&str] = &[
    "-std=c++17",
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
    /// The configuration's name in the `.variants` file (`v8`).
    config: String,
    /// `<top>_<config>`, `<top>_<config>_gate` or `<top>_<config>_mutant`.
    full_name: String,
    params: Vec<(String, i64)>,
    flags: Vec<String>,
    files: Vec<PathBuf>,
    gate: bool,
    /// A gate-level netlist with one fault injected by Yosys's `mutate` (an inverted cell pin):
    /// the tests require the co-simulation to catch it, which shows the gate flow can see a wrong
    /// netlist at all.
    mutant: bool,
}

struct Built {
    full_name: String,
    object: PathBuf,
    /// Seconds spent building it now; `None` when the cache already held it.
    built_secs: Option<f64>,
}

/// The content-addressed store of built objects (see the module comment).
struct Cache {
    root: PathBuf,
}

impl Cache {
    fn open(out: &Path) -> Self {
        println!("cargo:rerun-if-env-changed=CUBE5_CACHE");
        println!("cargo:rerun-if-env-changed=XDG_CACHE_HOME");
        let base = env::var_os("CUBE5_CACHE")
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                env::var_os("XDG_CACHE_HOME")
                    .filter(|s| !s.is_empty())
                    .map(|x| PathBuf::from(x).join("cube5"))
            })
            .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache/cube5")))
            // No home directory at all: fall back to the per-build directory (no sharing).
            .unwrap_or_else(|| out.join("cube5-cache"));
        let root = base.join(CACHE_LAYOUT);
        fs::create_dir_all(root.join("tmp"))
            .unwrap_or_else(|e| panic!("cannot create the build cache {}: {e}", root.display()));
        Self { root }
    }

    /// Where the entry for `kind/name` with content hash `stamp` lives once complete.
    fn entry(&self, kind: &str, name: &str, stamp: &str) -> PathBuf {
        self.root.join(kind).join(name).join(&stamp[..32])
    }

    /// Seconds the newest complete entry of `name` (any content hash) took to build, if any.
    fn last_build_secs(&self, name: &str) -> Option<f64> {
        fs::read_dir(self.root.join("variants").join(name))
            .ok()?
            .flatten()
            .filter_map(|e| {
                let marker = e.path().join(COMPLETE);
                let modified = marker.metadata().ok()?.modified().ok()?;
                let secs: f64 = fs::read_to_string(&marker).ok()?.trim().parse().ok()?;
                Some((modified, secs))
            })
            .max_by_key(|(modified, _)| *modified)
            .map(|(_, secs)| secs)
    }

    /// A private scratch directory that no other build uses.
    fn scratch(&self, name: &str) -> PathBuf {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir = self
            .root
            .join("tmp")
            .join(format!("{name}.{}.{nanos}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        dir
    }

    /// Moves a finished scratch directory into place. If another build published the same entry
    /// first, its copy wins (same inputs, same object) and ours is dropped.
    fn publish(&self, scratch: &Path, entry: &Path) -> Result<(), String> {
        fs::create_dir_all(entry.parent().unwrap()).map_err(|e| e.to_string())?;
        if fs::rename(scratch, entry).is_err() {
            let _ = fs::remove_dir_all(scratch);
            if !entry.join(COMPLETE).exists() {
                return Err(format!("cannot publish {} in the cache", entry.display()));
            }
        }
        Ok(())
    }
}

/// Written last into an entry: its presence means the entry is complete.
const COMPLETE: &str = "complete";

/// Prints which variants were built and which came from the cache, as cargo warnings (shown by
/// `make sim`), and writes the same to `target/cube5-variants.txt` with the build times.
fn report(repo: &Path, cache: &Cache, built: &[Built]) {
    let fresh: Vec<&Built> = built.iter().filter(|b| b.built_secs.is_some()).collect();
    let reused = built.len() - fresh.len();
    let mut text = format!(
        "cube5 RTL variants: {} built, {} reused from {}\n",
        fresh.len(),
        reused,
        cache.root.display()
    );
    for b in built {
        match b.built_secs {
            Some(s) => text.push_str(&format!("  built   {:<32} {s:7.1} s\n", b.full_name)),
            None => text.push_str(&format!("  reused  {}\n", b.full_name)),
        }
    }
    let _ = fs::create_dir_all(repo.join("target"));
    let _ = fs::write(repo.join("target/cube5-variants.txt"), &text);
    // Cargo replays this line while the build script is not re-run: it describes the last run.
    let names: Vec<&str> = fresh.iter().map(|b| b.full_name.as_str()).collect();
    let listed = if names.is_empty() {
        String::new()
    } else if names.len() <= 8 {
        format!(" ({})", names.join(", "))
    } else {
        format!(" ({} and {} more)", names[..8].join(", "), names.len() - 8)
    };
    println!(
        "cargo:warning=RTL variants at the last build of cube5-tb: {} built{listed}, {} reused from the cache; times in target/cube5-variants.txt",
        fresh.len(),
        reused
    );
}

fn main() {
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());
    let repo = manifest.parent().unwrap().to_path_buf();
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let tb = repo.join("tb");
    let vlt = repo.join("rtl/lint/verilator.vlt");

    println!("cargo:rerun-if-env-changed=CUBE5_TOPS");
    println!("cargo:rerun-if-env-changed=CUBE5_FULL");
    println!("cargo:rerun-if-changed=src/ffi.rs");
    for f in [
        "dut_core.h",
        "stream_shim.h",
        "clocked_top.h",
        "axi_mem.h",
        "axi_ports.h",
        "out_watch.h",
        "axi_shim.h",
        "axil_mgr.h",
        "axil_shim.h",
        "axi_wr_shim.h",
        "accel_ctrl_shim.h",
        "accel_shim.h",
        "win_host.h",
        "win_shim.h",
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

    let (tops, mut variants) = discover_variants(&repo);
    let only: Option<Vec<String>> = env::var("CUBE5_TOPS")
        .ok()
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.split(',').map(|t| t.trim().to_string()).collect());
    let full = env::var("CUBE5_FULL").is_ok_and(|v| v == "1");
    let cache = Cache::open(&out);
    // Every line's resolved top-level parameters, as Verilator elaborates them (defaults
    // included): the variant table carries them so a test can hold the model to every one.
    let mut resolved = resolve_all_params(&cache, &repo, &tops, &verilator_version);
    // `top@Param=value:...` entries: exactly that configuration, a checked-in line or a
    // generated one (scene-driven elaboration, `cube5 elaborate`).
    let only: Option<Vec<String>> = only.map(|entries| {
        entries
            .iter()
            .map(|e| {
                exact_entry(
                    e,
                    &tops,
                    &mut variants,
                    &mut resolved,
                    &cache,
                    &repo,
                    &verilator_version,
                )
            })
            .collect()
    });
    let selected: Vec<Variant> = variants
        .iter()
        .filter(|v| {
            only.as_ref()
                .is_none_or(|o| o.iter().any(|t| selects(t, v)))
        })
        // `full` lines serve only the runs too long for CI: built for `make sim-full` alone.
        .filter(|v| full || !v.flags.iter().any(|f| f == "full"))
        .cloned()
        .collect();

    let built_names: Vec<String> = selected.iter().map(|v| v.full_name.clone()).collect();
    write_if_changed(
        &out.join("variant_table.rs"),
        &variant_table_source(&variants, &resolved, &built_names),
    );

    let shim_text: String = ["dut_core.h", "stream_shim.h"]
        .iter()
        .map(|f| fs::read_to_string(tb.join(f)).unwrap())
        .collect();
    let vlt_text = fs::read_to_string(&vlt).unwrap();
    // A shim's own headers enter the stamps of its tops only, so the other tops' cached objects
    // stay valid when they change.
    let shim_headers: Vec<String> = Shim::ALL
        .iter()
        .map(|sh| {
            sh.stamp_headers()
                .iter()
                .map(|f| fs::read_to_string(tb.join(f)).unwrap())
                .collect()
        })
        .collect();

    // Runtime objects, shared by every variant.
    let runtime = build_runtime(&cache, &vl_include, &verilator_version);

    // Longest builds first (by the time the cache recorded for the same variant before; gate
    // netlists first when nothing is recorded), so both cores stay busy to the end.
    let mut selected = selected;
    let expected = |v: &Variant| {
        cache
            .last_build_secs(&v.full_name)
            .unwrap_or(if v.gate { 1e3 } else { 0.0 })
    };
    selected.sort_by(|a, b| expected(b).total_cmp(&expected(a)));

    // Variants, two at a time (the machine has two cores; cargo's NUM_JOBS says how many).
    let jobs: usize = env::var("NUM_JOBS")
        .ok()
        .and_then(|j| j.parse().ok())
        .unwrap_or(2)
        .max(1);
    let built = in_parallel(jobs, &selected, |v| {
        let own_headers = &shim_headers[Shim::of(v) as usize];
        let stamp = variant_stamp(
            v,
            &repo,
            &[
                &verilator_version,
                &yosys_version,
                &shim_text,
                &vlt_text,
                own_headers,
            ],
        );
        build_variant(v, &repo, &cache, &tb, &vl_include, &vlt, &stamp)
            .map_err(|e| format!("{}: {e}", v.full_name))
    })
    .unwrap_or_else(|failures| panic!("RTL variants failed to build:\n{}", failures.join("\n")));
    let mut built = built;
    built.sort_by(|a, b| a.full_name.cmp(&b.full_name));
    report(&repo, &cache, &built);

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

/// Every variant of every `rtl/**/<top>.variants`, read by `cube5_gen::variants` (the one reader,
/// shared with the scripts): the RTL build of each line, and its gate-level and mutant netlists
/// where the line asks for them.
fn discover_variants(repo: &Path) -> (Vec<cube5_gen::variants::Top>, Vec<Variant>) {
    let tops = cube5_gen::variants::discover(repo).unwrap_or_else(|e| panic!("{e}"));
    for p in cube5_gen::variants::inputs(repo, &tops) {
        println!("cargo:rerun-if-changed={}", p.display());
    }
    let mut out = Vec::new();
    for top in &tops {
        let files: Vec<PathBuf> = top.files.iter().map(|f| repo.join(f)).collect();
        for line in &top.variants {
            let base = Variant {
                top: top.name.clone(),
                config: line.config.clone(),
                full_name: line.full_name(),
                params: line.params.clone(),
                flags: line.flags.clone(),
                files: files.clone(),
                gate: false,
                mutant: false,
            };
            if line.has_flag("mutant") {
                out.push(Variant {
                    full_name: format!("{}_mutant", base.full_name),
                    gate: true,
                    mutant: true,
                    ..base.clone()
                });
            }
            if line.has_flag("gate") {
                // `gatefull`: the netlist alone is a `full` build (`make sim-full`).
                let mut flags = base.flags.clone();
                if line.has_flag("gatefull") {
                    flags.push("full".to_string());
                }
                out.push(Variant {
                    full_name: format!("{}_gate", base.full_name),
                    gate: true,
                    flags,
                    ..base.clone()
                });
            }
            out.push(base);
        }
    }
    (tops, out)
}

/// The cache key of a variant. Files enter by their path relative to the repository and their
/// text, never by absolute path, so every clone on the machine shares the same entries.
fn variant_stamp(v: &Variant, repo: &Path, extra: &[&str]) -> String {
    let mut h = Sha256::new();
    h.update(RECIPE);
    // Parameters enter as the text they had before they were parsed to integers, so the
    // stamps (and the cached objects) of unchanged variants stay valid.
    let params: Vec<(String, String)> = v
        .params
        .iter()
        .map(|(k, x)| (k.clone(), x.to_string()))
        .collect();
    h.update(format!(
        "{} {} {:?} gate={} mutant={}",
        v.top, v.full_name, params, v.gate, v.mutant
    ));
    for e in extra {
        h.update(e);
    }
    for f in &v.files {
        h.update(
            f.strip_prefix(repo)
                .unwrap_or(f)
                .to_string_lossy()
                .as_bytes(),
        );
        h.update(fs::read(f).unwrap_or_else(|e| panic!("{}: {e}", f.display())));
    }
    h.update(VERILATE_FLAGS.join(" "));
    h.update(CXX_FLAGS.join(" "));
    if v.gate {
        h.update(GATE_VERILATE_FLAGS.join(" "));
        h.update(CXX_OPT_GATE);
        h.update(GATE_FINE);
    } else {
        h.update(rtl_opt());
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
    repo: &Path,
    cache: &Cache,
    tb: &Path,
    vl_include: &Path,
    vlt: &Path,
    stamp: &str,
) -> Result<Built, String> {
    let entry = cache.entry("variants", &v.full_name, stamp);
    if entry.join(COMPLETE).exists() {
        return Ok(Built {
            full_name: v.full_name.clone(),
            object: entry.join("variant.o"),
            built_secs: None,
        });
    }
    let started = Instant::now();
    let dir = cache.scratch(&v.full_name);
    let result = compile_variant(v, repo, &dir, tb, vl_include, vlt, stamp);
    if let Err(e) = result {
        let _ = fs::remove_dir_all(&dir);
        return Err(e);
    }
    let secs = started.elapsed().as_secs_f64();
    // The Verilator output is only needed to compile the object; the netlist stays for debugging.
    let _ = fs::remove_dir_all(dir.join("obj"));
    fs::write(dir.join(COMPLETE), format!("{secs:.1}\n")).map_err(|e| e.to_string())?;
    cache.publish(&dir, &entry)?;
    Ok(Built {
        full_name: v.full_name.clone(),
        object: entry.join("variant.o"),
        built_secs: Some(secs),
    })
}

/// Verilates (after Yosys, for a gate-level variant) and compiles one variant into `dir`.
fn compile_variant(
    v: &Variant,
    repo: &Path,
    dir: &Path,
    tb: &Path,
    vl_include: &Path,
    vlt: &Path,
    stamp: &str,
) -> Result<(), String> {
    let object = dir.join("variant.o");
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
        // The mutant's one fault: the first of Yosys's evenly sampled inversions, fixed seed.
        let mutation = if v.mutant {
            let list = dir.join("mutation.ys");
            format!(
                " mutate -list 1 -seed 1 -mode inv -o {0}; script {0};",
                list.display()
            )
        } else {
            String::new()
        };
        let script = format!(
            "{} synth -flatten -top {} -run begin:fine; {GATE_FINE}{mutation} splitnets; opt_clean; write_verilog -noattr {}",
            cube5_gen::yosys::prelude(repo, &v.files, &v.top, &v.params),
            v.top,
            netlist.display()
        );
        run(
            Command::new("yosys").args([
                "-q",
                "-e",
                cube5_gen::yosys::FATAL_WARNINGS,
                "-p",
                &script,
            ]),
            "yosys",
        )?;
        verilate.args(GATE_VERILATE_FLAGS).arg(&netlist);
    } else {
        verilate
            .arg("-Wall")
            .arg(cube5_gen::variants::include_arg(repo))
            .arg(vlt);
        for (k, val) in &v.params {
            verilate.arg(format!("-G{k}={val}"));
        }
        verilate.args(&v.files);
    }
    run(&mut verilate, "verilator")?;

    let header = fs::read_to_string(mdir.join(format!("{prefix}.h"))).map_err(|e| e.to_string())?;
    // An AXI4-Lite top has no stream ports: its items are AxilShim's transactions and records.
    let shim = Shim::of(v);
    let (in_bits, out_bits) = if shim == Shim::Axil || shim == Shim::Accel {
        (AXIL_ITEM_BITS, AXIL_RECORD_BITS)
    } else if shim == Shim::AccelCtrl {
        (AXIL_ITEM_BITS, ACCEL_CTRL_RECORD_BITS)
    } else {
        (
            port_width(&header, "in_data_i")?,
            port_width(&header, "out_data_o")?,
        )
    };

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
    let (header, shim) = (shim.header(), shim.class());
    unity.push_str(&format!(
        "#include \"{header}\"\nnamespace cube5 {{\nDutCore* make_{name}(uint32_t seed) {{\n  \
         return new {shim}<{prefix}>(seed, PortWidths{{{in_bits}, {out_bits}}});\n}}\n}}\n",
        name = v.full_name
    ));
    let unity_path = dir.join("unity.cpp");
    fs::write(&unity_path, unity).map_err(|e| e.to_string())?;

    let compiler = cc::Build::new().cpp(true).get_compiler();
    run(
        Command::new(compiler.path())
            .args(CXX_FLAGS)
            .arg(if v.gate { CXX_OPT_GATE } else { rtl_opt() })
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
    fs::write(dir.join("stamp"), stamp).map_err(|e| e.to_string())?;
    Ok(())
}

/// The C++ shim a top runs in (tb/*_shim.h), chosen by the ports its own file declares: AXI4
/// read and write manager ports on a stream top (`m_axi_arvalid_o` and `m_axi_awvalid_o`: both
/// sides of the subordinate in the clock loop), an AXI4
/// write manager port (`m_axi_awvalid_o`, with the subordinate's write port in the clock loop),
/// an AXI4 read manager port (`m_axi_arvalid_o`, the AXI memory subordinate), an AXI4-Lite
/// subordinate port (`s_axil_awvalid_i`, an AXI4-Lite manager), or the plain streams.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Shim {
    Stream,
    Axi,
    AxiWr,
    Axil,
    AccelCtrl,
    Accel,
    Win,
    AxiRw,
}

impl Shim {
    /// In `Shim as usize` order.
    const ALL: [Shim; 8] = [
        Shim::Stream,
        Shim::Axi,
        Shim::AxiWr,
        Shim::Axil,
        Shim::AccelCtrl,
        Shim::Accel,
        Shim::Win,
        Shim::AxiRw,
    ];

    fn of(v: &Variant) -> Shim {
        // cube5_frame with the compositing window: its window streams played as DRAM.
        if v.top == "cube5_frame" && v.params.iter().any(|(k, x)| k == "Window" && *x != 0) {
            return Shim::Win;
        }
        let own = format!("{}.sv", v.top);
        let text = v
            .files
            .iter()
            .find(|f| f.file_name().is_some_and(|n| n.to_string_lossy() == own))
            .and_then(|f| fs::read_to_string(f).ok())
            .unwrap_or_default();
        // The port lists a macro of the filelist's headers (rtl/cube5_axi_ports.svh) stands for.
        let headers: String = v
            .files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "svh"))
            .filter_map(|f| fs::read_to_string(f).ok())
            .collect();
        let text = cube5_gen::variants::expand_port_macros(&text, &headers);
        // A port of the top itself: a declaration line (`input` / `output`), not an instance's
        // connection to a sub-unit's port of the same name.
        let has = |port: &str| {
            text.lines().any(|l| {
                let l = l.trim_start();
                (l.starts_with("input") || l.starts_with("output"))
                    && l.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                        .any(|w| w == port)
            })
        };
        if has("s_axil_awvalid_i") && has("m_axi_arvalid_o") {
            Shim::Accel
        } else if has("m_axi_awvalid_o") && has("m_axi_arvalid_o") {
            Shim::AxiRw
        } else if has("m_axi_awvalid_o") {
            Shim::AxiWr
        } else if has("m_axi_arvalid_o") {
            Shim::Axi
        } else if has("s_axil_awvalid_i") && has("fetch_cmd_valid_o") {
            Shim::AccelCtrl
        } else if has("s_axil_awvalid_i") {
            Shim::Axil
        } else {
            Shim::Stream
        }
    }

    fn header(self) -> &'static str {
        match self {
            Shim::Stream => "stream_shim.h",
            Shim::Axi => "axi_shim.h",
            Shim::AxiWr => "axi_wr_shim.h",
            Shim::Axil => "axil_shim.h",
            Shim::AccelCtrl => "accel_ctrl_shim.h",
            Shim::Accel => "accel_shim.h",
            Shim::Win => "win_shim.h",
            Shim::AxiRw => "axi_rw_shim.h",
        }
    }

    fn class(self) -> &'static str {
        match self {
            Shim::Stream => "StreamShim",
            Shim::Axi => "AxiShim",
            Shim::AxiWr => "AxiWrShim",
            Shim::Axil => "AxilShim",
            Shim::AccelCtrl => "AccelCtrlShim",
            Shim::Accel => "AccelShim",
            Shim::Win => "WinShim",
            Shim::AxiRw => "AxiRwShim",
        }
    }

    /// The headers beyond dut_core.h and stream_shim.h (in every stamp) that enter this shim's
    /// stamps, in the order they always have (so unchanged variants keep their stamps).
    fn stamp_headers(self) -> &'static [&'static str] {
        match self {
            Shim::Stream => &[],
            Shim::Axi => &[
                "clocked_top.h",
                "axi_mem.h",
                "axi_ports.h",
                "out_watch.h",
                "axi_shim.h",
            ],
            Shim::AxiWr => &[
                "clocked_top.h",
                "axi_mem.h",
                "axi_ports.h",
                "out_watch.h",
                "axi_shim.h",
                "axi_wr_shim.h",
            ],
            Shim::Axil => &["clocked_top.h", "axil_mgr.h", "axil_shim.h"],
            Shim::AccelCtrl => &["clocked_top.h", "axil_mgr.h", "accel_ctrl_shim.h"],
            Shim::Accel => &[
                "clocked_top.h",
                "axi_mem.h",
                "axi_ports.h",
                "axil_mgr.h",
                "accel_shim.h",
            ],
            Shim::Win => &["clocked_top.h", "win_host.h", "out_watch.h", "win_shim.h"],
            Shim::AxiRw => &[
                "clocked_top.h",
                "axi_mem.h",
                "axi_ports.h",
                "out_watch.h",
                "axi_shim.h",
                "axi_rw_shim.h",
            ],
        }
    }
}

/// AxilShim's transaction and record widths (tb/axil_mgr.h, `kItemWords`, `kRecordWords`).
const AXIL_ITEM_BITS: u32 = 128;
const AXIL_RECORD_BITS: u32 = 128;

/// AccelCtrlShim's record width (tb/accel_ctrl_shim.h, `kRecordWords`).
const ACCEL_CTRL_RECORD_BITS: u32 = 192;

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

fn build_runtime(cache: &Cache, vl_include: &Path, version: &str) -> Vec<PathBuf> {
    let sources = [
        "verilated.cpp",
        "verilated_threads.cpp",
        "verilated_vcd_c.cpp",
    ];
    let mut h = Sha256::new();
    h.update(format!(
        "{RECIPE}{version}{}{}",
        CXX_FLAGS.join(" "),
        rtl_opt()
    ));
    let stamp = format!("{:x}", h.finalize());
    let entry = cache.entry("runtime", "verilated", &stamp);
    let objects = |dir: &Path| -> Vec<PathBuf> {
        sources
            .iter()
            .map(|s| dir.join(s.replace(".cpp", ".o")))
            .collect()
    };
    if entry.join(COMPLETE).exists() {
        return objects(&entry);
    }
    let dir = cache.scratch("verilated-runtime");
    let compiler = cc::Build::new().cpp(true).get_compiler();
    for (src, obj) in sources.iter().zip(objects(&dir)) {
        run(
            Command::new(compiler.path())
                .args(CXX_FLAGS)
                .arg(rtl_opt())
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
    fs::write(dir.join(COMPLETE), "").unwrap();
    cache
        .publish(&dir, &entry)
        .unwrap_or_else(|e| panic!("{e}"));
    objects(&entry)
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

/// One `CUBE5_TOPS` entry: a top (`cube5_trilin`), a build (`cube5_trilin_v8_gate`), or a top
/// with parameter values its lines must have (`cube5_frame:P=4`, `cube5_frame:P=4:MaxDim=128`),
/// so a script can select configurations by what they are rather than by name.
fn selects(entry: &str, v: &Variant) -> bool {
    let mut parts = entry.split(':');
    let head = parts.next().unwrap_or_default();
    let conds: Vec<(&str, &str)> = parts.filter_map(|c| c.split_once('=')).collect();
    if conds.is_empty() {
        return head == v.top || head == v.full_name;
    }
    head == v.top
        && conds.iter().all(|(k, val)| {
            v.params
                .iter()
                .any(|(pk, pv)| pk == k && pv.to_string() == *val)
        })
}

/// A `CUBE5_TOPS` entry `top@Param=value:...` (what `cube5 elaborate` prints): exactly that
/// configuration, the top's defaults for every other parameter. The checked-in `.variants` line
/// that Verilator elaborates to the same parameters when there is one; otherwise a line generated
/// here (flag `sim`, named by the naming rule from the given parameters: `p4m32s0`), added to this
/// build's variants and cached like any other, never written to the `.variants` files. Other
/// entries are returned as they are.
fn exact_entry(
    entry: &str,
    tops: &[cube5_gen::variants::Top],
    variants: &mut Vec<Variant>,
    resolved: &mut Resolved,
    cache: &Cache,
    repo: &Path,
    verilator_version: &str,
) -> String {
    let Some((top, spec)) = entry.split_once('@') else {
        return entry.to_string();
    };
    let bad = |why: String| -> ! { panic!("CUBE5_TOPS entry `{entry}`: {why}") };
    let Some(t) = tops.iter().find(|t| t.name == top) else {
        bad(format!("no top `{top}` has a .variants file"))
    };
    let mut params = Vec::new();
    for kv in spec.split(':').filter(|kv| !kv.is_empty()) {
        let Some((k, v)) = kv.split_once('=') else {
            bad(format!("`{kv}` is not Param=value"))
        };
        let Ok(v) = v.parse::<i64>() else {
            bad(format!("`{kv}`: the value is not an integer"))
        };
        params.push((k.to_string(), v));
    }
    let name: String = params
        .iter()
        .map(|(k, v)| format!("{}{v}", k[..1].to_ascii_lowercase()))
        .collect();
    let line = cube5_gen::variants::VariantLine {
        top: top.to_string(),
        config: name.clone(),
        params: params.clone(),
        flags: vec!["sim".to_string()],
        origin: format!("CUBE5_TOPS entry `{entry}`"),
    };
    cube5_gen::variants::check_name(&line).unwrap_or_else(|e| bad(e));
    let want = resolve_params(cache, repo, t, &line, verilator_version)
        .unwrap_or_else(|e| bad(e.to_string()));
    if let Some(l) = t
        .variants
        .iter()
        .find(|l| resolved.get(&(top.to_string(), l.config.clone())) == Some(&want))
    {
        return l.full_name();
    }
    if t.variants.iter().any(|l| l.config == name) {
        bad(format!(
            "the generated name `{name}` is a line of {} with other parameters",
            t.variants_file.display()
        ));
    }
    if !variants.iter().any(|v| v.full_name == line.full_name()) {
        variants.push(Variant {
            top: top.to_string(),
            config: name.clone(),
            full_name: line.full_name(),
            params,
            flags: line.flags.clone(),
            files: t.files.iter().map(|f| repo.join(f)).collect(),
            gate: false,
            mutant: false,
        });
        resolved.insert((top.to_string(), name), want);
    }
    line.full_name()
}

/// `(top, config) -> [(Param, value)]` for every `.variants` line, read back from Verilator's
/// elaboration of the top with the line's `-G` overrides (`--xml-only`, 0.1-1 s a line). Cached
/// under the same content hash discipline as the objects, so it runs once per change.
type Resolved = std::collections::BTreeMap<(String, String), Vec<(String, i64)>>;

fn resolve_all_params(
    cache: &Cache,
    repo: &Path,
    tops: &[cube5_gen::variants::Top],
    verilator_version: &str,
) -> Resolved {
    let lines: Vec<(&cube5_gen::variants::Top, &cube5_gen::variants::VariantLine)> = tops
        .iter()
        .flat_map(|t| t.variants.iter().map(move |l| (t, l)))
        .collect();
    in_parallel(2, &lines, |(top, line)| {
        resolve_params(cache, repo, top, line, verilator_version)
            .map(|p| ((top.name.clone(), line.config.clone()), p))
            .map_err(|e| format!("{}: {e}", line.origin))
    })
    .unwrap_or_else(|failures| {
        panic!(
            "cannot elaborate the variants' parameters:\n{}",
            failures.join("\n")
        )
    })
    .into_iter()
    .collect()
}

/// `work` on every item, `jobs` threads each taking the next item in turn (so the caller's order
/// is the start order): the results in no particular order, or every failure's message.
fn in_parallel<T: Sync, R: Send>(
    jobs: usize,
    items: &[T],
    work: impl Fn(&T) -> Result<R, String> + Sync,
) -> Result<Vec<R>, Vec<String>> {
    let next = AtomicUsize::new(0);
    let done = Mutex::new(Vec::new());
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(items.len().max(1)) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(item) = items.get(i) else { break };
                match work(item) {
                    Ok(r) => done.lock().unwrap().push(r),
                    Err(e) => failures.lock().unwrap().push(e),
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    if failures.is_empty() {
        Ok(done.into_inner().unwrap())
    } else {
        Err(failures)
    }
}

fn resolve_params(
    cache: &Cache,
    repo: &Path,
    top: &cube5_gen::variants::Top,
    line: &cube5_gen::variants::VariantLine,
    verilator_version: &str,
) -> Result<Vec<(String, i64)>, String> {
    let mut h = Sha256::new();
    h.update(format!(
        "{RECIPE} params {} {:?} {verilator_version}",
        top.name, line.params
    ));
    for f in &top.files {
        h.update(f.to_string_lossy().as_bytes());
        h.update(fs::read(repo.join(f)).map_err(|e| format!("{}: {e}", f.display()))?);
    }
    let stamp = format!("{:x}", h.finalize());
    let entry = cache.entry("params", &line.full_name(), &stamp);
    let parse = |text: &str| -> Vec<(String, i64)> {
        text.lines()
            .filter_map(|l| {
                let (k, v) = l.split_once('=')?;
                Some((k.to_string(), v.parse().ok()?))
            })
            .collect()
    };
    if entry.join(COMPLETE).exists() {
        let text = fs::read_to_string(entry.join("params.txt")).map_err(|e| e.to_string())?;
        return Ok(parse(&text));
    }
    let dir = cache.scratch(&format!("{}.params", line.full_name()));
    let mut cmd = Command::new("verilator");
    cmd.args(["--xml-only", "-Wno-fatal", "--top-module", &top.name])
        .arg(cube5_gen::variants::include_arg(repo))
        .arg("--Mdir")
        .arg(&dir)
        .arg("--xml-output")
        .arg(dir.join("top.xml"));
    for (k, v) in &line.params {
        cmd.arg(format!("-G{k}={v}"));
    }
    cmd.args(top.files.iter().map(|f| repo.join(f)));
    run(&mut cmd, "verilator --xml-only")?;
    let xml = fs::read_to_string(dir.join("top.xml")).map_err(|e| e.to_string())?;
    let params = top_params_from_xml(&xml)?;
    let text: String = params.iter().map(|(k, v)| format!("{k}={v}\n")).collect();
    fs::write(dir.join("params.txt"), &text).map_err(|e| e.to_string())?;
    let _ = fs::remove_file(dir.join("top.xml"));
    fs::write(dir.join(COMPLETE), "").map_err(|e| e.to_string())?;
    cache.publish(&dir, &entry)?;
    Ok(parse(&text))
}

/// The top module's `param="true"` variables and their constant values from Verilator's XML
/// (`<var ... name="P" ... param="true"><const ... name="32'sh4" .../>`).
fn top_params_from_xml(xml: &str) -> Result<Vec<(String, i64)>, String> {
    let start = xml
        .find("topModule=\"1\"")
        .ok_or("no top module in Verilator's XML")?;
    let module = &xml[start
        ..xml[start..]
            .find("</module>")
            .map_or(xml.len(), |e| start + e)];
    let attr = |tag: &str, name: &str| -> Option<String> {
        let key = format!(" {name}=\"");
        let at = tag.find(&key)? + key.len();
        Some(tag[at..at + tag[at..].find('"')?].to_string())
    };
    let mut out = Vec::new();
    let mut rest = module;
    while let Some(at) = rest.find("<var ") {
        rest = &rest[at..];
        let tag_end = rest.find('>').ok_or("truncated XML")?;
        let tag = &rest[..tag_end];
        if tag.contains(" param=\"true\"") {
            let name = attr(tag, "name").ok_or("a parameter without a name")?;
            let body = &rest[tag_end..];
            let c = body
                .find("<const ")
                .ok_or(format!("parameter {name} has no value"))?;
            let ctag = &body[c..c + body[c..].find('>').ok_or("truncated XML")?];
            let lit = attr(ctag, "name")
                .ok_or(format!("parameter {name}: no constant"))?
                .replace("&apos;", "'");
            out.push((
                name.clone(),
                parse_sv_literal(&lit).ok_or(format!("parameter {name}: cannot read `{lit}`"))?,
            ));
        }
        rest = &rest[tag_end..];
    }
    Ok(out)
}

/// `32'sh4`, `32'd12`, `5'b101` -> value.
fn parse_sv_literal(lit: &str) -> Option<i64> {
    let (_, v) = lit.split_once('\'')?;
    let v = v.trim_start_matches('s');
    let (radix, digits) = match v.chars().next()? {
        'h' => (16, &v[1..]),
        'd' => (10, &v[1..]),
        'b' => (2, &v[1..]),
        'o' => (8, &v[1..]),
        _ => (10, v),
    };
    i64::from_str_radix(&digits.replace('_', ""), radix).ok()
}

/// The variant table for `tb-rs/src/variants.rs`: every variant (built or not), with the
/// parameters given on its line and the ones the RTL elaborates.
fn variant_table_source(variants: &[Variant], resolved: &Resolved, built: &[String]) -> String {
    let pairs = |ps: &[(String, i64)]| -> String {
        ps.iter()
            .map(|(k, v)| format!("(\"{k}\", {v})"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut s = String::from(
        "// Generated by tb-rs/build.rs from rtl/**/*.variants (read by scripts/cube5-gen). Do not edit.\n\
         pub static VARIANTS: &[Variant] = &[\n",
    );
    for v in variants {
        let netlist = if v.mutant {
            "Mutant"
        } else if v.gate {
            "Gate"
        } else {
            "Rtl"
        };
        let flags: Vec<String> = v.flags.iter().map(|f| format!("\"{f}\"")).collect();
        let rtl = resolved
            .get(&(v.top.clone(), v.config.clone()))
            .map(|p| pairs(p))
            .unwrap_or_default();
        s.push_str(&format!(
            "    Variant {{ top: \"{}\", config: \"{}\", name: \"{}\", netlist: Netlist::{netlist}, \
             flags: &[{}], given: &[{}], rtl_params: &[{rtl}], built: {} }},\n",
            v.top,
            v.config,
            v.full_name,
            flags.join(", "),
            pairs(&v.params),
            built.contains(&v.full_name)
        ));
    }
    s.push_str("];\n");
    s
}

fn write_if_changed(path: &Path, text: &str) {
    if fs::read_to_string(path).ok().as_deref() != Some(text) {
        fs::write(path, text).unwrap();
    }
}
