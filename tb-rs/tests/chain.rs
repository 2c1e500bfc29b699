//! Whole rays through the Cube-5 pipeline: trilin -> gradient -> shader -> compos, the RTL units
//! chained back to back in the test bench against the model chain, bit-exact at every stage.
//!
//! Each ray is a random walk of densities (so opacity accumulates as along a real ray); each of
//! its samples is interpolated seven times (the sample and its six orthogonal neighbours, as the
//! frame feeds the gradient unit, docs/numerics/frame.md), the gradient is estimated (`N6`),
//! adapted to the shader's format, shaded, and composited onto the ray's coxel, which the test
//! bench carries from one sample to the next (the compositing buffer's role).

mod support;

use cube5_model::transfer::TransferFunction;
use cube5_model::unit::{StreamCodec, StreamUnit};
use cube5_model::units::cube5_compos::{
    Compos, ComposConfig, ComposIn, ComposMode, ComposRegs, Coxel, OpacityLut, Sample,
};
use cube5_model::units::cube5_frame::{n6_gradient_in, shader_in, N6_OFFSETS};
use cube5_model::units::cube5_gradient::{Gradient, GradientConfig, GradientIn, GradientOut};
use cube5_model::units::cube5_shader::{
    ClassLut, Phong, ReflectanceMap, Rgba, Shader, ShaderConfig, ShaderIn, ShaderMode, ShaderTables,
};
use cube5_model::units::cube5_trilin::{Trilin, TrilinConfig, TrilinIn, TrilinMode};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Debug;
use support::{seed, variant_with};

const RAYS: usize = 10_000;
const MIN_LEN: usize = 64;
const MAX_LEN: usize = 512;

struct Ray {
    len: usize,
    density: i64,
    mode: ComposMode,
    tf2d: bool,
}

/// Drives one stage on the RTL and checks it against the model on the RTL's own inputs, so a
/// difference is pinned to the stage that made it.
fn stage<C>(
    rtl: &mut RtlStream<C>,
    gold: &mut impl StreamUnit<In = C::In, Out = C::Out>,
    items: &[C::In],
    traffic: &Traffic,
    what: &str,
    n: usize,
    seed: u64,
) -> Vec<C::Out>
where
    C: StreamCodec,
    C::In: Clone + Debug,
    C::Out: Clone + Debug + PartialEq,
{
    let want = items.len() as u64;
    let driven = rtl
        .drive(items, traffic, want, 64 * want + 10_000)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        driven.stats.produced, want,
        "{what}: RTL lost items at sample {n} (seed {seed})"
    );
    assert_eq!(
        driven.stats.protocol_errors, 0,
        "{what}: valid/ready violated (seed {seed})"
    );
    let expected = gold.run(items);
    let got: Vec<C::Out> = driven.outputs.into_iter().map(|t| t.value).collect();
    if let Some(k) = (0..got.len()).find(|&k| got[k] != expected[k]) {
        panic!(
            "MISMATCH in {what} at ray sample {n}, item {k} (seed {seed}; CUBE5_SEED={seed} reproduces)\n  input {:?}\n  rtl   {:?}\n  model {:?}",
            items[k], got[k], expected[k]
        );
    }
    got
}

