//! Co-simulation of cube5_er, the ER-Perspective sweep (docs/numerics/er_perspective.md, "The
//! RTL: cube5_er"), against the contract's model `ErJob::render`: whole base planes, bit for bit,
//! at 32^3 and 64^3 (128^3 outside CI), fields of view 20-90 degrees, composite and MIP, the
//! Bartlett and the centre merge, 1 and 2 rays per voxel, the eye outside and inside the volume's
//! bounding sphere, random input idle and output back-pressure, a reset in mid-frame followed by
//! an exact frame, and the gate-level smoke run. Every frame prints its samples per slice against
//! the N^2 .. 4 N^2 bound and its clocks per sample.

mod support;

use cube5_model::er_perspective::{ErJob, ErMerge, ErScheme};
use cube5_model::phantom::head_phantom;
use cube5_model::render::{CompositeMode, Projection, RenderParams};
use cube5_model::transfer::TransferFunction;
use cube5_tb::er::{er_gate_variants, er_variants, first_difference, ErBench};
use cube5_tb::rtl::Traffic;
use cube5_tb::Variant;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::seed;

fn params(dir: [f64; 3], fov: f64, mode: CompositeMode) -> RenderParams {
    RenderParams {
        width: 32,
        height: 32,
        direction: Some(dir),
        projection: Projection::Perspective,
        fov,
        mode,
        ..RenderParams::default()
    }
}

/// One frame to run: the job and what it is.
struct Case {
    job: ErJob,
    what: String,
}

fn job(
    bench: &ErBench,
    n: usize,
    p: &RenderParams,
    rho: u32,
    merge: ErMerge,
) -> cube5_model::Result<ErJob> {
    let vol = head_phantom(n, 12)?;
    let tf = TransferFunction::head_default();
    let scheme = ErScheme {
        rays_per_voxel: rho,
        merge,
    };
    ErJob::new(&vol, &tf, p, &bench.cfg.frame_config(), scheme)
}

/// The job with its eye moved to `eye` (voxel units, unit spacing): inside the bounding sphere.
fn placed(job: ErJob, eye: [f64; 3]) -> cube5_model::Result<ErJob> {
    let setup = job.setup.with_eye_at(eye)?;
    job.with_setup(setup)
}

/// Distance from `eye` to the centre of an `n`^3 volume against its bounding sphere's radius.
fn inside_sphere(eye: [f64; 3], n: usize) -> bool {
    let c = (n as f64 - 1.0) / 2.0;
    let d2: f64 = eye.iter().map(|x| (x - c) * (x - c)).sum();
    d2.sqrt() < c * 3f64.sqrt()
}

/// Runs `case` on `bench` (its volume loaded here) under `traffic` and holds the base plane to the
/// model's; prints the frame's figures.
fn run_case(bench: &mut ErBench, case: &Case, traffic: &Traffic, seed: u64) -> (u64, u64) {
    let v = bench.variant();
    bench
        .load(&case.job)
        .unwrap_or_else(|e| panic!("{v}: seed {seed}: {}: {e}", case.what));
    let want = case.job.render();
    let got = bench
        .frame(&case.job, traffic)
        .unwrap_or_else(|e| panic!("{v}: seed {seed}: {}: {e}", case.what));
    if let Some(d) = first_difference(&got, &want) {
        panic!(
            "{v}: seed {seed}: {}: {d} (reproduce with CUBE5_SEED={seed})",
            case.what
        );
    }
    let st = &want.stats;
    assert!(
        st.min_per_slice() >= st.n2 && st.max_per_slice() <= 4 * st.n2,
        "{}: samples per slice {}..{} outside {}..{}",
        case.what,
        st.min_per_slice(),
        st.max_per_slice(),
        st.n2,
        4 * st.n2
    );
    eprintln!(
        "{v}: {}: {} regions, {} samples, per slice {}..{} against N^2 = {} .. 4N^2 = {}; sweep {} clocks ({:.2} per sample), frame {} clocks",
        case.what,
        st.regions,
        st.samples,
        st.min_per_slice(),
        st.max_per_slice(),
        st.n2,
        4 * st.n2,
        got.sweep_cycles,
        got.sweep_cycles as f64 / st.samples.max(1) as f64,
        got.cycles
    );
    (st.samples, got.sweep_cycles)
}

/// The built configurations that hold `n`^3 volumes at 2 rays per voxel.
fn holding(n: usize) -> Vec<&'static Variant> {
    er_variants()
        .into_iter()
        .filter(|v| v.param("MaxDim").is_some_and(|d| d >= n as i64))
        .collect()
}

