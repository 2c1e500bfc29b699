//! Orientation: the same RAS volume written in every axis order and direction (the 48 signed
//! permutations, RAS, LAS and LPS among them) as a NIfTI sform, a NIfTI qform and NRRD space
//! directions (RAS and LPS spaces) reads back as the same [`Volume`], so it renders identically;
//! files built by hand the way nibabel and 3D Slicer write them, and one written by nibabel itself,
//! read back in RAS; oblique and sheared files are refused with the angle; malformed orientation
//! fields are errors, never panics.

use cube5_model::volume::Volume;
use cube5_model::volume_io::{
    axis_map, matrix_quaternion, parse_nifti_header, quaternion_matrix, read_nifti, read_nrrd,
    reorient, write_nifti, write_nifti_with, write_nrrd, AxisMap, NiftiTransform, NiftiXform,
    NrrdEncoding,
};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cube5-orientation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A volume on which any wrong permutation or flip shows: every voxel a different value, every
/// edge and every spacing different (and exact in f32).
fn ras_volume() -> Volume {
    let dims = [5, 6, 7];
    let data = (0..210u16).map(|i| (i * 37) % 251).collect();
    Volume::new(dims, [0.5, 0.75, 1.25], 8, data).unwrap()
}

/// Equality without printing two whole volumes on failure.
fn same(a: &Volume, b: &Volume) -> bool {
    a == b
}

/// All 48 axis maps (6 permutations x 8 sign patterns).
fn all_maps() -> Vec<AxisMap> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::new();
    for ras in perms {
        for bits in 0..8 {
            let flip = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
            out.push(AxisMap { ras, flip });
        }
    }
    out
}

/// The stored form of `ras` in orientation `map`, and that orientation's affine.
fn stored_as(ras: &Volume, map: AxisMap) -> (Volume, [[f64; 4]; 3]) {
    let stored = reorient(ras.clone(), map.inverse());
    let xf = NiftiXform::from_axes(map, stored.spacing);
    (stored, xf.affine)
}

/// The NRRD text of `stored` placed by `affine` (RAS), written in `space` ("RAS" or "LPS").
fn nrrd_text(stored: &Volume, affine: &[[f64; 4]; 3], space: &str) -> Vec<u8> {
    let sign = if space == "LPS" {
        [-1.0, -1.0, 1.0]
    } else {
        [1.0; 3]
    };
    let name = if space == "LPS" {
        "left-posterior-superior"
    } else {
        "right-anterior-superior"
    };
    let dirs: Vec<String> = (0..3)
        .map(|c| {
            let v: Vec<String> = (0..3)
                .map(|r| format!("{}", affine[r][c] * sign[r] + 0.0))
                .collect();
            format!("({})", v.join(","))
        })
        .collect();
    let [nx, ny, nz] = stored.dims;
    let mut t = format!(
        "NRRD0004\ntype: uint8\ndimension: 3\nspace: {name}\nsizes: {nx} {ny} {nz}\n\
         space directions: {}\nkinds: domain domain domain\nencoding: raw\n\n",
        dirs.join(" ")
    )
    .into_bytes();
    t.extend(stored.data.iter().map(|&v| v as u8));
    t
}

#[test]
fn axis_codes_name_the_maps() {
    for map in all_maps() {
        assert_eq!(AxisMap::from_codes(&map.codes()), Some(map));
        assert_eq!(
            reorient(reorient(ras_volume(), map), map.inverse()),
            ras_volume()
        );
    }
    assert_eq!(AxisMap::RAS.codes(), "RAS");
    let las = AxisMap::from_codes("LAS").unwrap();
    assert_eq!((las.ras, las.flip), ([0, 1, 2], [true, false, false]));
    let lps = AxisMap::from_codes("lps").unwrap();
    assert_eq!(lps.flip, [true, true, false]);
    let asl = AxisMap::from_codes("ASL").unwrap();
    assert_eq!((asl.ras, asl.flip), ([1, 2, 0], [false, false, true]));
    assert_eq!(AxisMap::from_codes("RRS"), None);
    assert_eq!(AxisMap::from_codes("RA"), None);
    // Reorienting a stored LAS row [a, b, c] gives the RAS row [c, b, a].
    let row = Volume::new([3, 1, 1], [1.0; 3], 8, vec![1, 2, 3]).unwrap();
    assert_eq!(reorient(row, las).data, vec![3, 2, 1]);
}

