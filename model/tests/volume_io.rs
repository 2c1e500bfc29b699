//! Volume files: the shipped examples are the phantoms they claim to be; phantoms written as NRRD
//! and NIfTI read back exactly; and the NRRD and NIfTI header parsers never panic (proptest,
//! a bounded number of cases in the normal test run).

use cube5_model::phantom::phantom_by_name;
use cube5_model::volume::Volume;
use cube5_model::volume_io::{
    parse_nifti_header, parse_nrrd_header, read_nifti, read_nrrd, read_raw, write_nifti,
    write_nrrd, Endian, NrrdEncoding, RawSpec, VoxelType,
};
use proptest::prelude::*;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cube5-model-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn shipped_volumes_are_the_phantoms() {
    let data = cube5_model::repo_root().join("scenes/data");
    let head8 = phantom_by_name("head", 64, 8).unwrap();
    assert!(same(
        &read_nifti(&data.join("head64.nii.gz"), None).unwrap(),
        &head8
    ));
    let head12 = phantom_by_name("head", 64, 12).unwrap();
    assert!(same(
        &read_nrrd(&data.join("head64.nrrd"), Some(12)).unwrap(),
        &head12
    ));
    let bubbles = phantom_by_name("bubbles", 32, 12).unwrap();
    let spec = RawSpec {
        dims: [32; 3],
        voxel_type: VoxelType::U16,
        endian: Endian::Little,
        spacing: [1.0; 3],
        offset: 0,
    };
    assert!(same(
        &read_raw(&data.join("bubbles32.raw"), &spec, Some(12)).unwrap(),
        &bubbles
    ));
    for f in ["head64.nii.gz", "head64.nrrd", "bubbles32.raw"] {
        let len = std::fs::metadata(data.join(f)).unwrap().len();
        assert!(
            len < 300_000,
            "{f} is {len} bytes: ship small examples only"
        );
    }
}

#[test]
fn phantoms_round_trip_through_nrrd_and_nifti() {
    for (name, bits) in [("head", 12), ("sphere", 8), ("bubbles", 16)] {
        let mut vol = phantom_by_name(name, 20, bits).unwrap();
        vol.spacing = [0.75, 1.0, 1.25]; // exact in the f32 of NIfTI's pixdim
        let nii = scratch(&format!("{name}.nii.gz"));
        write_nifti(&nii, &vol, name).unwrap();
        assert!(
            same(&read_nifti(&nii, Some(bits)).unwrap(), &vol),
            "{name} NIfTI"
        );
        for enc in [NrrdEncoding::Raw, NrrdEncoding::Gzip] {
            let nrrd = scratch(&format!("{name}-{enc:?}.nrrd"));
            write_nrrd(&nrrd, &vol, enc, name).unwrap();
            assert!(
                same(&read_nrrd(&nrrd, Some(bits)).unwrap(), &vol),
                "{name} NRRD {enc:?}"
            );
        }
    }
}

#[test]
fn detached_nrrd_and_big_endian_nifti() {
    let vol = phantom_by_name("sphere", 6, 12).unwrap();
    let raw = scratch("detached.raw");
    let bytes: Vec<u8> = vol.data.iter().flat_map(|v| v.to_be_bytes()).collect();
    std::fs::write(&raw, &bytes).unwrap();
    let nhdr = scratch("detached.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0005\n# detached\ntype: ushort\ndimension: 3\nsizes: 6 6 6\n\
         space directions: (1,0,0) (0,1,0) (0,0,1)\nencoding: raw\nendian: big\n\
         data file: detached.raw\n",
    )
    .unwrap();
    assert!(same(&read_nrrd(&nhdr, Some(12)).unwrap(), &vol));
    // The same header byte-swapped: a big-endian NIfTI.
    let le = scratch("le.nii");
    write_nifti(&le, &vol, "").unwrap();
    let b = std::fs::read(&le).unwrap();
    let mut h = b.clone();
    let swap = |h: &mut Vec<u8>, o: usize, n: usize| h[o..o + n].reverse();
    swap(&mut h, 0, 4);
    for k in 0..8 {
        swap(&mut h, 40 + 2 * k, 2);
    }
    swap(&mut h, 70, 2);
    swap(&mut h, 72, 2);
    for k in 0..8 {
        swap(&mut h, 76 + 4 * k, 4);
    }
    for o in [108, 112, 116] {
        swap(&mut h, o, 4);
    }
    // qform_code, sform_code; quatern_b/c/d, qoffset_x/y/z, srow_x/y/z.
    swap(&mut h, 252, 2);
    swap(&mut h, 254, 2);
    for k in 0..18 {
        swap(&mut h, 256 + 4 * k, 4);
    }
    for i in 0..vol.len() {
        swap(&mut h, 352 + 2 * i, 2);
    }
    let be = scratch("be.nii");
    std::fs::write(&be, &h).unwrap();
    assert!(same(&read_nifti(&be, Some(12)).unwrap(), &vol));
}

/// Equality without printing two whole volumes on failure.
fn same(a: &Volume, b: &Volume) -> bool {
    a == b
}

fn valid_nrrd_header() -> Vec<u8> {
    b"NRRD0004\ntype: ushort\ndimension: 3\nsizes: 3 4 5\nspacings: 1 1 2\nencoding: gzip\nendian: little\n\n".to_vec()
}

/// The same with an orientation (the mutations reach `space` and `space directions` too).
fn oriented_nrrd_header() -> Vec<u8> {
    b"NRRD0004\ntype: ushort\ndimension: 3\nspace: LPS\nsizes: 3 4 5\nspace directions: (0,1,0) (-1,0,0) (0,0,2)\nencoding: gzip\nendian: little\n\n".to_vec()
}

fn valid_nifti() -> Vec<u8> {
    let vol: Volume = phantom_by_name("sphere", 4, 12).unwrap();
    let p = scratch("fuzz-seed.nii");
    write_nifti(&p, &vol, "seed").unwrap();
    std::fs::read(&p).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn nrrd_header_parser_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = parse_nrrd_header(&bytes, Path::new("fuzz.nrrd"));
        let mut with_magic = b"NRRD0004\n".to_vec();
        with_magic.extend_from_slice(&bytes);
        let _ = parse_nrrd_header(&with_magic, Path::new("fuzz.nrrd"));
    }

    #[test]
    fn mutated_nrrd_headers_never_panic(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
        oriented in any::<bool>(),
    ) {
        let mut h = if oriented { oriented_nrrd_header() } else { valid_nrrd_header() };
        for (i, b) in edits {
            let at = i.index(h.len());
            h[at] = b;
        }
        let at = cut.index(h.len() + 1);
        let _ = parse_nrrd_header(&h[..at], Path::new("fuzz.nrrd"));
        let _ = parse_nrrd_header(&h, Path::new("fuzz.nrrd"));
    }

    #[test]
    fn nifti_header_parser_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..700)) {
        let _ = parse_nifti_header(&bytes, Path::new("fuzz.nii"));
    }

    #[test]
    fn mutated_nifti_files_never_panic(
        edits in proptest::collection::vec((0usize..352, any::<u8>()), 1..6),
    ) {
        let mut f = valid_nifti();
        for (i, b) in edits {
            f[i] = b;
        }
        let _ = parse_nifti_header(&f, Path::new("fuzz.nii"));
        // The whole reader too (data size checks, scaling, mapping).
        let p = scratch("fuzz-mutated.nii");
        std::fs::write(&p, &f).unwrap();
        let _ = read_nifti(&p, None);
    }
}
