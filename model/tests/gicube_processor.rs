//! The GI-Cube block processor's renderer (docs/numerics/gicube_processor.md): accuracy against
//! its f64 reference on the head phantom, no ray lost under queue overflow, the image independent
//! of queue order, space leaping exact, early termination, bad input refused.

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::cube5_shader::Phong;
use cube5_model::units::gicube_cache::CacheConfig;
use cube5_model::units::gicube_processor::{
    half_tags, host_rays, psnr, HostOrder, Processor, ProcessorConfig, ProcessorCounts,
    ProcessorFrame, Projection, QueueOrder,
};
use cube5_model::units::gicube_sample::ShadeConfig;
use cube5_model::volume::Volume;
use glam::DVec3;

/// The head scene's view (azimuth 65, elevation 20 degrees).
fn view_dir() -> DVec3 {
    let (a, e) = (65f64.to_radians(), 20f64.to_radians());
    -DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

fn camera(vol: &Volume, px: u32) -> Camera {
    Camera::new(view_dir(), vol.dims, vol.spacing, px, px)
}

/// The GI shadow scene's view.
fn scene_camera(vol: &Volume, px: u32) -> Camera {
    Camera::new(
        DVec3::new(0.35, 0.75, -0.55).normalize(),
        vol.dims,
        vol.spacing,
        px,
        px,
    )
}

fn cfg_for(n: usize) -> ProcessorConfig {
    ProcessorConfig {
        block_log2: if n <= 32 { 3 } else { 4 },
        ..ProcessorConfig::DEFAULT
    }
}

/// The rays are conserved and every pixel with a ray got exactly one result.
fn check_conservation(f: &ProcessorFrame) {
    let c = &f.counts;
    assert_eq!(
        c.rays_in,
        c.rays_finished + c.rays_overflowed,
        "rays in = finished + overflowed: {c:?}"
    );
    assert_eq!(
        c.rays_finished, c.rays_made,
        "every ray finished once: {c:?}"
    );
}

fn psnr_case(n: usize, px: u32, proj: Projection, min_db: f64) -> (f64, f64, ProcessorFrame) {
    let vol = head_phantom(n, 12).unwrap();
    let tf = TransferFunction::head_default();
    let cam = camera(&vol, px);
    let p = Processor::new(cfg_for(n), &vol, &tf).unwrap();
    let f = p.render(&cam, proj).unwrap();
    check_conservation(&f);
    let r = p.reference(&tf, &cam, proj).unwrap();
    let (db, max) = psnr(&f.to_f64(), &r);
    let mean = r.iter().map(|c| c[0] + c[1] + c[2]).sum::<f64>() / (3 * r.len()) as f64;
    println!(
        "n={n} {proj:?}: PSNR {db:.2} dB, max {max:.4}, reference mean {mean:.3}, {:?}",
        f.counts
    );
    assert!(
        mean > 0.02,
        "the reference image is not empty (mean {mean})"
    );
    assert!(db >= min_db, "PSNR {db:.2} dB below {min_db} dB");
    (db, max, f)
}

#[test]
fn head_parallel_32_within_psnr_of_f64() {
    psnr_case(32, 64, Projection::Parallel, 45.0);
}

#[test]
fn head_parallel_64_within_psnr_of_f64() {
    psnr_case(64, 96, Projection::Parallel, 45.0);
}

#[test]
fn head_perspective_32_and_64_within_psnr_of_f64() {
    psnr_case(32, 64, Projection::Perspective { fov_deg: 30.0 }, 45.0);
    psnr_case(64, 96, Projection::Perspective { fov_deg: 30.0 }, 45.0);
}

fn render(vol: &Volume, cfg: ProcessorConfig, px: u32, proj: Projection) -> ProcessorFrame {
    let tf = TransferFunction::head_default();
    let p = Processor::new(cfg, vol, &tf).unwrap();
    let f = p.render(&camera(vol, px), proj).unwrap();
    check_conservation(&f);
    f
}

#[test]
fn forced_overflow_loses_no_ray_and_changes_no_pixel() {
    let vol = head_phantom(32, 12).unwrap();
    for proj in [
        Projection::Parallel,
        Projection::Perspective { fov_deg: 40.0 },
    ] {
        let base = render(&vol, cfg_for(32), 48, proj);
        assert_eq!(base.counts.rays_overflowed, 0, "{:?}", base.counts);
        for queue_len in [1, 3, 16] {
            let cfg = ProcessorConfig {
                queue_len,
                ..cfg_for(32)
            };
            let f = render(&vol, cfg, 48, proj);
            println!("queue_len {queue_len} {proj:?}: {:?}", f.counts);
            assert!(
                f.counts.rays_overflowed > 0,
                "queue_len {queue_len} forces overflow"
            );
            assert!(f.counts.max_queue <= queue_len);
            assert_eq!(f.rgb, base.rgb, "queue_len {queue_len}: the image changed");
        }
    }
}

#[test]
fn image_does_not_depend_on_queue_order() {
    let vol = head_phantom(32, 12).unwrap();
    let proj = Projection::Perspective { fov_deg: 30.0 };
    let base = render(&vol, cfg_for(32), 48, proj);
    let mut activations = vec![base.counts.activations];
    for (order, host_order, ranks) in [
        (QueueOrder::Scan, HostOrder::RowMajor, 16),
        (QueueOrder::Scan, HostOrder::Reversed, 16),
        (QueueOrder::Sorter, HostOrder::Reversed, 16),
        (QueueOrder::Sorter, HostOrder::RowMajor, 2),
    ] {
        let cfg = ProcessorConfig {
            order,
            host_order,
            ranks,
            queue_len: 24,
            ..cfg_for(32)
        };
        let f = render(&vol, cfg, 48, proj);
        println!("{order:?} {host_order:?} ranks {ranks}: {:?}", f.counts);
        activations.push(f.counts.activations);
        assert_eq!(
            f.rgb, base.rgb,
            "{order:?} {host_order:?}: the image changed"
        );
        assert_eq!(f.counts.samples, base.counts.samples);
        // Eight corner reads per sample through the volume cache, mostly hits.
        assert_eq!(
            f.counts.cache_hits + f.counts.cache_misses,
            8 * f.counts.samples
        );
        assert!(f.counts.cache_hit_rate() > 0.5, "{:?}", f.counts);
    }
    // The orders really differ (the test is not comparing one schedule with itself).
    activations.sort_unstable();
    activations.dedup();
    assert!(activations.len() > 1, "every order activated queues alike");
}

#[test]
fn space_leaping_is_exact_and_saves_samples() {
    let vol = head_phantom(32, 12).unwrap();
    for proj in [
        Projection::Parallel,
        Projection::Perspective { fov_deg: 30.0 },
    ] {
        let on = render(&vol, cfg_for(32), 48, proj);
        let off = render(
            &vol,
            ProcessorConfig {
                space_leap: false,
                ..cfg_for(32)
            },
            48,
            proj,
        );
        assert_eq!(on.rgb, off.rgb, "{proj:?}: leaping changed the image");
        assert_eq!(off.counts.leaps, 0);
        assert!(on.counts.leaps > 0);
        println!(
            "{proj:?}: samples {} with leaping, {} without",
            on.counts.samples, off.counts.samples
        );
        assert!(on.counts.samples < off.counts.samples);
    }
}

#[test]
fn empty_flags_follow_the_transfer_function() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = TransferFunction::head_default();
    let p = Processor::new(cfg_for(32), &vol, &tf).unwrap();
    let empty = p.empty_flags();
    assert_eq!(empty.len(), 64);
    // Corner blocks are air; the centre of the head is not.
    assert!(empty[0], "the corner block (0,0,0) is air");
    assert!(empty.iter().any(|&e| !e));
    // A transfer function opaque everywhere leaves no block empty.
    let opaque = TransferFunction::preset("grey").unwrap();
    let mut tf2 = opaque.clone();
    tf2.points[0].rgba[3] = 0.1;
    let p2 = Processor::new(cfg_for(32), &vol, &tf2).unwrap();
    assert!(p2.empty_flags().iter().all(|&e| !e));
}