#[test]
fn every_orientation_reads_back_as_the_same_ras_volume() {
    let ras = ras_volume();
    for (n, map) in all_maps().into_iter().enumerate() {
        let codes = map.codes();
        let (stored, affine) = stored_as(&ras, map);
        for (sform_code, qform_code, what) in [(1, 0, "sform"), (0, 1, "qform"), (2, 1, "both")] {
            let ext = if n % 2 == 0 { "nii" } else { "nii.gz" };
            let p = scratch(&format!("{codes}-{what}.{ext}"));
            let xf = NiftiXform {
                affine,
                sform_code,
                qform_code,
            };
            write_nifti_with(&p, &stored, "orientation", &xf).unwrap();
            let back = read_nifti(&p, Some(8)).unwrap();
            assert!(same(&back, &ras), "{codes} {what}: {:?}", back.dims);
        }
        for space in ["RAS", "LPS"] {
            let p = scratch(&format!("{codes}-{space}.nrrd"));
            std::fs::write(&p, nrrd_text(&stored, &affine, space)).unwrap();
            let back = read_nrrd(&p, Some(8)).unwrap();
            assert!(same(&back, &ras), "{codes} NRRD in {space}");
        }
    }
}

/// Byte offsets in a NIfTI-1 header (nifti1.h).
const QFORM_CODE: usize = 252;
const SFORM_CODE: usize = 254;
const SROW_X: usize = 280;
const VOXELS: usize = 352;

fn put_f32(b: &mut [u8], at: usize, v: f32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn get_f32(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn get_i16(b: &[u8], at: usize) -> i16 {
    i16::from_le_bytes(b[at..at + 2].try_into().unwrap())
}

/// `ras` stored with the x axis (and the y axis when `flip_y`) reversed, by hand: not through
/// [`reorient`], so the test does not check the reader against itself.
fn reversed_by_hand(ras: &Volume, flip_y: bool) -> Vec<u8> {
    let [nx, ny, nz] = ras.dims;
    let mut out = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let (sx, sy) = (nx - 1 - x, if flip_y { ny - 1 - y } else { y });
                out.push(ras.data[sx + nx * (sy + ny * z)] as u8);
            }
        }
    }
    out
}

#[test]
fn las_and_lps_files_built_by_hand_read_back_ras() {
    // nibabel writes a radiological (LAS) image with the affine diag(-sx, sy, sz): voxel i runs
    // towards the subject's left. Built here from an RAS file by patching srow_x and the voxels.
    let ras = ras_volume();
    let p = scratch("hand-ras.nii");
    write_nifti(&p, &ras, "ras").unwrap();
    let mut b = std::fs::read(&p).unwrap();
    assert_eq!(read_nifti(&p, Some(8)).unwrap(), ras);
    b[QFORM_CODE..QFORM_CODE + 2].copy_from_slice(&0i16.to_le_bytes());
    put_f32(&mut b, SROW_X, -0.5);
    put_f32(&mut b, SROW_X + 12, 2.0); // x offset: voxel 0 is the rightmost column
    b.truncate(VOXELS);
    b.extend(reversed_by_hand(&ras, false));
    let las = scratch("hand-las.nii");
    std::fs::write(&las, &b).unwrap();
    let h = parse_nifti_header(&b, &las).unwrap();
    assert_eq!(
        (h.transform, h.orientation.codes()),
        (NiftiTransform::Sform, "LAS".into())
    );
    assert!(same(&read_nifti(&las, Some(8)).unwrap(), &ras));
    // LPS (DICOM's, ITK's): srow_y negative too.
    put_f32(&mut b, SROW_X + 16 + 4, -0.75);
    b.truncate(VOXELS);
    b.extend(reversed_by_hand(&ras, true));
    let lps = scratch("hand-lps.nii");
    std::fs::write(&lps, &b).unwrap();
    assert_eq!(
        parse_nifti_header(&b, &lps).unwrap().orientation.codes(),
        "LPS"
    );
    assert!(same(&read_nifti(&lps, Some(8)).unwrap(), &ras));
    // An NRRD as 3D Slicer writes a DICOM series: LPS space, positive diagonal directions, so the
    // stored voxels run towards Left and Posterior.
    let [nx, ny, nz] = ras.dims;
    let mut t = format!(
        "NRRD0004\ntype: unsigned char\ndimension: 3\nspace: left-posterior-superior\n\
         sizes: {nx} {ny} {nz}\nspace directions: (0.5,0,0) (0,0.75,0) (0,0,1.25)\n\
         kinds: domain domain domain\nendian: little\nencoding: raw\nspace origin: (1,2,3)\n\n"
    )
    .into_bytes();
    t.extend(reversed_by_hand(&ras, true));
    let nrrd = scratch("slicer-lps.nrrd");
    std::fs::write(&nrrd, &t).unwrap();
    assert!(same(&read_nrrd(&nrrd, Some(8)).unwrap(), &ras));
}