/// A random view: direction, field of view 20-90 degrees, mode, merge filter.
fn random_case(
    bench: &ErBench,
    rng: &mut ChaCha8Rng,
    n: usize,
    rho: u32,
) -> cube5_model::Result<Case> {
    let dir = loop {
        let d = [(); 3].map(|_| rng.random_range(-1.0..1.0));
        if d.iter().map(|x| x * x).sum::<f64>() > 0.04 {
            break d;
        }
    };
    let fov = rng.random_range(20.0..90.0);
    let mode = if rng.random_bool(0.5) {
        CompositeMode::Composite
    } else {
        CompositeMode::Mip
    };
    let merge = if rng.random_bool(0.7) {
        ErMerge::Bartlett
    } else {
        ErMerge::Centre
    };
    let p = params(dir, fov, mode);
    Ok(Case {
        job: job(bench, n, &p, rho, merge)?,
        what: format!(
            "{n}^3, dir {dir:.3?}, fov {fov:.1}, {}, {} merge, {rho} ray(s) per voxel",
            mode.name(),
            merge.name()
        ),
    })
}

/// 32^3: random views (fov 20-90 degrees, composite and MIP, both merges, 1 and 2 rays per voxel)
/// under random idle and back-pressure, plus the axis views at full speed.
#[test]
fn frames_at_32_are_bit_exact() {
    let seed = seed(0xe5_0032);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let variants = holding(32);
    assert!(!variants.is_empty(), "no cube5_er configuration holds 32^3");
    for v in variants.into_iter().take(1) {
        let mut bench = ErBench::new(v, seed as u32).unwrap();
        for (i, dir) in [[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.2]]
            .into_iter()
            .enumerate()
        {
            let mode = [CompositeMode::Composite, CompositeMode::Mip][i % 2];
            let fov = [20.0, 55.0, 90.0][i];
            let p = params(dir, fov, mode);
            let case = Case {
                job: job(&bench, 32, &p, 1, ErMerge::Bartlett).unwrap(),
                what: format!("32^3, dir {dir:?}, fov {fov}, {}", mode.name()),
            };
            run_case(&mut bench, &case, &Traffic::full_speed(), seed);
        }
        for k in 0..3 {
            let rho = 1 + (k % 2) as u32;
            let case = random_case(&bench, &mut rng, 32, rho).unwrap();
            if let Err(e) = bench.check(&case.job) {
                eprintln!("{v}: {}: refused by the host: {e}", case.what);
                continue;
            }
            let traffic = Traffic::random(&mut rng, 0.3, 0.5);
            run_case(&mut bench, &case, &traffic, seed);
        }
    }
}

/// 64^3: composite and MIP at 30 and 80 degrees, under idle and back-pressure.
#[test]
fn frames_at_64_are_bit_exact() {
    let seed = seed(0xe5_0064);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let variants = holding(64);
    assert!(!variants.is_empty(), "no cube5_er configuration holds 64^3");
    for v in variants.into_iter().take(1) {
        let mut bench = ErBench::new(v, seed as u32).unwrap();
        for (dir, fov, mode) in [
            ([0.3, -0.2, 1.0], 30.0, CompositeMode::Composite),
            ([-1.0, 0.4, -0.3], 80.0, CompositeMode::Mip),
        ] {
            let p = params(dir, fov, mode);
            let case = Case {
                job: job(&bench, 64, &p, 1, ErMerge::Bartlett).unwrap(),
                what: format!("64^3, dir {dir:?}, fov {fov}, {}", mode.name()),
            };
            let traffic = Traffic::random(&mut rng, 0.2, 0.3);
            run_case(&mut bench, &case, &traffic, seed);
        }
    }
}

/// The eye inside the volume's bounding sphere (a few slices in front of the first slice, off
/// centre): many regions, so many merges; both filters, composite and MIP. An eye less than one
/// slice in front of the volume is refused by the set-up (the scheme needs it in front), and a
/// region wider than the buffers by the host, each with a one-line reason.
#[test]
fn eye_inside_the_bounding_sphere() {
    let seed = seed(0xe5_1e5e);
    let v = holding(32)[0];
    let mut bench = ErBench::new(v, seed as u32).unwrap();
    for (eye, mode, merge) in [
        (
            [15.5, 15.5, -2.0],
            CompositeMode::Composite,
            ErMerge::Bartlett,
        ),
        ([4.0, 25.0, -1.3], CompositeMode::Mip, ErMerge::Bartlett),
        ([20.0, 9.0, -3.7], CompositeMode::Composite, ErMerge::Centre),
    ] {
        let p = params([0.0, 0.0, 1.0], 90.0, mode);
        let j = job(&bench, 32, &p, 1, merge).unwrap();
        let j = placed(j, eye).unwrap();
        assert!(inside_sphere(eye, 32), "inside the sphere");
        let case = Case {
            what: format!("32^3, eye {eye:?}, {}, {} merge", mode.name(), merge.name()),
            job: j,
        };
        assert!(case.job.setup.layout().regions() >= 4, "{}", case.what);
        run_case(&mut bench, &case, &Traffic::full_speed(), seed);
    }
    // Less than one slice in front: refused by the set-up, naming the distance.
    let p = params([0.0, 0.0, 1.0], 90.0, CompositeMode::Composite);
    let j = job(&bench, 32, &p, 1, ErMerge::Bartlett).unwrap();
    let err = placed(j, [15.5, 15.5, 0.5]).err().unwrap();
    assert!(err.to_string().contains("slice"), "{err}");
    // Four rays per voxel at 32^3 need regions wider than the smallest buffers: the host refuses.
    for v in er_variants() {
        let bench = ErBench::new(v, 1).unwrap();
        let j = job(
            &bench,
            32.min(bench.cfg.max_dim()),
            &p,
            4,
            ErMerge::Bartlett,
        )
        .unwrap();
        if let Err(e) = bench.check(&j) {
            assert!(e.contains("MaxRays") || e.contains("MaxDim"), "{e}");
        }
    }
}