#[test]
fn early_termination_stops_opaque_rays() {
    let vol = head_phantom(32, 12).unwrap();
    // Skin and everything denser nearly opaque.
    let pt = |density, a| cube5_model::transfer::TfPoint {
        density,
        rgba: [0.9, 0.7, 0.6, a],
    };
    let tf = TransferFunction::new(vec![
        pt(0.0, 0.0),
        pt(0.15, 0.0),
        pt(0.25, 0.6),
        pt(1.0, 0.6),
    ])
    .unwrap();
    let cam = camera(&vol, 48);
    let run = |et: Option<u32>| {
        let cfg = ProcessorConfig {
            et_threshold: et,
            ..cfg_for(32)
        };
        let p = Processor::new(cfg, &vol, &tf).unwrap();
        let f = p.render(&cam, Projection::Parallel).unwrap();
        check_conservation(&f);
        let r = p.reference(&tf, &cam, Projection::Parallel).unwrap();
        (f, r)
    };
    let (on, ref_on) = run(Some(4096 - 16));
    let (off, ref_off) = run(None);
    println!("termination: {:?}\nnone: {:?}", on.counts, off.counts);
    assert!(on.counts.rays_terminated > 0);
    assert_eq!(off.counts.rays_terminated, 0);
    assert!(on.counts.samples < off.counts.samples);
    let (db_on, _) = psnr(&on.to_f64(), &ref_on);
    let (db_off, _) = psnr(&off.to_f64(), &ref_off);
    let (db_et, _) = psnr(&on.to_f64(), &off.to_f64());
    println!("PSNR vs f64: {db_on:.1} dB with termination, {db_off:.1} dB without; {db_et:.1} dB between");
    assert!(db_on > 40.0 && db_off > 40.0 && db_et > 40.0);
}

