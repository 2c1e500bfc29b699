//! A ring of GI-Cube block processors (docs/numerics/gicube_ring.md): one processor in a ring is
//! the processor, counts and all; 2 and 4 processors render the single processor's image bit for
//! bit, send rays to their neighbours, lose none, and at every RTL configuration.

use cube5_model::camera::Camera;
use cube5_model::phantom::head_phantom;
use cube5_model::transfer::TransferFunction;
use cube5_model::units::gicube_processor::{
    Processor, ProcessorConfig, ProcessorCounts, ProcessorRtlConfig, Projection,
};
use cube5_model::units::gicube_ring::{Ring, RingRtlConfig};
use cube5_model::volume::Volume;
use glam::DVec3;

fn camera(vol: &Volume, px: u32) -> Camera {
    let (a, e) = (65f64.to_radians(), 20f64.to_radians());
    let dir = -DVec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
    Camera::new(dir, vol.dims, vol.spacing, px, px)
}

fn processor(n: usize, cfg: ProcessorConfig) -> (Processor, Volume) {
    let vol = head_phantom(n, 12).unwrap();
    let p = Processor::new(cfg, &vol, &TransferFunction::head_default()).unwrap();
    (p, vol)
}

/// 32^3 in 8^3 blocks (4 a side), a ring latency of 8.
fn cfg32(queue_len: u32) -> ProcessorConfig {
    ProcessorConfig {
        block_log2: 3,
        queue_len,
        ring_latency: 8,
        ..ProcessorConfig::DEFAULT
    }
}

#[test]
fn one_processor_ring_is_the_processor() {
    for proj in [
        Projection::Parallel,
        Projection::Perspective { fov_deg: 40.0 },
    ] {
        for queue_len in [4, 256] {
            let (p, vol) = processor(32, cfg32(queue_len));
            let cam = camera(&vol, 24);
            let single = p.render(&cam, proj).unwrap();
            let ring = Ring::new(p, 1).unwrap().render(&cam, proj).unwrap();
            ring.check_conservation().unwrap();
            assert_eq!(ring.rgb, single.rgb);
            let c = ring.counts[0];
            let want = ProcessorCounts {
                rays_made: 0,
                ..single.counts
            };
            assert_eq!(c, want, "{proj:?} q{queue_len}");
            assert_eq!(ring.links[0].nb_out, 0);
        }
    }
}

#[test]
fn two_and_four_processors_render_the_single_image() {
    for proj in [
        Projection::Parallel,
        Projection::Perspective { fov_deg: 40.0 },
    ] {
        for queue_len in [4, 16, 256] {
            let (p, vol) = processor(32, cfg32(queue_len));
            let cam = camera(&vol, 24);
            let single = p.render(&cam, proj).unwrap();
            for procs in [2, 4] {
                let ring = Ring::new(p.clone(), procs).unwrap();
                let f = ring.render(&cam, proj).unwrap();
                f.check_conservation().unwrap();
                assert_eq!(
                    f.rgb, single.rgb,
                    "{procs} processors, {proj:?} q{queue_len}"
                );
                let sent: u64 = f.links.iter().map(|l| l.nb_out).sum();
                assert!(sent > 0, "rays cross the slabs");
                let samples: u64 = f.counts.iter().map(|c| c.samples).sum();
                let leaps: u64 = f.counts.iter().map(|c| c.leaps).sum();
                // A ray's samples and leaps are its own, wherever it is processed.
                assert_eq!(samples, single.counts.samples);
                assert_eq!(leaps, single.counts.leaps);
                for c in &f.counts {
                    assert!(c.samples > 0, "every slab works: {:?}", f.counts);
                }
                assert!(
                    f.cycles() < single.counts.cycles,
                    "{procs} processors take fewer cycles: {} vs {}",
                    f.cycles(),
                    single.counts.cycles
                );
            }
        }
    }
}

#[test]
fn full_links_return_rays_to_the_host_and_lose_none() {
    // Queues of 1 ray: the links and the queues refuse rays in every frame.
    let (p, vol) = processor(32, cfg32(1));
    let cam = camera(&vol, 16);
    let single = p.render(&cam, Projection::Parallel).unwrap();
    let f = Ring::new(p, 2)
        .unwrap()
        .render(&cam, Projection::Parallel)
        .unwrap();
    f.check_conservation().unwrap();
    assert_eq!(f.rgb, single.rgb);
    assert!(f.counts.iter().all(|c| c.rays_overflowed > 0), "{f:?}");
    assert!(
        f.links.iter().any(|l| l.nb_refused > 0),
        "a full link: {f:?}"
    );
}

#[test]
fn the_ring_runs_at_every_rtl_configuration() {
    for cfg in [
        RingRtlConfig {
            proc: ProcessorRtlConfig {
                prefetch: 4,
                data_w: 32,
                line_vox: 8,
                sets: 8,
                ..ProcessorRtlConfig::DEFAULT
            },
            ..RingRtlConfig::DEFAULT
        },
        RingRtlConfig {
            proc: ProcessorRtlConfig {
                block_log2: 3,
                voxel_w: 12,
                ..ProcessorRtlConfig::DEFAULT
            },
            ..RingRtlConfig::DEFAULT
        },
    ] {
        cfg.validate().unwrap();
        let rtl = cfg.processor();
        let vol = head_phantom(rtl.side() as usize, rtl.voxel_w).unwrap();
        let p = Processor::new(
            rtl.processor_config(),
            &vol,
            &TransferFunction::head_default(),
        )
        .unwrap();
        let cam = camera(&vol, 16);
        let single = p.render(&cam, Projection::Parallel).unwrap();
        let (f, reads) = Ring::new(p, cfg.procs())
            .unwrap()
            .render_cache_traced(&cam, Projection::Parallel)
            .unwrap();
        f.check_conservation().unwrap();
        assert_eq!(f.rgb, single.rgb);
        assert_eq!(reads.len(), 2);
        assert!(reads.iter().all(|r| !r.is_empty()));
    }
}

#[test]
fn bad_rings_are_refused() {
    let (p, _) = processor(32, cfg32(16));
    for procs in [0, 3, 8] {
        let e = Ring::new(p.clone(), procs).unwrap_err().to_string();
        assert!(e.contains("processors") && !e.contains('\n'), "{e}");
    }
    let bad = RingRtlConfig {
        proc: ProcessorRtlConfig {
            vol_blocks: 3,
            ..ProcessorRtlConfig::DEFAULT
        },
        ..RingRtlConfig::DEFAULT
    };
    assert!(bad.validate().is_err());
}