#[test]
fn no_transform_and_qfac_rules() {
    let ras = ras_volume();
    let p = scratch("codes0.nii");
    write_nifti(&p, &ras, "").unwrap();
    let mut b = std::fs::read(&p).unwrap();
    // Both codes 0 ("method 1"): pixdim only, axes taken as RAS, a negative pixdim as its size.
    b[QFORM_CODE..QFORM_CODE + 4].fill(0);
    put_f32(&mut b, 80, -0.5);
    let h = parse_nifti_header(&b, &p).unwrap();
    assert_eq!(h.transform, NiftiTransform::Pixdim);
    assert_eq!(
        (h.orientation, h.spacing),
        (AxisMap::RAS, [0.5, 0.75, 1.25])
    );
    // A qform with qfac (pixdim[0]) 0 counts as 1; -1 reverses the third axis.
    b[QFORM_CODE..QFORM_CODE + 2].copy_from_slice(&1i16.to_le_bytes());
    put_f32(&mut b, 80, 0.5);
    put_f32(&mut b, 76, 0.0);
    assert_eq!(
        parse_nifti_header(&b, &p).unwrap().orientation.codes(),
        "RAS"
    );
    put_f32(&mut b, 76, -1.0);
    let h = parse_nifti_header(&b, &p).unwrap();
    assert_eq!(
        (h.transform, h.orientation.codes()),
        (NiftiTransform::Qform, "RAI".into())
    );
    // A qform with a zero pixdim reads it as 1 (nifti1_io.c).
    put_f32(&mut b, 76, 1.0);
    put_f32(&mut b, 84, 0.0);
    assert_eq!(
        parse_nifti_header(&b, &p).unwrap().spacing,
        [0.5, 1.0, 1.25]
    );
}

/// 4x4 rotation about z by `deg` degrees, times diag(spacing): an oblique affine.
fn rotated_z(deg: f64, s: [f64; 3]) -> [[f64; 4]; 3] {
    let (sin, cos) = deg.to_radians().sin_cos();
    [
        [cos * s[0], -sin * s[1], 0.0, 0.0],
        [sin * s[0], cos * s[1], 0.0, 0.0],
        [0.0, 0.0, s[2], 0.0],
    ]
}