#[test]
fn host_rays_hit_the_volume_and_diverge_in_perspective() {
    let vol = head_phantom(32, 12).unwrap();
    let cam = camera(&vol, 32);
    let par = host_rays(&vol, &cam, Projection::Parallel, HostOrder::RowMajor).unwrap();
    assert!(par.iter().all(|r| (r.dir - cam.dir).length() < 1e-12));
    let per = host_rays(
        &vol,
        &cam,
        Projection::Perspective { fov_deg: 60.0 },
        HostOrder::RowMajor,
    )
    .unwrap();
    for r in par.iter().chain(&per) {
        assert!(r.entry.min_element() >= -1e-9 && r.entry.max_element() <= 31.0 + 1e-9);
    }
    let left = per.iter().min_by_key(|r| r.px).unwrap();
    let right = per.iter().max_by_key(|r| r.px).unwrap();
    assert!(left.px + 8 < right.px);
    assert!(left.dir.dot(cam.right) < right.dir.dot(cam.right));
}

#[test]
fn bad_input_is_refused_with_one_line() {
    let tf = TransferFunction::head_default();
    let vol = head_phantom(16, 12).unwrap();
    let msg = |e: cube5_model::ModelError| {
        let s = e.to_string();
        assert!(!s.contains('\n'), "{s}");
        s
    };
    let aniso = Volume::new([8, 8, 8], [1.0, 1.0, 2.0], 8, vec![0; 512]).unwrap();
    let p = Processor::new(cfg_for(16), &aniso, &tf).unwrap();
    let cam = Camera::new(view_dir(), aniso.dims, aniso.spacing, 8, 8);
    assert!(msg(p.render(&cam, Projection::Parallel).unwrap_err()).contains("anisotropic"));
    for bad in [
        ProcessorConfig {
            step: 0,
            ..cfg_for(16)
        },
        ProcessorConfig {
            queue_len: 0,
            ..cfg_for(16)
        },
        ProcessorConfig {
            block_log2: 1,
            ..cfg_for(16)
        },
        ProcessorConfig {
            et_threshold: Some(0),
            ..cfg_for(16)
        },
    ] {
        msg(Processor::new(bad, &vol, &tf).unwrap_err());
    }
    // 64^3 in blocks of 8: 512 blocks, more than the sorter's 256 queues.
    let big = head_phantom(64, 12).unwrap();
    let e = msg(Processor::new(cfg_for(32), &big, &tf).unwrap_err());
    assert!(e.contains("256 queues"), "{e}");
    let p = Processor::new(cfg_for(16), &vol, &tf).unwrap();
    for proj in [
        Projection::Perspective { fov_deg: 0.0 },
        Projection::Perspective { fov_deg: f64::NAN },
    ] {
        msg(p.render(&camera(&vol, 8), proj).unwrap_err());
    }
    let mut cam = camera(&vol, 8);
    cam.dir = DVec3::ZERO;
    msg(p.render(&cam, Projection::Parallel).unwrap_err());
    cam = camera(&vol, 8);
    cam.width = 5000;
    msg(p.render(&cam, Projection::Parallel).unwrap_err());
}

