//! The variant table against the model and the tree (issue 16, "one list, one place"):
//! - every `.variants` line has a model configuration, and the model's configuration built from
//!   the line agrees with the RTL's elaborated top-level parameters on every parameter (names and
//!   values, defaults included);
//! - no variant is named by a string anywhere in the Rust sources, scripts or Makefile: tests
//!   and benches loop over `variants_of(top)` or pick by a property.
//!
//! Needs no RTL build: the table carries the parameters Verilator elaborated.

use cube5_model::unit::UnitConfig;
use cube5_model::units::cube5_accel::AccelConfig;
use cube5_model::units::cube5_accel_ctrl::AccelCtrlConfig;
use cube5_model::units::cube5_axi_wr::AxiWrConfig;
use cube5_model::units::cube5_axil::AxilConfig;
use cube5_model::units::cube5_er::ErConfig;
use cube5_model::units::cube5_pwarp::PwarpConfig;
use cube5_model::units::cube5_section_buf::SectionBufConfig;
use cube5_model::units::gicube_cache::CacheConfig;
use cube5_model::units::gicube_deposit::DepositConfig;
use cube5_model::units::gicube_processor::ProcessorRtlConfig;
use cube5_model::units::gicube_queue_front::QueueFrontConfig;
use cube5_model::units::gicube_ray_queues::RayQueuesConfig;
use cube5_model::units::gicube_ring::RingRtlConfig;
use cube5_model::units::gicube_sample::SampleRtlConfig;
use cube5_model::units::gicube_step::StepConfig;
use cube5_model::units::{
    cube5_axi_rd::AxiRdConfig, cube5_compos::ComposConfig, cube5_frame::FrameConfig,
    cube5_gradient::GradientConfig, cube5_rblock::RBlockConfig, cube5_sepconv::SepconvConfig,
    cube5_shader::ShaderConfig, cube5_skewmem::SkewConfig, cube5_trilin::TrilinConfig,
    cube5_vol_fetch::VolFetchConfig, cube5_warp::WarpConfig, gicube_bucket::BucketConfig,
    gicube_packet_loop::PacketLoopConfig, gicube_scatter::ScatterConfig,
    gicube_sorter::SorterConfig,
};
use cube5_tb::variants::{Netlist, Variant, VARIANTS};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The model's parameters of `v` against the RTL's, or what differs.
fn agree<C: UnitConfig>(v: &Variant) -> Result<(), String> {
    let cfg = v.config::<C>().map_err(|e| e.to_string())?;
    let model: BTreeMap<&str, i64> = cfg.to_params().into_iter().collect();
    let rtl: BTreeMap<&str, i64> = v.rtl_params.iter().copied().collect();
    let mut diffs = Vec::new();
    for (k, r) in &rtl {
        match model.get(k) {
            Some(m) if m == r => {}
            Some(m) => diffs.push(format!("{k}: RTL {r}, model {m}")),
            None => diffs.push(format!("{k}: RTL {r}, not in the model's configuration")),
        }
    }
    for k in model.keys().filter(|k| !rtl.contains_key(*k)) {
        diffs.push(format!(
            "{k}: in the model's configuration, not an RTL parameter"
        ));
    }
    if diffs.is_empty() {
        Ok(())
    } else {
        Err(diffs.join("; "))
    }
}

/// Dispatch by top: a top without an arm here has no model configuration and fails.
fn check(v: &Variant) -> Result<(), String> {
    match v.top {
        t if t == TrilinConfig::TOP => agree::<TrilinConfig>(v),
        t if t == GradientConfig::TOP => agree::<GradientConfig>(v),
        t if t == SepconvConfig::TOP => agree::<SepconvConfig>(v),
        t if t == ShaderConfig::TOP => agree::<ShaderConfig>(v),
        t if t == ComposConfig::TOP => agree::<ComposConfig>(v),
        t if t == SkewConfig::TOP => agree::<SkewConfig>(v),
        t if t == RBlockConfig::TOP => agree::<RBlockConfig>(v),
        t if t == FrameConfig::TOP => agree::<FrameConfig>(v),
        t if t == BucketConfig::TOP => agree::<BucketConfig>(v),
        t if t == PacketLoopConfig::TOP => agree::<PacketLoopConfig>(v),
        t if t == ScatterConfig::TOP => agree::<ScatterConfig>(v),
        t if t == SorterConfig::TOP => agree::<SorterConfig>(v),
        t if t == AxiRdConfig::TOP => agree::<AxiRdConfig>(v),
        t if t == VolFetchConfig::TOP => agree::<VolFetchConfig>(v),
        t if t == WarpConfig::TOP => agree::<WarpConfig>(v),
        t if t == PwarpConfig::TOP => agree::<PwarpConfig>(v),
        t if t == AxilConfig::TOP => agree::<AxilConfig>(v),
        t if t == AxiWrConfig::TOP => agree::<AxiWrConfig>(v),
        t if t == AccelCtrlConfig::TOP => agree::<AccelCtrlConfig>(v),
        t if t == RayQueuesConfig::TOP => agree::<RayQueuesConfig>(v),
        t if t == QueueFrontConfig::TOP => agree::<QueueFrontConfig>(v),
        t if t == ProcessorRtlConfig::TOP => agree::<ProcessorRtlConfig>(v),
        t if t == RingRtlConfig::TOP => agree::<RingRtlConfig>(v),
        t if t == SectionBufConfig::TOP => agree::<SectionBufConfig>(v),
        t if t == StepConfig::TOP => agree::<StepConfig>(v),
        t if t == DepositConfig::TOP => agree::<DepositConfig>(v),
        t if t == CacheConfig::TOP => agree::<CacheConfig>(v),
        t if t == SampleRtlConfig::TOP => agree::<SampleRtlConfig>(v),
        t if t == ErConfig::TOP => agree::<ErConfig>(v),
        t if t == AccelConfig::TOP => agree::<AccelConfig>(v),
        other => Err(format!(
            "top {other} has no model configuration (UnitConfig)"
        )),
    }
}