#[test]
fn oblique_and_sheared_files_are_refused_with_the_angle() {
    let ras = ras_volume();
    let s = ras.spacing;
    for (code_s, code_q, field) in [(1, 0, "sform"), (0, 1, "qform")] {
        let p = scratch(&format!("oblique-{field}.nii"));
        let xf = NiftiXform {
            affine: rotated_z(10.0, s),
            sform_code: code_s,
            qform_code: code_q,
        };
        write_nifti_with(&p, &ras, "oblique", &xf).unwrap();
        let e = read_nifti(&p, None).unwrap_err().to_string();
        assert!(!e.contains('\n'), "one line: {e}");
        assert!(
            e.contains(&format!("oblique-{field}.nii: {field}: oblique"))
                && e.contains("10.000 degrees"),
            "{e}"
        );
    }
    // A tilt too small to move any voxel by half a voxel (f32 noise in real headers) is accepted.
    let p = scratch("tiny-tilt.nii");
    let xf = NiftiXform {
        affine: rotated_z(0.001, s),
        sform_code: 1,
        qform_code: 1,
    };
    write_nifti_with(&p, &ras, "", &xf).unwrap();
    let back = read_nifti(&p, Some(8)).unwrap();
    assert_eq!(back.data, ras.data);
    // Shear: the j column leans towards x.
    let mut sheared = NiftiXform::ras(s);
    sheared.affine[0][1] = 0.3;
    sheared.qform_code = 0;
    let p = scratch("shear.nii");
    write_nifti_with(&p, &ras, "", &sheared).unwrap();
    let e = read_nifti(&p, None).unwrap_err().to_string();
    assert!(e.contains("shear.nii: sform: oblique"), "{e}");
    // ...which a qform cannot hold: the writer refuses it.
    sheared.qform_code = 1;
    let e = write_nifti_with(&p, &ras, "", &sheared)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sheared"), "{e}");
    // NRRD: oblique space directions.
    let [nx, ny, nz] = ras.dims;
    let mut t = format!(
        "NRRD0004\ntype: uchar\ndimension: 3\nspace: RAS\nsizes: {nx} {ny} {nz}\n\
         space directions: (0.49,0.1,0) (-0.15,0.735,0) (0,0,1.25)\nencoding: raw\n\n"
    )
    .into_bytes();
    t.extend(ras.data.iter().map(|&v| v as u8));
    let p = scratch("oblique.nrrd");
    std::fs::write(&p, &t).unwrap();
    let e = read_nrrd(&p, None).unwrap_err().to_string();
    assert!(e.contains("oblique.nrrd: space directions: oblique"), "{e}");
}

#[test]
fn writers_place_the_volume_in_ras() {
    let ras = ras_volume();
    let p = scratch("w.nii");
    write_nifti(&p, &ras, "").unwrap();
    let b = std::fs::read(&p).unwrap();
    assert_eq!((get_i16(&b, QFORM_CODE), get_i16(&b, SFORM_CODE)), (1, 1));
    let srow: Vec<f32> = (0..12).map(|k| get_f32(&b, SROW_X + 4 * k)).collect();
    assert_eq!(
        srow,
        [0.5, 0.0, 0.0, 0.0, 0.0, 0.75, 0.0, 0.0, 0.0, 0.0, 1.25, 0.0]
    );
    let q: Vec<f32> = (0..3).map(|k| get_f32(&b, 256 + 4 * k)).collect();
    assert_eq!((get_f32(&b, 76), q), (1.0, vec![0.0; 3]));
    let p = scratch("w.nrrd");
    write_nrrd(&p, &ras, NrrdEncoding::Raw, "").unwrap();
    let text = String::from_utf8_lossy(&std::fs::read(&p).unwrap()).to_string();
    assert!(
        text.contains("\nspace: right-anterior-superior\n"),
        "{text}"
    );
    assert!(
        text.contains("\nspace directions: (0.5,0,0) (0,0.75,0) (0,0,1.25)\n"),
        "{text}"
    );
    assert!(
        !text.contains("spacings"),
        "NRRD forbids spacings with directions"
    );
}

/// A 2 x 3 x 4 uint8 image written by nibabel 5.4.2 (`Nifti1Image(data, affine).to_file_map`):
/// data `(arange(24) * 7 + 3)` in Fortran order, affine
/// `[[0, 0, -1.5, 10], [-2, 0, 0, 20], [0, 0.5, 0, -5]]` (axis codes PSL), so sform_code 2,
/// qform_code 0 and the quaternion (0.5, -0.5, -0.5) filled in as nibabel always does.
const NIBABEL_PSL: &[&str] = &[
    "5c0100000000000000000000000000000000000000000000000000000000000000000000000000000300020003000400",
    "010001000100010000000000000000000000000000000200080000000000803f000000400000003f0000c03f0000803f",
    "0000803f0000803f0000803f0000b0430000803f00000000000000000000000000000000000000000000000000000000",
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
    "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
    "000000000000000000000000000002000000003f000000bf000000bf000020410000a0410000a0c00000000000000000",
    "0000c0bf00002041000000c000000000000000000000a041000000000000003f000000000000a0c00000000000000000",
    "00000000000000006e2b310000000000030a11181f262d343b424950575e656c737a81888f969da4",
];