/// The ring latency (contract, *The ring*) changes the counts, never a pixel: latencies 0, 1, 3
/// and 16 on the head at 32^3 with short queues (overflow), every ray finished once, each frame
/// its own cycle count; and a latency above the RTL's 16 is refused.
#[test]
fn ring_latency_changes_counts_not_pixels() {
    let tf = TransferFunction::head_default();
    let vol = head_phantom(32, 12).unwrap();
    let cam = camera(&vol, 32);
    let frames: Vec<ProcessorFrame> = [0, 1, 3, 16]
        .into_iter()
        .map(|ring_latency| {
            let cfg = ProcessorConfig {
                queue_len: 8,
                ring_latency,
                ..cfg_for(32)
            };
            let f = Processor::new(cfg, &vol, &tf)
                .unwrap()
                .render(&cam, Projection::Parallel)
                .unwrap();
            check_conservation(&f);
            f
        })
        .collect();
    for f in &frames[1..] {
        assert_eq!(
            f.rgb, frames[0].rgb,
            "the image does not depend on the ring"
        );
        assert_eq!(
            (f.counts.samples, f.counts.leaps),
            (frames[0].counts.samples, frames[0].counts.leaps)
        );
        assert!(f.counts.rays_overflowed > 0, "{:?}", f.counts);
    }
    let cycles: std::collections::BTreeSet<u64> = frames.iter().map(|f| f.counts.cycles).collect();
    assert_eq!(
        cycles.len(),
        frames.len(),
        "each latency its own cycle count"
    );
    let bad = ProcessorConfig {
        ring_latency: 17,
        ..cfg_for(32)
    };
    assert!(Processor::new(bad, &vol, &tf).is_err());
}

mod gi {
    use super::*;
    use cube5_model::units::gicube_processor::{
        irradiance_error, monte_carlo_gi, shadow_scene, GiLight, IRR_FRAC_W,
    };

    /// Irradiance (real) of the voxel nearest `p`.
    fn irr_at(field: &[u16], n: usize, p: DVec3) -> f64 {
        let v = p.round().as_ivec3();
        f64::from(field[v.x as usize + n * (v.y as usize + n * v.z as usize)])
            / f64::from(1u32 << IRR_FRAC_W)
    }