/// A reset in the middle of a frame (after a random share of its clocks), then the same frame
/// again from the volume up: exact.
#[test]
fn mid_frame_reset_then_an_exact_frame() {
    let seed = seed(0xe5_4e5e);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let v = holding(32)[0];
    let mut bench = ErBench::new(v, seed as u32).unwrap();
    let p = params([0.2, 1.0, -0.1], 60.0, CompositeMode::Composite);
    let case = Case {
        job: job(&bench, 32, &p, 1, ErMerge::Bartlett).unwrap(),
        what: "32^3 after a reset in mid-frame".into(),
    };
    bench.load(&case.job).unwrap();
    let items = bench.items(&case.job).unwrap();
    let cut = rng.random_range(1_000..200_000);
    let d = bench
        .dut
        .drive(&items, &Traffic::random(&mut rng, 0.2, 0.2), u64::MAX, cut)
        .unwrap();
    eprintln!(
        "{v}: reset after {} clocks, {} of {} items taken, {} coxels out",
        d.stats.cycles,
        d.stats.consumed,
        items.len(),
        d.stats.produced
    );
    bench.dut.reset();
    run_case(
        &mut bench,
        &case,
        &Traffic::random(&mut rng, 0.2, 0.4),
        seed,
    );
}

/// The gate-level netlist: an 8^3 frame, composite then MIP, with idle and back-pressure.
#[test]
#[ignore = "sim-full: the gate-level netlist is `gatefull` (141 s of build; docs/ci.md)"]
fn gate_level_smoke() {
    let seed = seed(0xe5_6a7e);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let gates = er_gate_variants();
    assert!(!gates.is_empty(), "no gate-level build of cube5_er");
    for v in gates {
        let mut bench = ErBench::new(v, seed as u32).unwrap();
        let n = bench.cfg.max_dim().min(8);
        for (mode, merge) in [
            (CompositeMode::Composite, ErMerge::Bartlett),
            (CompositeMode::Mip, ErMerge::Centre),
        ] {
            let p = params([0.3, 0.2, 1.0], 70.0, mode);
            let j = job(&bench, n, &p, 1, merge).unwrap();
            let j = placed(j, [3.5, 4.0, -1.5]).unwrap();
            let case = Case {
                what: format!("{n}^3 gate-level, {}", mode.name()),
                job: j,
            };
            let traffic = Traffic::random(&mut rng, 0.2, 0.3);
            run_case(&mut bench, &case, &traffic, seed);
        }
    }
}

/// The smallest configuration at its own size, against the model (also CI's RTL view of the
/// gate configuration): an 8^3 volume, eye inside the sphere, both modes and merges.
#[test]
fn smallest_configuration_frames() {
    let seed = seed(0xe5_0008);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for v in er_variants() {
        let mut bench = ErBench::new(v, seed as u32).unwrap();
        if bench.cfg.max_dim() > 16 {
            continue;
        }
        let n = bench.cfg.max_dim().min(8);
        for k in 0..4 {
            let mode = [CompositeMode::Composite, CompositeMode::Mip][k % 2];
            let merge = [ErMerge::Bartlett, ErMerge::Centre][k / 2];
            let p = params([0.1, -0.3, 1.0], 45.0 + 10.0 * k as f64, mode);
            let j = job(&bench, n, &p, 1 + (k % 2) as u32, merge).unwrap();
            let eye = [
                rng.random_range(0.0..8.0),
                rng.random_range(0.0..8.0),
                -rng.random_range(1.2..6.0),
            ];
            let j = placed(j, eye).unwrap();
            let case = Case {
                what: format!(
                    "{n}^3, eye {eye:.2?}, {}, {} merge",
                    mode.name(),
                    merge.name()
                ),
                job: j,
            };
            run_case(
                &mut bench,
                &case,
                &Traffic::random(&mut rng, 0.3, 0.3),
                seed,
            );
        }
    }
}

/// 128^3, composite at 45 degrees.
#[test]
#[ignore = "sim-full: a 128^3 frame is about 38 M clocks of simulation (141 s)"]
fn frames_at_128_are_bit_exact() {
    let seed = seed(0xe5_0128);
    let variants = holding(128);
    assert!(
        !variants.is_empty(),
        "no cube5_er configuration holds 128^3"
    );
    let mut bench = ErBench::new(variants[0], seed as u32).unwrap();
    let p = params([0.2, 0.1, 1.0], 45.0, CompositeMode::Composite);
    let case = Case {
        job: job(&bench, 128, &p, 1, ErMerge::Bartlett).unwrap(),
        what: "128^3, fov 45, composite".into(),
    };
    run_case(&mut bench, &case, &Traffic::full_speed(), seed);
}