#[test]
fn ten_thousand_whole_rays_through_the_chained_units() {
    let seed = seed(2024);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let traffic = Traffic::random(&mut rng, 0.15, 0.15);

    let trilin_cfg = TrilinConfig::DEFAULT;
    let grad_cfg = GradientConfig::DEFAULT;
    let shader_cfg = ShaderConfig::DEFAULT;
    let compos_cfg = ComposConfig::DEFAULT;

    let tables = ShaderTables {
        class: ClassLut::from_transfer(&shader_cfg, &TransferFunction::head_default()).unwrap(),
        rmap: ReflectanceMap::from_lights(&shader_cfg, &Phong::two_lights()).unwrap(),
    };
    let lut = OpacityLut::new(1.3, &compos_cfg).unwrap();
    let regs = ComposRegs::defaults(&compos_cfg);

    let mut m_trilin = Trilin::new(trilin_cfg).unwrap();
    let mut m_grad = Gradient::new(grad_cfg).unwrap();
    let mut m_shader = Shader::new(shader_cfg, tables.clone()).unwrap();
    let mut m_compos = Compos::new(compos_cfg, lut.clone(), regs).unwrap();

    let mut r_trilin = RtlStream::new(variant_with(trilin_cfg), trilin_cfg, rng.random()).unwrap();
    let mut r_grad = RtlStream::new(variant_with(grad_cfg), grad_cfg, rng.random()).unwrap();
    let mut r_shader = RtlStream::new(variant_with(shader_cfg), shader_cfg, rng.random()).unwrap();
    for (addr, data) in tables.config_writes(&shader_cfg) {
        r_shader.write_config(addr, &data).unwrap();
    }
    let mut r_compos = RtlStream::new(variant_with(compos_cfg), compos_cfg, rng.random()).unwrap();
    for (addr, data) in m_compos.config_writes() {
        r_compos.write_config(addr, &data).unwrap();
    }

    let modes = [
        (ComposMode::FrontToBack, 70),
        (ComposMode::Max, 10),
        (ComposMode::XraySum, 10),
        (ComposMode::FirstOpaque, 10),
    ];
    let mut rays: Vec<Ray> = (0..RAYS)
        .map(|_| {
            let mut pick = rng.random_range(0..100);
            let mode = modes
                .iter()
                .find(|(_, w)| {
                    let hit = pick < *w;
                    pick -= if hit { 0 } else { *w };
                    hit
                })
                .unwrap()
                .0;
            Ray {
                len: rng.random_range(MIN_LEN..=MAX_LEN),
                density: rng.random_range(0..4096),
                mode,
                tf2d: rng.random_bool(0.1),
            }
        })
        .collect();
    let mut coxels = vec![Coxel::empty(&compos_cfg); RAYS];
    let voxel_max = i64::from(trilin_cfg.voxel_max());
    let mut samples_total = 0usize;

    for n in 0..MAX_LEN {
        let active: Vec<usize> = (0..RAYS).filter(|&r| rays[r].len > n).collect();
        if active.is_empty() {
            break;
        }
        samples_total += active.len();

        // Trilin: seven interpolations per sample around the ray's current density.
        let mut trilin_in = Vec::with_capacity(active.len() * N6_OFFSETS.len());
        for &r in &active {
            let ray = &mut rays[r];
            ray.density = (ray.density + rng.random_range(-90..=90)).clamp(0, voxel_max);
            for _ in N6_OFFSETS {
                let base = (ray.density + rng.random_range(-150..=150)).clamp(0, voxel_max);
                trilin_in.push(TrilinIn {
                    voxels: std::array::from_fn(|_| {
                        (base + rng.random_range(-60..=60)).clamp(0, voxel_max) as u32
                    }),
                    weights: std::array::from_fn(|_| rng.random_range(0..=trilin_cfg.weight_max())),
                    mode: TrilinMode::Lerp,
                });
            }
        }
        let samples = stage(
            &mut r_trilin,
            &mut m_trilin,
            &trilin_in,
            &traffic,
            "trilin",
            n,
            seed,
        );

        // Gradient, N6 on the orthogonal neighbours.
        let grad_in: Vec<GradientIn> = samples
            .chunks_exact(N6_OFFSETS.len())
            .map(n6_gradient_in)
            .collect();
        let grads: Vec<GradientOut> = stage(
            &mut r_grad,
            &mut m_grad,
            &grad_in,
            &traffic,
            "gradient",
            n,
            seed,
        );

        // Shader, through the frame's adapter (>> 4).
        let shader_in: Vec<ShaderIn> = active
            .iter()
            .zip(&grads)
            .zip(samples.chunks_exact(N6_OFFSETS.len()))
            .map(|((&r, g), s)| {
                let mode = ShaderMode {
                    tf2d: rays[r].tf2d,
                    unlit: rays[r].mode != ComposMode::FrontToBack,
                };
                shader_in(s[0], g, mode)
            })
            .collect();
        let shaded: Vec<Rgba> = stage(
            &mut r_shader,
            &mut m_shader,
            &shader_in,
            &traffic,
            "shader",
            n,
            seed,
        );

        // Compos onto the carried coxel.
        let compos_in: Vec<ComposIn> = active
            .iter()
            .zip(&shaded)
            .map(|(&r, c)| ComposIn {
                coxel: coxels[r],
                sample: Sample {
                    rgb: [c.r, c.g, c.b],
                    alpha: c.a,
                    depth: n as u32,
                    mode: rays[r].mode,
                },
            })
            .collect();
        let out = stage(
            &mut r_compos,
            &mut m_compos,
            &compos_in,
            &traffic,
            "compos",
            n,
            seed,
        );
        for (&r, c) in active.iter().zip(out) {
            coxels[r] = c;
        }
    }

    // Every stage matched the model on the same inputs, so by induction the model chain run alone
    // on this stimulus ends in the same coxels as the RTL chain.
    let terminated = coxels.iter().filter(|c| c.terminated).count();
    let opaque = coxels
        .iter()
        .filter(|c| c.rgba[3] >= compos_cfg.one() / 2)
        .count();
    eprintln!(
        "{RAYS} rays, {samples_total} samples, {} interpolations: bit-exact at every stage; {terminated} rays terminated, {opaque} at least half opaque (seed {seed})",
        samples_total * N6_OFFSETS.len()
    );
    assert!(samples_total >= RAYS * MIN_LEN);
    assert!(
        opaque > RAYS / 10,
        "the stimulus reaches the interesting part of compositing"
    );
}