    #[test]
    fn lighting_pass_casts_a_shadow_and_gi_matches_its_f64_reference() {
        let n = 32;
        let (vol, tf, light) = shadow_scene(n).unwrap();
        let cfg = ProcessorConfig {
            block_log2: 3,
            ..ProcessorConfig::DEFAULT
        };
        let mut p = Processor::new(cfg, &vol, &tf).unwrap();
        let lc = p.light(&light).unwrap();
        check_conservation(&lc);
        println!("lighting pass: {:?}", lc.counts);
        let field = p.irradiance().unwrap().to_vec();
        // The floor under the sphere, along the light, against the floor on the other side.
        let nf = n as f64;
        let centre = DVec3::new(0.5, 0.5, 0.58) * (nf - 1.0);
        let floor_z = (0.22 * nf - 1.0).round();
        let t = (centre.z - floor_z) / -light.dir.z;
        let shadow = centre + light.dir * t;
        let lit = DVec3::new(nf - 1.0 - shadow.x, nf - 1.0 - shadow.y, floor_z);
        let (e_shadow, e_lit) = (irr_at(&field, n, shadow), irr_at(&field, n, lit));
        println!("irradiance in the shadow {e_shadow:.3}, in the light {e_lit:.3}");
        assert!(e_lit > 0.3, "the lit floor gets light: {e_lit}");
        assert!(e_shadow < 0.5 * e_lit, "the sphere shadows the floor");
        // Against the f64 irradiance.
        let rf = p.reference_irradiance(&tf, &light).unwrap();
        let (max_err, mean) = irradiance_error(&field, &rf, vol.dims);
        println!("irradiance vs f64: interior max {max_err:.4}, mean {mean:.5}");
        assert!(
            max_err < 0.1 && mean < 0.01,
            "irradiance error {max_err} / {mean}"
        );
        let cam = scene_camera(&vol, 64);
        let f = p.render(&cam, Projection::Parallel).unwrap();
        check_conservation(&f);
        let r = p
            .reference_gi(&tf, &light, &cam, Projection::Parallel)
            .unwrap();
        let (db, max) = psnr(&f.to_f64(), &r);
        println!("GI image vs f64 GI: PSNR {db:.2} dB, max {max:.4}");
        assert!(db > 45.0, "GI PSNR {db}");
        // The lighting matters: the GI image is far from the unlit one.
        let unlit = p.reference(&tf, &cam, Projection::Parallel).unwrap();
        let (db_unlit, _) = psnr(&f.to_f64(), &unlit);
        println!("GI image vs unlit f64: {db_unlit:.2} dB");
        assert!(db_unlit < 30.0, "GI changed little: {db_unlit} dB");
        let mc = monte_carlo_gi(&vol, &tf, &light, &cam, Projection::Parallel, 3, 64, 1).unwrap();
        let (db_mc, max_mc) = psnr(&r, &mc);
        let (db_mc_fx, _) = psnr(&f.to_f64(), &mc);
        println!("f64 GI vs Monte Carlo (64 paths): PSNR {db_mc:.2} dB, max {max_mc:.4}; fixed point vs MC {db_mc_fx:.2} dB");
        assert!(db_mc > 25.0, "GI method vs MC {db_mc}");
    }