/// `nib.as_closest_canonical(img)` of that image: shape (4, 2, 3), zooms (1.5, 2, 0.5), RAS, data
/// in Fortran (x fastest) order.
const NIBABEL_CANONICAL: [u16; 24] = [
    136, 94, 52, 10, 129, 87, 45, 3, 150, 108, 66, 24, 143, 101, 59, 17, 164, 122, 80, 38, 157,
    115, 73, 31,
];

fn unhex(lines: &[&str]) -> Vec<u8> {
    let s: String = lines.concat();
    (0..s.len() / 2)
        .map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).unwrap())
        .collect()
}

#[test]
fn a_file_written_by_nibabel_reads_as_nibabel_reorients_it() {
    let canonical = Volume::new([4, 2, 3], [1.5, 2.0, 0.5], 8, NIBABEL_CANONICAL.to_vec()).unwrap();
    let b = unhex(NIBABEL_PSL);
    let p = scratch("nibabel-psl.nii");
    std::fs::write(&p, &b).unwrap();
    let h = parse_nifti_header(&b, &p).unwrap();
    assert_eq!(
        (h.transform, h.orientation.codes()),
        (NiftiTransform::Sform, "PSL".into())
    );
    assert!(same(&read_nifti(&p, Some(8)).unwrap(), &canonical));
    // The same file placed by its qform alone (nibabel's quaternion, qfac 1) reads the same.
    let mut q = b.clone();
    q[QFORM_CODE..QFORM_CODE + 2].copy_from_slice(&1i16.to_le_bytes());
    q[SFORM_CODE..SFORM_CODE + 2].copy_from_slice(&0i16.to_le_bytes());
    let pq = scratch("nibabel-psl-qform.nii");
    std::fs::write(&pq, &q).unwrap();
    assert_eq!(
        parse_nifti_header(&q, &pq).unwrap().transform,
        NiftiTransform::Qform
    );
    assert!(same(&read_nifti(&pq, Some(8)).unwrap(), &canonical));
    // The project's writer, given nibabel's affine and codes, writes the same header fields.
    let stored = Volume::new(
        [2, 3, 4],
        [1.0; 3],
        8,
        b[VOXELS..].iter().map(|&v| u16::from(v)).collect(),
    )
    .unwrap();
    let xf = NiftiXform {
        affine: [
            [0.0, 0.0, -1.5, 10.0],
            [-2.0, 0.0, 0.0, 20.0],
            [0.0, 0.5, 0.0, -5.0],
        ],
        sform_code: 2,
        qform_code: 0,
    };
    let ours = scratch("ours-psl.nii");
    write_nifti_with(&ours, &stored, "", &xf).unwrap();
    let o = std::fs::read(&ours).unwrap();
    // qfac and pixdim[1..3], codes, quaternion, qoffset, srow: bytes 76..92 and 252..328.
    assert_eq!(o[76..92], b[76..92]);
    assert_eq!(o[252..328], b[252..328]);
    assert!(same(&read_nifti(&ours, Some(8)).unwrap(), &canonical));
}

#[test]
fn quaternions_round_trip_for_every_rotation_of_the_axes() {
    for map in all_maps() {
        let mut r = map.direction_matrix([1.0; 3]);
        let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        if det < 0.0 {
            for row in r.iter_mut() {
                row[2] = -row[2];
            }
        }
        let q = matrix_quaternion(r).map(|v| f64::from(v as f32));
        let back = quaternion_matrix(q).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (back[i][j] - r[i][j]).abs() < 1e-6,
                    "{}: {back:?}",
                    map.codes()
                );
            }
        }
    }
}