#[test]
fn every_variant_has_a_model_configuration_that_agrees_with_the_rtl_on_every_parameter() {
    let lines: Vec<&Variant> = VARIANTS
        .iter()
        .filter(|v| v.netlist == Netlist::Rtl)
        .collect();
    assert!(lines.len() >= 30, "the table lists every .variants line");
    let failures: Vec<String> = lines
        .iter()
        .filter_map(|v| check(v).err().map(|e| format!("{}: {e}", v.name)))
        .collect();
    assert!(
        failures.is_empty(),
        "model and RTL disagree:\n{}",
        failures.join("\n")
    );
    for v in &lines {
        assert!(
            !v.rtl_params.is_empty(),
            "{}: no parameters elaborated",
            v.name
        );
    }
}

/// The check bites: a model configuration with one parameter changed is refused.
#[test]
fn a_parameter_the_model_sets_differently_is_caught() {
    let v = VARIANTS
        .iter()
        .find(|v| v.top == FrameConfig::TOP && v.netlist == Netlist::Rtl)
        .unwrap();
    let mut cfg: FrameConfig = v.config().unwrap();
    cfg.shader.rm_frac_w += 1;
    let model: BTreeMap<&str, i64> = cfg.to_params().into_iter().collect();
    let rtl: BTreeMap<&str, i64> = v.rtl_params.iter().copied().collect();
    assert_ne!(model, rtl);
    assert!(FrameConfig::from_params(&[("NoSuchParam", 1)]).is_err());
}

/// Files that may name variants: none but the generated table (in OUT_DIR) and the `.variants`
/// files themselves (and their reader's own tests of the naming rule, and this file). Docs
/// (Markdown) name configurations in their tables; that is prose.
const EXEMPT: &[&str] = &[
    "scripts/cube5-gen/src/variants.rs",
    "tb-rs/tests/variant_table.rs",
];
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if !matches!(name.as_str(), "target" | ".git" | "out" | "node_modules")
                && !name.starts_with('.')
            {
                sources(&p, out);
            }
        } else if name.ends_with(".rs")
            || name.ends_with(".sh")
            || name == "Makefile"
            || name == "run"
            || name.ends_with(".toml")
        {
            out.push(p);
        }
    }
}

/// String literals of a source (double-quoted, escapes skipped); good enough for Rust and shell.
fn literals(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur: Option<String> = None;
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        match (&mut cur, c) {
            (None, '"') => cur = Some(String::new()),
            (Some(s), '"') => {
                out.push(std::mem::take(s));
                cur = None;
            }
            (Some(s), '\\') => {
                s.push('\\');
                if let Some(n) = chars.next() {
                    s.push(n);
                }
            }
            (Some(s), c) => s.push(c),
            (None, _) => {}
        }
    }
    out
}

#[test]
fn no_variant_is_named_by_a_string_outside_the_table_and_the_variants_files() {
    let repo = cube5_model::repo_root();
    let mut files = Vec::new();
    sources(&repo, &mut files);
    assert!(files.len() > 50, "the scan sees the sources");
    let rtl: Vec<&Variant> = VARIANTS
        .iter()
        .filter(|v| v.netlist == Netlist::Rtl)
        .collect();
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        let shown = f.strip_prefix(&repo).unwrap_or(f).display().to_string();
        if EXEMPT.contains(&shown.as_str()) {
            continue;
        }
        for lit in literals(&text) {
            for v in &rtl {
                let built_name = lit.contains(v.name);
                // `format!("cube5_trilin_{name}")`: a name assembled from the top.
                let assembled = lit.contains(&format!("{}_{{", v.top));
                // A bare configuration name (`"v8"`) for this top.
                let bare = lit == v.config;
                if built_name || assembled || bare {
                    found.push(format!("{shown}: \"{lit}\" names {}", v.name));
                    break;
                }
            }
        }
        // Shell and make: unquoted names too (CUBE5_TOPS=cube5_frame_p4).
        if shown.ends_with(".sh") || shown.ends_with("Makefile") || shown.ends_with("run") {
            for v in &rtl {
                if text
                    .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .any(|w| w == v.name)
                {
                    found.push(format!("{shown}: names {}", v.name));
                }
            }
        }
    }
    found.sort();
    found.dedup();
    assert!(
        found.is_empty(),
        "variant names outside the table and rtl/**/*.variants (loop over variants_of(top) or pick by a property):\n{}",
        found.join("\n")
    );
}