    /// The lighting pass through a splatting cache (contract, *Splatting through the cache*):
    /// one item per sample (a lighting sample's deposit is its read), in the sample order, then a
    /// flush. Memory then holds the volume with the field above it, equal to `irradiance()` and
    /// to the field of a read-only cache (the same additions in the same order); the counts and
    /// the two-pass image equal; every missed line read once and every dirty line written back.
    #[test]
    fn lighting_through_the_splatting_cache_leaves_the_field_in_memory() {
        let n = 16;
        let (vol, tf, light) = shadow_scene(n).unwrap();
        let splat = CacheConfig {
            max_dim: 32,
            word_w: 32,
            data_w: 64,
            line_vox: 8,
            sets: 8,
            splat: 1,
            ..CacheConfig::DEFAULT
        };
        let cfg = |cache| ProcessorConfig {
            block_log2: 2,
            ring_latency: 3,
            cache: Some(cache),
            ..ProcessorConfig::DEFAULT
        };
        let mut p = Processor::new(cfg(splat), &vol, &tf).unwrap();
        let (lc, t) = p.light_cache_traced(&light).unwrap();
        check_conservation(&lc);
        let field = p.irradiance().unwrap().to_vec();
        assert!(field.iter().any(|&v| v > 0));
        let m = splat.max_dim as usize;
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    let w = t.memory[x + m * (y + m * z)];
                    let inside = x < n && y < n && z < n;
                    let irr = if inside {
                        field[x + n * (y + n * z)]
                    } else {
                        0
                    };
                    assert_eq!(w >> 16, u32::from(irr), "field at ({x}, {y}, {z})");
                    assert_eq!(w & 0xffff, vol.get(x as i64, y as i64, z as i64));
                }
            }
        }
        assert_eq!(t.reads.len() as u64, lc.counts.cache_misses);
        assert!(!t.writes.is_empty());
        let read_only = CacheConfig {
            word_w: 16,
            splat: 0,
            ..splat
        };
        let mut q = Processor::new(cfg(read_only), &vol, &tf).unwrap();
        let (lq, tq) = q.light_cache_traced(&light).unwrap();
        assert_eq!(q.irradiance().unwrap(), field.as_slice());
        // The same lines (at other byte addresses: the words are narrower).
        assert_eq!((lq.counts, tq.reads.len()), (lc.counts, t.reads.len()));
        assert!(tq.writes.is_empty());
        let cam = scene_camera(&vol, 16);
        let (fp, fq) = (
            p.render(&cam, Projection::Parallel).unwrap(),
            q.render(&cam, Projection::Parallel).unwrap(),
        );
        assert_eq!((fp.rgb, fp.counts), (fq.rgb, fq.counts));
        println!(
            "16^3 lighting pass: {} samples, {} lines read, {} written back (flush included)",
            lc.counts.samples,
            t.reads.len(),
            t.writes.len()
        );
    }

    #[test]
    fn irradiance_does_not_depend_on_queue_order() {
        let (vol, tf, light) = shadow_scene(24).unwrap();
        let field = |order, host_order, queue_len| {
            let cfg = ProcessorConfig {
                block_log2: 3,
                order,
                host_order,
                queue_len,
                ..ProcessorConfig::DEFAULT
            };
            let mut p = Processor::new(cfg, &vol, &tf).unwrap();
            let f = p.light(&light).unwrap();
            check_conservation(&f);
            (p.irradiance().unwrap().to_vec(), f.counts)
        };
        let (base, c0) = field(QueueOrder::Sorter, HostOrder::RowMajor, 256);
        assert!(base.iter().any(|&v| v > 0));
        for (o, h, len) in [
            (QueueOrder::Scan, HostOrder::Reversed, 256),
            (QueueOrder::Sorter, HostOrder::Reversed, 5),
        ] {
            let (f, c) = field(o, h, len);
            println!("{o:?} {h:?} {len}: {c:?} (base {c0:?})");
            assert_eq!(f, base, "{o:?} {h:?} queue_len {len}");
        }
    }

    #[test]
    fn bad_light_is_refused() {
        let (vol, tf, light) = shadow_scene(16).unwrap();
        let mut p = Processor::new(cfg_for(16), &vol, &tf).unwrap();
        for bad in [
            GiLight {
                dir: DVec3::ZERO,
                ..light
            },
            GiLight { grid: 0, ..light },
            GiLight { grid: 4, ..light },
            GiLight {
                energy: f64::NAN,
                ..light
            },
        ] {
            let e = p.light(&bad).unwrap_err().to_string();
            assert!(!e.contains('\n') && e.contains("lighting pass"), "{e}");
        }
    }
}

mod high_albedo {
    use super::*;
    use cube5_model::units::gicube_processor::{monte_carlo_gi, shadow_scene, GiLight, GiMode};

    fn photons(light: GiLight) -> GiLight {
        GiLight {
            mode: GiMode::HighAlbedo {
                albedo: 0.8,
                lifetime: 8,
            },
            ..light
        }
    }

    #[test]
    fn photons_scatter_into_the_shadow_deterministically_and_in_any_order() {
        let n = 32;
        let (vol, tf, light) = shadow_scene(n).unwrap();
        let run = |light: &GiLight, order, host_order, queue_len| {
            let cfg = ProcessorConfig {
                block_log2: 3,
                order,
                host_order,
                queue_len,
                ..ProcessorConfig::DEFAULT
            };
            let mut p = Processor::new(cfg, &vol, &tf).unwrap();
            let f = p.light(light).unwrap();
            check_conservation(&f);
            (p, f.counts)
        };
        let hi = photons(light);
        let (p_hi, c_hi) = run(&hi, QueueOrder::Sorter, HostOrder::RowMajor, 256);
        println!("high albedo: {c_hi:?}");
        assert!(c_hi.scatterings > 0 && c_hi.absorbed > 0);
        assert_eq!(
            c_hi.rays_terminated, 0,
            "photons end by absorption or by leaving"
        );
        let f_hi = p_hi.irradiance().unwrap().to_vec();
        // Hash-drawn randomness: the same field in another order, with overflow.
        let (p2, c2) = run(&hi, QueueOrder::Scan, HostOrder::Reversed, 7);
        assert!(c2.rays_overflowed > 0);
        assert_eq!(p2.irradiance().unwrap(), &f_hi[..]);
        // Scattered light brightens the shadow (and everything else a little).
        let (p_lo, _) = run(&light, QueueOrder::Sorter, HostOrder::RowMajor, 256);
        let f_lo = p_lo.irradiance().unwrap();
        let sum = |f: &[u16]| f.iter().map(|&v| u64::from(v)).sum::<u64>();
        println!(
            "total irradiance: low albedo {}, high albedo {}",
            sum(f_lo),
            sum(&f_hi)
        );
        assert!(sum(&f_hi) > sum(f_lo));
        // The high-albedo pass has no f64 reference of its own (stochastic): a clear error.
        let e = p_hi.reference_irradiance(&tf, &hi).unwrap_err().to_string();
        assert!(e.contains("Monte Carlo"), "{e}");
    }

