//! DRAM to beams in RTL (issue 12): `cube5_vol_fetch` reads random volumes in the blocked layout
//! from the test bench's AXI4 memory (random latency 10..200, ARREADY/RVALID gaps, output
//! back-pressure); the items it delivers, as the RTL delivered them, are fed with their section
//! commands into `cube5_section_buf` (random idle and back-pressure); every beam must equal the
//! reference read straight from the volume (`section_beams`). Runs on every pair of builds of the
//! two tops that agree on P, the block edge and the voxel width (at least one pair must exist):
//!
//!     CUBE5_TOPS=cube5_vol_fetch,cube5_section_buf cargo test --release -p cube5-tb --test fetch_to_beams

mod support;

use cube5_model::units::cube5_section_buf::{
    frame_dims, section_beams, Beam, SectionBufConfig, SectionCmd,
};
use cube5_model::units::cube5_vol_fetch::{
    dram_image, FetchCmd, FetchItem, VolFetch, VolFetchConfig,
};
use cube5_tb::rtl::{RtlStream, Traffic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use support::{
    axi_mem_setup, axi_protocol_clean, configs, random_blocked_volume, section_buf_input, seed,
};

#[test]
fn dram_to_beams_through_both_rtl_units() {
    let mut pairs = 0;
    for (fv, fcfg) in configs::<VolFetchConfig>() {
        for (sv, scfg) in configs::<SectionBufConfig>() {
            if (fcfg.p, fcfg.block_dim, fcfg.voxel_w)
                != (scfg.item_p(), scfg.block_dim, scfg.voxel_w)
            {
                continue;
            }
            pairs += 1;
            for k in 0..4 {
                one_case(fv, fcfg, sv, scfg, seed(900 + k));
            }
        }
    }
    assert!(
        pairs > 0,
        "no build of cube5_vol_fetch agrees with one of cube5_section_buf on P, B and VoxelW"
    );
}

/// One random volume, a few views, every section of each: fetch RTL, then buffer RTL.
fn one_case(
    fv: &'static cube5_tb::Variant,
    fcfg: VolFetchConfig,
    sv: &'static cube5_tb::Variant,
    scfg: SectionBufConfig,
    s: u64,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(s);
    let edge = fcfg.max_dim.min(scfg.max_dim).min(48) as usize;
    let p = scfg.p as usize;
    let dims = [0; 3].map(|_: usize| rng.random_range(1..=edge / p) * p);
    let (vol, lut) = random_blocked_volume(dims, scfg.block_dim, scfg.voxel_w, &mut rng);
    let bbus = u64::from(fcfg.data_w / 8);
    let base = rng.random_range(0..4096 / bbus) * bbus;
    let img = dram_image(&vol, &lut, base).unwrap();
    // Every section of the face, for a few random views.
    let mut cmds = Vec::new();
    for _ in 0..4 {
        let axis_k = rng.random_range(0..3u32);
        let fd = frame_dims(vol.dims, axis_k);
        let reversed = rng.random_bool(0.5);
        for a0 in (0..fd[0]).step_by(scfg.section as usize) {
            cmds.push(SectionCmd {
                axis_k,
                reversed,
                dims: fd,
                a0,
            });
        }
    }
    // The fetch: LUT, then one sweep per section, on the RTL with the AXI memory.
    let mut fetch_in = fcfg.lut_writes(&lut).unwrap();
    fetch_in.extend(cmds.iter().map(|c| FetchCmd::Sweep(scfg.sweep(c, base))));
    let want_items = VolFetch::new(fcfg)
        .unwrap()
        .run(&fetch_in, &img)
        .unwrap()
        .items;
    let mut fetch = RtlStream::new(fv, fcfg, s as u32).unwrap();
    let setup = axi_mem_setup(
        (fcfg.data_w / 8, fcfg.addr_w),
        &img,
        (10, 190),
        (100, 100),
        (0, 1),
        rng.random(),
    );
    fetch.axi_setup(&setup).unwrap();
    fetch.axi_load(img.base, &img.bytes).unwrap();
    let traffic = Traffic::random(&mut rng, 0.2, 0.3);
    let n = want_items.len() as u64;
    let d = fetch
        .drive(&fetch_in, &traffic, n, 100_000 + 400 * n)
        .unwrap();
    axi_protocol_clean(&fetch, &d.stats, fv, s).unwrap_or_else(|e| panic!("{e}"));
    let items: Vec<FetchItem> = d.outputs.into_iter().map(|t| t.value).collect();
    assert_eq!(items.len(), want_items.len(), "{fv}: every item delivered");
    assert!(
        items == want_items,
        "{fv}: the fetch's items equal its model's"
    );
    // The buffer: each section command, then the items of its sweep (up to `last`).
    let input = section_buf_input(&cmds, items);
    let mut want: Vec<Beam> = Vec::new();
    for c in &cmds {
        want.extend(section_beams(&scfg, &vol, &lut, c).unwrap());
    }
    let mut sbuf = RtlStream::new(sv, scfg, s as u32).unwrap();
    let traffic = Traffic::random(&mut rng, 0.2, 0.3);
    let m = want.len() as u64;
    let d = sbuf
        .drive(&input, &traffic, m, 100_000 + 20 * (m + input.len() as u64))
        .unwrap();
    assert_eq!(d.outputs.len(), want.len(), "{sv}: every beam out");
    for (k, t) in d.outputs.iter().enumerate() {
        assert_eq!(
            t.value, want[k],
            "{fv} -> {sv}: beam {k} (seed {s}) differs from the volume's"
        );
    }
    eprintln!(
                "{fv} -> {sv}: volume {:?}, {} sections, {} items, {} beams: every beam equals the volume's",
                vol.dims,
                cmds.len(),
                input.len() - cmds.len(),
                want.len()
            );
}
