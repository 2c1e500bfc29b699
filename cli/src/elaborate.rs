//! `cube5 elaborate [SCENE]`: the `cube5_frame` configuration a scene needs
//! (`cube5_model::scene_elab`), why each choice was made and which units are left out, its
//! `.variants` line and `CUBE5_TOPS` entry, whether this build has it, and its area from a quick
//! Yosys `synth_ecp5` (scripts/synth.sh, cached) against the full frame at the same P and MaxDim.
//! `make cosim SCENE=...` builds exactly that configuration and co-simulates it.

use crate::load_scene;
use anyhow::{anyhow, Context, Result};
use cube5_model::scene::Scene;
use cube5_model::scene_elab::{elaborate, Elaboration, PrefilterBuild};
use std::path::PathBuf;
use std::process::Command;

#[derive(Debug, clap::Args)]
pub struct ElaborateArgs {
    /// Scene file (TOML); omit for the embedded default scene.
    scene: Option<PathBuf>,
    /// Pipelines, overriding the scene's run.pipelines (1, 2, 4 or 8).
    #[arg(short, long)]
    pipelines: Option<usize>,
    /// Print only the CUBE5_TOPS entry that builds the configuration (for `make cosim`).
    #[arg(long)]
    spec: bool,
    /// Synthesize the configuration, and the full frame it leaves units out of, with Yosys
    /// synth_ecp5 when the rows are not cached (minutes for a 128^3 memory); without it only
    /// cached rows are shown.
    #[arg(long)]
    area: bool,
}

/// The scene's configuration, refused with the scene's origin and the field named.
pub fn derive(scene: &Scene, origin: &str, pipelines: Option<usize>) -> Result<Elaboration> {
    let vol = scene.build_volume().with_context(|| origin.to_string())?;
    elaborate(scene, vol.dims, pipelines).map_err(|e| anyhow!("{origin}: {e}"))
}

/// The scene at `path` (the embedded default scene when none), validated, and how to name it.
pub fn load_valid(path: Option<&std::path::Path>) -> Result<(Scene, String)> {
    let scene = load_scene(path)?;
    let origin = path.map_or("the default scene".to_string(), |p| p.display().to_string());
    scene.validate(&origin)?;
    Ok((scene, origin))
}

pub fn run(args: ElaborateArgs) -> Result<()> {
    let (scene, origin) = load_valid(args.scene.as_deref())?;
    let e = derive(&scene, &origin, args.pipelines)?;
    if args.spec {
        println!("{}", e.tops());
        return Ok(());
    }
    for line in report(&e, &origin) {
        say!("{line}");
    }
    for line in area_lines(&e, args.area)? {
        say!("{line}");
    }
    Ok(())
}

/// What was elaborated and why: the configuration, each choice, the units left out, the
/// `.variants` line, the `CUBE5_TOPS` entry and whether this build has the configuration.
pub fn report(e: &Elaboration, origin: &str) -> Vec<String> {
    let params: Vec<String> = e.params().iter().map(|(k, v)| format!("{k}={v}")).collect();
    let mut out = vec![format!(
        "elaborate: {origin} needs cube5_frame {} ({})",
        e.name(),
        params.join(" ")
    )];
    for (what, why) in &e.choices {
        out.push(format!("  {what}: {why}"));
    }
    if e.left_out.is_empty() {
        out.push("  left out: nothing (every unit of the pipeline is used)".into());
    }
    for l in &e.left_out {
        out.push(format!("  left out: {}: {}", l.unit, l.why));
    }
    out.push(format!(".variants line: {}", e.variants_line()));
    out.push(format!("build: {}", built(e)));
    if let Some(pf) = &e.prefilter {
        out.push(format!(
            "  built beside it: cube5_sepconv {} ({}): {}",
            pf.name(),
            pf.spec()
                .split_once('@')
                .map_or(String::new(), |(_, p)| p.replace(':', " ")),
            pf.why
        ));
        out.push(format!(
            "cube5_sepconv .variants line: {}",
            pf.variants_line()
        ));
        out.push(format!("build: {}", built_prefilter(pf)));
    }
    out
}

/// Whether this build of `cube5` has the pre-pass unit.
#[cfg(feature = "rtl")]
fn built_prefilter(pf: &PrefilterBuild) -> String {
    match cube5_tb::prefilter::sepconv_variant(&pf.config) {
        Ok(v) => format!("{v} (built in this cube5; CUBE5_TOPS={})", pf.spec()),
        Err(_) => format!(
            "not built in this cube5 (`make cosim SCENE=...` or CUBE5_TOPS={} builds it)",
            pf.spec()
        ),
    }
}

#[cfg(not(feature = "rtl"))]
fn built_prefilter(pf: &PrefilterBuild) -> String {
    format!(
        "this cube5 has no RTL (feature `rtl`); CUBE5_TOPS={} builds it",
        pf.spec()
    )
}