    #[test]
    fn high_albedo_gi_is_near_its_monte_carlo_reference() {
        let n = 32;
        let (vol, tf, light) = shadow_scene(n).unwrap();
        let hi = photons(light);
        let cfg = ProcessorConfig {
            block_log2: 3,
            ..ProcessorConfig::DEFAULT
        };
        let mut p = Processor::new(cfg, &vol, &tf).unwrap();
        p.light(&hi).unwrap();
        let cam = scene_camera(&vol, 48);
        let f = p.render(&cam, Projection::Parallel).unwrap();
        let mc = monte_carlo_gi(&vol, &tf, &hi, &cam, Projection::Parallel, 3, 64, 7).unwrap();
        let mc_single =
            monte_carlo_gi(&vol, &tf, &light, &cam, Projection::Parallel, 3, 64, 7).unwrap();
        let (db, _) = psnr(&f.to_f64(), &mc);
        let (db_single, _) = psnr(&f.to_f64(), &mc_single);
        println!("high-albedo GI vs MC (high albedo) {db:.1} dB, vs MC single scattering {db_single:.1} dB");
        assert!(db > 22.0, "{db}");
        assert!(db > db_single, "the photons' scattered light is real");
    }
}

/// Jitter off is the processor's default (every test above); on, the image stays within 40 dB of
/// its f64 reference, which takes each sample's factor from the same random LUT at the f64
/// position's fraction bits (measured 44.0 dB: where the packet's rounded position has other
/// fraction bits the two samples take different factors, the largest pixel error 0.094).
#[test]
fn jittered_head_within_psnr_of_its_f64_reference() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = TransferFunction::head_default();
    let cam = camera(&vol, 64);
    let proj = Projection::Perspective { fov_deg: 30.0 };
    let cfg = ProcessorConfig {
        jitter: true,
        ..cfg_for(32)
    };
    let p = Processor::new(cfg, &vol, &tf).unwrap();
    let f = p.render(&cam, proj).unwrap();
    check_conservation(&f);
    let (db, max) = psnr(&f.to_f64(), &p.reference(&tf, &cam, proj).unwrap());
    let plain = Processor::new(cfg_for(32), &vol, &tf).unwrap();
    let g = plain.render(&cam, proj).unwrap();
    let (db_plain, _) = psnr(&f.to_f64(), &g.to_f64());
    println!(
        "jitter: PSNR {db:.2} dB, max {max:.4}; against the unjittered image {db_plain:.2} dB"
    );
    assert!(db >= 40.0, "PSNR {db:.2} dB below 40 dB");
    assert!(f.rgb != g.rgb, "the jitter changed the image");
}