#[test]
fn malformed_orientation_fields_are_errors() {
    let ras = ras_volume();
    let p = scratch("bad.nii");
    write_nifti(&p, &ras, "").unwrap();
    let good = std::fs::read(&p).unwrap();
    let check = |edit: &dyn Fn(&mut Vec<u8>), want: &str| {
        let mut b = good.clone();
        edit(&mut b);
        let e = parse_nifti_header(&b, Path::new("bad.nii"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("bad.nii: {want}")), "{want}: {e}");
    };
    let sform_off = |b: &mut Vec<u8>| b[SFORM_CODE..SFORM_CODE + 2].fill(0);
    // With the sform set the quaternion is not read (nibabel's choice), so only sform-off cases.
    check(
        &|b| {
            sform_off(b);
            put_f32(b, 256, f32::NAN)
        },
        "quatern_b/c/d",
    );
    check(
        &|b| {
            sform_off(b);
            put_f32(b, 256, 0.9);
            put_f32(b, 260, 0.9)
        },
        "quatern_b/c/d",
    );
    check(
        &|b| {
            sform_off(b);
            put_f32(b, 84, -0.75)
        },
        "pixdim[2]",
    );
    check(
        &|b| b[SFORM_CODE..SFORM_CODE + 2].copy_from_slice(&(-1i16).to_le_bytes()),
        "sform_code",
    );
    check(
        &|b| put_f32(b, SROW_X + 16 + 4, 0.0),
        "sform: voxel axis j has length 0",
    );
    check(&|b| put_f32(b, SROW_X, f32::INFINITY), "sform");
    check(
        &|b| {
            put_f32(b, SROW_X, 0.0);
            put_f32(b, SROW_X + 4, 0.5)
        },
        "sform",
    );
    // NRRD.
    let nrrd = |fields: &str| {
        let t = format!(
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n{fields}\n\n"
        );
        cube5_model::volume_io::parse_nrrd_header(t.as_bytes(), Path::new("x.nrrd"))
            .map(|(h, _)| h)
            .map_err(|e| e.to_string())
    };
    for (fields, want) in [
        (
            "space: 3D-left-handed\nspace directions: (1,0,0) (0,1,0) (0,0,1)",
            "x.nrrd: space",
        ),
        ("space: RAST", "x.nrrd: space"),
        ("space: up-down-charm", "x.nrrd: space"),
        ("space dimension: 4", "x.nrrd: space dimension"),
        (
            "space directions: (1,0,0) none (0,0,1)",
            "x.nrrd: space directions",
        ),
        (
            "space directions: (1,0) (0,1) (0,0)",
            "x.nrrd: space directions",
        ),
        (
            "space directions: (1,0,0) (0,1,0)",
            "x.nrrd: space directions",
        ),
        (
            "space directions: (1,0,0) (1,0,0) (0,0,1)",
            "x.nrrd: space directions",
        ),
        (
            "space directions: (nan,0,0) (0,1,0) (0,0,1)",
            "x.nrrd: space directions",
        ),
    ] {
        let e = nrrd(fields).unwrap_err();
        assert!(e.contains(want), "{fields}: {e}");
    }
    // Spaces without anatomical axes keep x, y, z as R, A, S; no directions at all is RAS.
    for fields in [
        "space: scanner-xyz\nspace directions: (-1,0,0) (0,1,0) (0,0,1)",
        "space: 3D-right-handed\nspace directions: (-1,0,0) (0,1,0) (0,0,1)",
        "space dimension: 3\nspace directions: (-1,0,0) (0,1,0) (0,0,1)",
    ] {
        assert_eq!(nrrd(fields).unwrap().orientation.codes(), "LAS", "{fields}");
    }
    assert_eq!(nrrd("spacings: 1 2 3").unwrap().orientation, AxisMap::RAS);
    // axis_map on its own: a permuted, flipped, anisotropic matrix.
    let (map, s) = axis_map(
        [[0.0, 0.0, -3.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [4, 4, 4],
    )
    .unwrap();
    assert_eq!((map.codes(), s), ("ASL".into(), [2.0, 1.0, 3.0]));
}