/// Whether this build of `cube5` has the configuration, under which name.
#[cfg(feature = "rtl")]
fn built(e: &Elaboration) -> String {
    let spec = e.spec();
    match cube5_tb::frame::FrameRtl::all()
        .into_iter()
        .find(|r| r.cfg == e.config)
    {
        Some(r) if r.variant.built => format!("{} (built in this cube5; CUBE5_TOPS={spec})", r.variant),
        Some(r) => format!(
            "{} (not built in this cube5: `make cosim SCENE=...` or CUBE5_TOPS={spec} builds it)",
            r.variant
        ),
        None => format!(
            "not built: a generated configuration, {} (`make cosim SCENE=...` or CUBE5_TOPS={spec} builds it)",
            e.name()
        ),
    }
}

#[cfg(not(feature = "rtl"))]
fn built(e: &Elaboration) -> String {
    format!(
        "this cube5 has no RTL (feature `rtl`); CUBE5_TOPS={} builds it",
        e.spec()
    )
}

/// One row of scripts/synth.sh's ECP5 table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Area {
    pub lut4: i64,
    pub ff: i64,
    pub ccu2c: i64,
    pub mult18: i64,
    pub dp16kd: i64,
}

impl std::fmt::Display for Area {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} LUT4, {} FF, {} CCU2C, {} MULT18, {} DP16KD",
            self.lut4, self.ff, self.ccu2c, self.mult18, self.dp16kd
        )
    }
}

/// The ECP5 area of `e` from scripts/synth.sh (`SYNTH_SPEC`): synthesized when `run`, else only
/// a cached row; `None` when there is none (or no repository beside this `cube5`).
pub fn area(e: &Elaboration, run: bool) -> Result<Option<Area>> {
    area_of("cube5_frame", &e.name(), &e.spec(), run)
}

/// The ECP5 area of configuration `name` of `top`, given as the `CUBE5_TOPS`-style `spec`.
pub fn area_of(top: &str, name: &str, spec: &str, run: bool) -> Result<Option<Area>> {
    let repo = cube5_model::repo_root();
    let script = repo.join("scripts/synth.sh");
    if !script.exists() {
        return Ok(None);
    }
    let out = Command::new(&script)
        .current_dir(&repo)
        .env("SYNTH_SPEC", spec)
        .env("SYNTH_FLOWS", "ecp5")
        .env("SYNTH_FMAX", "0")
        .env("SYNTH_CACHED", if run { "0" } else { "1" })
        .output()
        .with_context(|| format!("running {}", script.display()))?;
    if !out.status.success() {
        return Err(anyhow!(
            "scripts/synth.sh for {} failed: {}",
            spec,
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let head = format!("| {top} | {name} |");
    let Some(row) = text.lines().find(|l| l.starts_with(&head)) else {
        return Ok(None);
    };
    let cols: Vec<&str> = row.split('|').map(str::trim).collect();
    // | top | config | generic | LUT4 | FF | CCU2C | MULT18 | DP16KD | ...
    let n = |i: usize| -> Result<i64> {
        cols.get(i)
            .and_then(|c| c.parse().ok())
            .ok_or_else(|| anyhow!("scripts/synth.sh row `{row}`: column {i} is not a count"))
    };
    Ok(Some(Area {
        lut4: n(4)?,
        ff: n(5)?,
        ccu2c: n(6)?,
        mult18: n(7)?,
        dp16kd: n(8)?,
    }))
}

/// The area lines: the configuration's, the full frame's and what leaving units out saved.
pub fn area_lines(e: &Elaboration, run: bool) -> Result<Vec<String>> {
    let how = if run {
        ""
    } else {
        " (`cube5 elaborate --area` or `make cosim SCENE=...` synthesizes it)"
    };
    let mut out = Vec::new();
    let mine = area(e, run)?;
    match mine {
        Some(a) => out.push(format!("area (Yosys synth_ecp5): {a}")),
        None => out.push(format!("area: not synthesized yet{how}")),
    }
    if let Some(full) = e.full() {
        match (mine, area(&full, run)?) {
            (Some(a), Some(f)) => {
                out.push(format!("the full frame ({}): {f}", full.name()));
                out.push(format!(
                    "leaving gradient and shader out saves {} LUT4, {} FF, {} CCU2C, {} MULT18, {} DP16KD ({:.0}% of the LUT4s)",
                    f.lut4 - a.lut4,
                    f.ff - a.ff,
                    f.ccu2c - a.ccu2c,
                    f.mult18 - a.mult18,
                    f.dp16kd - a.dp16kd,
                    100.0 * (f.lut4 - a.lut4) as f64 / f.lut4.max(1) as f64
                ));
            }
            (_, f) => out.push(format!(
                "the full frame ({}): {}",
                full.name(),
                f.map_or(format!("not synthesized yet{how}"), |f| f.to_string())
            )),
        }
    }
    if let Some(pf) = &e.prefilter {
        let name = pf.name();
        out.push(match area_of("cube5_sepconv", &name, &pf.spec(), run)? {
            Some(a) => {
                format!("the pre-pass unit cube5_sepconv {name} adds (Yosys synth_ecp5): {a}")
            }
            None => format!("the pre-pass unit cube5_sepconv {name}: not synthesized yet{how}"),
        });
    }
    Ok(out)
}