/// Shading (contract, *Shading and jitter in the processor*): the head at 32^3 with the
/// viewer's two-light map, tagged in two halves (`half_tags`), its voxel words holding 11-bit
/// (and 7-bit, the CI line's) gradient indices; alone and with jitter, each within its bound of
/// the f64 reference (Phong at the interpolated exact gradient directions, the tag's colour, the
/// same jitter factors), and far from the unshaded image (the map lights it). Measured 51.8 dB
/// (max 0.049), with jitter 46.4 dB (0.072), 7-bit indices 48.3 dB (0.085); the unshaded image
/// is 25.6-27.3 dB away.
#[test]
fn shaded_head_within_psnr_of_its_f64_reference() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = TransferFunction::head_default();
    let cam = camera(&vol, 64);
    let proj = Projection::Perspective { fov_deg: 30.0 };
    let phong = Phong {
        view: (-view_dir()).to_array(),
        ..Phong::two_lights()
    };
    let flat = Processor::new(cfg_for(32), &vol, &tf)
        .unwrap()
        .render(&cam, proj)
        .unwrap();
    for (jitter, grad_idx_w, min_db) in [(false, 11, 48.0), (true, 11, 43.0), (false, 7, 45.0)] {
        let cfg = ProcessorConfig {
            jitter,
            shade: Some(ShadeConfig {
                grad_idx_w,
                tag_w: 1,
            }),
            ..cfg_for(32)
        };
        let mut p = Processor::new(cfg, &vol, &tf).unwrap();
        p.set_shading(&phong, Some(half_tags(&vol))).unwrap();
        let f = p.render(&cam, proj).unwrap();
        check_conservation(&f);
        let (db, max) = psnr(&f.to_f64(), &p.reference(&tf, &cam, proj).unwrap());
        let (db_flat, _) = psnr(&f.to_f64(), &flat.to_f64());
        println!(
            "shaded (GradIdxW {grad_idx_w}, jitter {jitter}): PSNR {db:.2} dB, max {max:.4}; against the unshaded image {db_flat:.2} dB"
        );
        assert!(db >= min_db, "PSNR {db:.2} dB below {min_db} dB");
        assert!(
            db_flat < db - 6.0,
            "shading changed the image ({db_flat:.2} dB)"
        );
    }
}

/// The samples read through the volume cache (contract, *The volume cache*): another cache
/// geometry changes the hit and miss counts, never a pixel or another count; one AXI4 burst per
/// missed line; a cache whose `MaxDim` does not exceed the domain is refused.
#[test]
fn the_volume_cache_changes_its_counts_not_the_image() {
    let vol = head_phantom(32, 12).unwrap();
    let tf = TransferFunction::head_default();
    let cam = camera(&vol, 48);
    let proj = Projection::Parallel;
    let base = Processor::new(cfg_for(32), &vol, &tf).unwrap();
    let (want, bursts) = base.render_cache_traced(&cam, proj).unwrap();
    assert_eq!(bursts.len() as u64, want.counts.cache_misses);
    assert_eq!(
        want.counts.cache_hits + want.counts.cache_misses,
        8 * want.counts.samples
    );
    let small = CacheConfig {
        max_dim: 64,
        sets: 4,
        line_vox: 8,
        ..CacheConfig::DEFAULT
    };
    let p = Processor::new(
        ProcessorConfig {
            cache: Some(small),
            ..cfg_for(32)
        },
        &vol,
        &tf,
    )
    .unwrap();
    let f = p.render(&cam, proj).unwrap();
    assert_eq!(f.rgb, want.rgb);
    let strip = |c: ProcessorCounts| ProcessorCounts {
        cache_hits: 0,
        cache_misses: 0,
        ..c
    };
    assert_eq!(strip(f.counts), strip(want.counts));
    assert!(
        f.counts.cache_misses > want.counts.cache_misses,
        "four sets of short lines miss more: {:?} vs {:?}",
        f.counts,
        want.counts
    );
    println!(
        "32^3 parallel: hit rate {:.3} (default cache at M = 64), {:.3} (4 sets of 8 voxels)",
        want.counts.cache_hit_rate(),
        f.counts.cache_hit_rate()
    );
    for bad in [
        CacheConfig {
            max_dim: 32,
            ..CacheConfig::DEFAULT
        },
        CacheConfig {
            word_w: 8,
            ..CacheConfig::DEFAULT
        },
    ] {
        let cfg = ProcessorConfig {
            cache: Some(bad),
            ..cfg_for(32)
        };
        assert!(Processor::new(cfg, &vol, &tf).is_err(), "{bad:?}");
    }
}
