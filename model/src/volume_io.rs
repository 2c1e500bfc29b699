//! Volume files: raw voxels, NRRD (raw, gzip and ASCII encodings, attached or detached data) and
//! NIfTI-1 (`.nii`, `.nii.gz`), read into a [`Volume`]; writers for NRRD, NIfTI and raw so the tests
//! and the shipped examples (`scenes/data/`) are made from the embedded phantoms.
//!
//! Voxel values: unsigned integer types of at most 16 bits are kept exactly (the volume's width is
//! the one asked for, or the smallest of 8..=16 that holds the largest value); signed, 32-bit and
//! floating-point types (after NIfTI's `scl_slope`/`scl_inter`) are mapped linearly from their
//! range `[min, max]` onto `0 ..= 2^bits - 1` (12 bits unless asked), rounding to nearest.
//!
//! Orientation: every volume is read into RAS (x Left to Right, y Posterior to Anterior, z Inferior
//! to Superior) from NIfTI's sform or qform and NRRD's `space directions`, by permuting and
//! reversing axes; oblique files are refused ([`axis_map`]; the rules in `docs/scenes.md`).
//!
//! Every error names the file and the header field (or the byte count) that is wrong; no input
//! makes a reader panic (the header parsers are fuzzed in `model/tests/volume_io.rs`).

use crate::error::{ModelError, Result};
use crate::volume::{Volume, MAX_EDGE};
use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// Element type of stored voxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VoxelType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    F32,
    F64,
}

impl VoxelType {
    pub fn size(self) -> usize {
        match self {
            Self::U8 | Self::I8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// Unsigned integer of at most 16 bits: stored exactly.
    pub fn is_exact(self) -> bool {
        matches!(self, Self::U8 | Self::U16)
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::U8 => "u8",
            Self::I8 => "i8",
            Self::U16 => "u16",
            Self::I16 => "i16",
            Self::U32 => "u32",
            Self::I32 => "i32",
            Self::F32 => "f32",
            Self::F64 => "f64",
        }
    }

    /// One value from the start of `b` (at least `size()` bytes).
    fn read(self, b: &[u8], endian: Endian) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(&b[..$n]);
                match endian {
                    Endian::Little => <$t>::from_le_bytes(a),
                    Endian::Big => <$t>::from_be_bytes(a),
                }
            }};
        }
        match self {
            Self::U8 => f64::from(b[0]),
            Self::I8 => f64::from(b[0] as i8),
            Self::U16 => f64::from(get!(u16, 2)),
            Self::I16 => f64::from(get!(i16, 2)),
            Self::U32 => f64::from(get!(u32, 4)),
            Self::I32 => f64::from(get!(i32, 4)),
            Self::F32 => f64::from(get!(f32, 4)),
            Self::F64 => get!(f64, 8),
        }
    }
}

/// Byte order of multi-byte voxels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Endian {
    #[default]
    Little,
    Big,
}

/// What a raw file holds (everything a raw file cannot say about itself).
#[derive(Debug, Clone, PartialEq)]
pub struct RawSpec {
    pub dims: [usize; 3],
    pub voxel_type: VoxelType,
    pub endian: Endian,
    pub spacing: [f64; 3],
    /// Header bytes to skip before the voxels.
    pub offset: u64,
}

/// A volume file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Raw,
    Nrrd,
    Nifti,
}

impl Format {
    /// The format a file name implies: `.raw`/`.bin`, `.nrrd`/`.nhdr`, `.nii`/`.nii.gz`.
    pub fn from_path(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        if name.ends_with(".nii") || name.ends_with(".nii.gz") {
            Some(Self::Nifti)
        } else if name.ends_with(".nrrd") || name.ends_with(".nhdr") {
            Some(Self::Nrrd)
        } else if name.ends_with(".raw") || name.ends_with(".bin") {
            Some(Self::Raw)
        } else {
            None
        }
    }
}

fn err(path: &Path, field: &str, message: impl std::fmt::Display) -> ModelError {
    ModelError::Volume(format!("{}: {field}: {message}", path.display()))
}

/// A header field of one value per axis (`sizes`, `spacings`), white space between; a value that
/// does not read as `T` is refused as not `what`.
fn per_axis<T: std::str::FromStr>(
    path: &Path,
    field: &str,
    value: &str,
    what: &str,
) -> Result<Vec<T>> {
    value
        .split_whitespace()
        .map(|v| {
            v.parse::<T>()
                .map_err(|_| err(path, field, format!("`{v}` is not {what}")))
        })
        .collect()
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|source| ModelError::Io {
        path: path.display().to_string(),
        source,
    })
}

fn gunzip(path: &Path, bytes: &[u8], limit: usize) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    // Read one byte past the limit so an oversized stream is refused, not silently truncated.
    GzDecoder::new(bytes)
        .take(limit as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| err(path, "gzip data", e))?;
    Ok(out)
}

fn check_dims(path: &Path, field: &str, dims: [usize; 3]) -> Result<()> {
    if dims.iter().any(|&d| d == 0 || d > MAX_EDGE) {
        return Err(err(
            path,
            field,
            format!("{dims:?}: each edge must be 1..={MAX_EDGE}"),
        ));
    }
    Ok(())
}

fn check_spacing(path: &Path, field: &str, spacing: [f64; 3]) -> Result<()> {
    if spacing.iter().any(|s| !s.is_finite() || *s <= 0.0) {
        return Err(err(
            path,
            field,
            format!("{spacing:?}: must be finite and > 0"),
        ));
    }
    Ok(())
}

// ------------------------------------------------------------------------------------------------
// Orientation: stored voxel axes to RAS+
// ------------------------------------------------------------------------------------------------

/// World axis names of RAS+ (NIfTI's world, nifti1.h: +x Right, +y Anterior, +z Superior), as
/// `(towards +, towards -)`.
const RAS_LETTERS: [(char, char); 3] = [('R', 'L'), ('A', 'P'), ('S', 'I')];

/// How the stored voxel axes lie in the RAS+ world (+x towards the subject's Right, +y Anterior,
/// +z Superior): stored axis `a` runs along world axis `ras[a]`, towards decreasing world
/// coordinates when `flip[a]`. The readers apply it ([`reorient`]), so every [`Volume`] read from a
/// file is stored RAS: x (fastest) from Left to Right, y from Posterior to Anterior, z from
/// Inferior to Superior.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisMap {
    pub ras: [usize; 3],
    pub flip: [bool; 3],
}

impl AxisMap {
    /// Stored axes already RAS.
    pub const RAS: Self = Self {
        ras: [0, 1, 2],
        flip: [false; 3],
    };

    /// From axis codes as nibabel's `aff2axcodes` gives them: the world direction each stored axis
    /// runs towards (`"RAS"`, `"LPS"`, `"ASL"`, ...). `None` unless the three name distinct axes.
    pub fn from_codes(codes: &str) -> Option<Self> {
        let c: Vec<char> = codes.chars().map(|c| c.to_ascii_uppercase()).collect();
        if c.len() != 3 {
            return None;
        }
        let mut map = Self::RAS;
        let mut seen = [false; 3];
        for (a, &letter) in c.iter().enumerate() {
            let (w, &(_, minus)) = RAS_LETTERS
                .iter()
                .enumerate()
                .find(|(_, (p, m))| *p == letter || *m == letter)?;
            if std::mem::replace(&mut seen[w], true) {
                return None;
            }
            map.ras[a] = w;
            map.flip[a] = letter == minus;
        }
        Some(map)
    }

    /// The axis codes (`"RAS"`, `"LPS"`, ...), as nibabel's `aff2axcodes` names them.
    pub fn codes(&self) -> String {
        (0..3)
            .map(|a| {
                let (plus, minus) = RAS_LETTERS[self.ras[a]];
                if self.flip[a] {
                    minus
                } else {
                    plus
                }
            })
            .collect()
    }

    /// The map from RAS back to this orientation: `reorient(reorient(v, m), m.inverse()) == v`.
    pub fn inverse(&self) -> Self {
        let mut inv = Self::RAS;
        for a in 0..3 {
            inv.ras[self.ras[a]] = a;
            inv.flip[self.ras[a]] = self.flip[a];
        }
        inv
    }

    /// The direction part of a voxel-to-RAS affine for this map, `m[row][column]`: column `a` is
    /// stored axis `a`'s step, `±spacing[a]` along world axis `ras[a]`.
    pub fn direction_matrix(&self, spacing: [f64; 3]) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for a in 0..3 {
            m[self.ras[a]][a] = if self.flip[a] {
                -spacing[a]
            } else {
                spacing[a]
            };
        }
        m
    }
}

/// Largest distortion, in voxels from one corner of the volume to the opposite one, accepted when
/// an oblique direction matrix is taken as axis-aligned: half a voxel, so no voxel lands nearer a
/// neighbour's place than its own. A rounding error of the f32 header fields (about 1e-7 of the
/// spacing) stays far below it even at 1024 voxels; a real tilt of 0.1 degree across 300 voxels
/// (0.52 voxels) does not.
pub const MAX_OBLIQUE_VOXELS: f64 = 0.5;

/// The axis map and the spacings (stored order, mm: the column lengths) of a voxel-to-RAS
/// direction matrix `m` (`m[row][column]`; column `a` = the world step of stored axis `a`), for a
/// grid of `dims`. Each stored axis goes to the world axis its column points along most (as
/// nibabel's `io_orientation`), and the reason is given as text when the matrix cannot be
/// represented that way: not finite, a zero column, two axes along one world axis, or oblique or
/// sheared by more than [`MAX_OBLIQUE_VOXELS`] across the volume.
pub fn axis_map(
    m: [[f64; 3]; 3],
    dims: [usize; 3],
) -> std::result::Result<(AxisMap, [f64; 3]), String> {
    const NAME: [&str; 3] = ["i", "j", "k"];
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("direction matrix {m:?} is not finite"));
    }
    let col = |a: usize| [m[0][a], m[1][a], m[2][a]];
    let mut map = AxisMap::RAS;
    let mut spacing = [0.0; 3];
    let mut taken: [Option<usize>; 3] = [None; 3];
    let mut angle = 0.0f64;
    for a in 0..3 {
        let c = col(a);
        let len = c.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(len > 0.0 && len.is_finite()) {
            return Err(format!(
                "voxel axis {} has length {len}: the direction matrix is singular",
                NAME[a]
            ));
        }
        let w = (0..3)
            .max_by(|&x, &y| c[x].abs().total_cmp(&c[y].abs()))
            .unwrap_or(0);
        if let Some(b) = taken[w] {
            return Err(format!(
                "voxel axes {} and {} both run nearest to world axis {}: the direction matrix is \
                 degenerate",
                NAME[b], NAME[a], RAS_LETTERS[w].0
            ));
        }
        taken[w] = Some(a);
        map.ras[a] = w;
        map.flip[a] = c[w] < 0.0;
        spacing[a] = len;
        angle = angle.max((c[w].abs() / len).min(1.0).acos().to_degrees());
    }
    // Distortion from taking the grid as axis-aligned: the largest difference, across the volume,
    // between where a voxel is and where the axis-aligned grid puts it, along each world axis, in
    // that axis's voxels.
    let ideal = map.direction_matrix(spacing);
    let mut worst = 0.0f64;
    for w in 0..3 {
        let off: f64 = (0..3)
            .map(|a| dims[a].saturating_sub(1) as f64 * (m[w][a] - ideal[w][a]).abs())
            .sum();
        let along = taken[w].map_or(1.0, |a| spacing[a]);
        worst = worst.max(off / along);
    }
    if worst > MAX_OBLIQUE_VOXELS {
        return Err(format!(
            "oblique: a voxel axis is {angle:.3} degrees off the nearest RAS axis, which would \
             distort the volume by {worst:.2} voxels (at most {MAX_OBLIQUE_VOXELS}) if drawn \
             axis-aligned; resample it onto an axis-aligned grid first"
        ));
    }
    Ok((map, spacing))
}

/// The volume with its axes permuted and reversed as `map` says, so that a volume stored in the
/// orientation `map` describes comes out stored RAS (spacings permuted with the axes).
pub fn reorient(vol: Volume, map: AxisMap) -> Volume {
    if map == AxisMap::RAS {
        return vol;
    }
    let n = vol.dims;
    let mut dims = [0; 3];
    let mut spacing = [0.0; 3];
    for a in 0..3 {
        dims[map.ras[a]] = n[a];
        spacing[map.ras[a]] = vol.spacing[a];
    }
    let stride = [1, dims[0], dims[0] * dims[1]];
    let (mut start, mut step) = (0isize, [0isize; 3]);
    for a in 0..3 {
        let s = stride[map.ras[a]] as isize;
        if map.flip[a] {
            start += s * (n[a] as isize - 1);
            step[a] = -s;
        } else {
            step[a] = s;
        }
    }
    let mut data = vec![0u16; vol.data.len()];
    let mut src = vol.data.iter();
    for z in 0..n[2] as isize {
        for y in 0..n[1] as isize {
            let row = start + step[1] * y + step[2] * z;
            for x in 0..n[0] as isize {
                if let Some(&v) = src.next() {
                    data[(row + step[0] * x) as usize] = v;
                }
            }
        }
    }
    Volume {
        dims,
        spacing,
        bits: vol.bits,
        data,
    }
}

/// How stored voxels are laid out.
struct Stored {
    voxel_type: VoxelType,
    endian: Endian,
    dims: [usize; 3],
    spacing: [f64; 3],
    /// NIfTI's `(scl_slope, scl_inter)`.
    scale: Option<(f64, f64)>,
    /// How the stored axes lie in RAS: applied last.
    orient: AxisMap,
}

/// Turns stored values into a [`Volume`] (the rules in the module comment). `bits` is the width
/// asked for (`None`: as stored for u8/u16, 12 for other types).
fn to_volume(path: &Path, data: &[u8], st: Stored, bits: Option<u32>) -> Result<Volume> {
    let Stored {
        voxel_type,
        endian,
        dims,
        spacing,
        scale,
        orient,
    } = st;
    check_dims(path, "dimensions", dims)?;
    check_spacing(path, "spacing", spacing)?;
    if let Some(b) = bits {
        if !(1..=16).contains(&b) {
            return Err(err(path, "bits", format!("{b}: must be 1..=16")));
        }
    }
    let n = dims[0] * dims[1] * dims[2];
    let size = voxel_type.size();
    let need = n * size;
    if data.len() != need {
        return Err(err(
            path,
            "data size",
            format!(
                "{} bytes of voxels, but {} x {} x {} x {} ({}) needs {need}",
                data.len(),
                dims[0],
                dims[1],
                dims[2],
                size,
                voxel_type.name()
            ),
        ));
    }
    let value = |i: usize| {
        let v = voxel_type.read(&data[i * size..], endian);
        match scale {
            Some((slope, inter)) => v * slope + inter,
            None => v,
        }
    };
    let exact = voxel_type.is_exact() && scale.is_none();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..n {
        let v = value(i);
        if !v.is_finite() {
            return Err(err(path, "data", format!("voxel {i} is {v} (not finite)")));
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    let out: Vec<u16>;
    let width;
    if exact {
        let needed = (8..=16).find(|&b| hi < f64::from(1u32 << b)).unwrap_or(16);
        width = bits.unwrap_or(needed);
        let max = f64::from((1u32 << width) - 1);
        if hi > max {
            return Err(err(
                path,
                "bits",
                format!(
                    "voxel value {hi} does not fit in {width} bits (stored type {})",
                    voxel_type.name()
                ),
            ));
        }
        out = (0..n).map(|i| value(i) as u16).collect();
    } else {
        width = bits.unwrap_or(12);
        let max = f64::from((1u32 << width) - 1);
        let span = hi - lo;
        out = (0..n)
            .map(|i| {
                if span > 0.0 {
                    ((value(i) - lo) / span * max).round() as u16
                } else {
                    0
                }
            })
            .collect();
    }
    let stored = Volume::new(dims, spacing, width, out).map_err(|e| err(path, "volume", e))?;
    Ok(reorient(stored, orient))
}

/// Reads a raw volume as `spec` describes; the file must hold exactly `offset + dims x size` bytes.
pub fn read_raw(path: &Path, spec: &RawSpec, bits: Option<u32>) -> Result<Volume> {
    check_dims(path, "dims", spec.dims)?;
    let bytes = read_file(path)?;
    let n = spec.dims.iter().product::<usize>();
    let need = spec.offset as usize + n * spec.voxel_type.size();
    if bytes.len() != need {
        return Err(err(
            path,
            "file size",
            format!(
                "{} bytes, but offset {} + dims {} x {} x {} x {} bytes ({}) = {need}",
                bytes.len(),
                spec.offset,
                spec.dims[0],
                spec.dims[1],
                spec.dims[2],
                spec.voxel_type.size(),
                spec.voxel_type.name()
            ),
        ));
    }
    to_volume(
        path,
        &bytes[spec.offset as usize..],
        Stored {
            voxel_type: spec.voxel_type,
            endian: spec.endian,
            dims: spec.dims,
            spacing: spec.spacing,
            scale: None,
            orient: AxisMap::RAS,
        },
        bits,
    )
}

// ------------------------------------------------------------------------------------------------
// NRRD
// ------------------------------------------------------------------------------------------------

/// NRRD data encodings this reader supports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NrrdEncoding {
    Raw,
    Gzip,
    Ascii,
}

/// The fields of an NRRD header that matter here.
#[derive(Debug, Clone, PartialEq)]
pub struct NrrdHeader {
    pub voxel_type: VoxelType,
    pub dims: [usize; 3],
    pub encoding: NrrdEncoding,
    pub endian: Endian,
    /// Voxel size along each stored axis (`spacings`, or the lengths of the `space directions`).
    pub spacing: [f64; 3],
    /// `space`, as written (`right-anterior-superior`, `LPS`, ...).
    pub space: Option<String>,
    /// How the stored axes lie in RAS: from `space` and `space directions`; [`AxisMap::RAS`] when
    /// the header gives no directions.
    pub orientation: AxisMap,
    /// Detached data file (`data file:`), relative to the header's directory.
    pub data_file: Option<String>,
    pub line_skip: usize,
    /// `byte skip`; -1 means "the data are the last bytes of the file" (raw only).
    pub byte_skip: i64,
}

/// Parses an NRRD header at the start of `bytes`; returns it and the offset of the attached data.
/// `origin` names the file in errors.
pub fn parse_nrrd_header(bytes: &[u8], origin: &Path) -> Result<(NrrdHeader, usize)> {
    let e = |field: &str, m: String| err(origin, field, m);
    if !bytes.starts_with(b"NRRD000") || bytes.len() < 9 || !(b'1'..=b'5').contains(&bytes[7]) {
        return Err(e(
            "magic",
            "not an NRRD file (the first line must be NRRD0001..NRRD0005)".into(),
        ));
    }
    let mut pos = 0usize;
    let mut lines: Vec<String> = Vec::new();
    let mut end = None;
    while pos < bytes.len() {
        let stop = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let line = String::from_utf8_lossy(&bytes[pos..stop])
            .trim_end_matches('\r')
            .to_string();
        pos = (stop + 1).min(bytes.len());
        if line.is_empty() && !lines.is_empty() {
            end = Some(pos);
            break;
        }
        lines.push(line);
        if lines.len() > 4096 {
            return Err(e("header", "more than 4096 header lines".into()));
        }
    }
    let mut voxel_type = None;
    let mut dimension = None;
    let mut sizes: Option<Vec<usize>> = None;
    let mut encoding = None;
    let mut endian = None;
    let mut spacings: Option<Vec<f64>> = None;
    let mut directions: Option<Vec<Option<Vec<f64>>>> = None;
    let mut space: Option<String> = None;
    let mut space_dimension: Option<String> = None;
    let mut data_file = None;
    let mut line_skip = 0usize;
    let mut byte_skip = 0i64;
    for line in lines.iter().skip(1) {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        if line.contains(":=") {
            continue; // key/value pair: not needed
        }
        let Some((field, value)) = line.split_once(": ") else {
            return Err(e("header", format!("line `{line}` is not `field: value`")));
        };
        let field = field.trim().to_ascii_lowercase();
        let value = value.trim();
        match field.as_str() {
            "type" => {
                voxel_type = Some(match value.to_ascii_lowercase().as_str() {
                    "uchar" | "unsigned char" | "uint8" | "uint8_t" => VoxelType::U8,
                    "signed char" | "int8" | "int8_t" => VoxelType::I8,
                    "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
                        VoxelType::U16
                    }
                    "short" | "short int" | "signed short" | "signed short int" | "int16"
                    | "int16_t" => VoxelType::I16,
                    "uint" | "unsigned int" | "uint32" | "uint32_t" => VoxelType::U32,
                    "int" | "signed int" | "int32" | "int32_t" => VoxelType::I32,
                    "float" => VoxelType::F32,
                    "double" => VoxelType::F64,
                    other => return Err(e("type", format!("`{other}` is not supported"))),
                })
            }
            "dimension" => {
                dimension = Some(
                    value
                        .parse::<usize>()
                        .map_err(|_| e("dimension", format!("`{value}` is not a number")))?,
                )
            }
            "sizes" => sizes = Some(per_axis(origin, "sizes", value, "a size")?),
            "encoding" => {
                encoding = Some(match value.to_ascii_lowercase().as_str() {
                    "raw" => NrrdEncoding::Raw,
                    "gzip" | "gz" => NrrdEncoding::Gzip,
                    "ascii" | "text" | "txt" => NrrdEncoding::Ascii,
                    other => return Err(e("encoding", format!("`{other}` is not supported"))),
                })
            }
            "endian" => {
                endian = Some(match value.to_ascii_lowercase().as_str() {
                    "little" => Endian::Little,
                    "big" => Endian::Big,
                    other => return Err(e("endian", format!("`{other}` is not little or big"))),
                })
            }
            "spacings" => spacings = Some(per_axis(origin, "spacings", value, "a number")?),
            "space directions" => directions = Some(parse_space_directions(value, origin)?),
            "space" => space = Some(value.to_string()),
            "space dimension" => space_dimension = Some(value.to_string()),
            "data file" | "datafile" => {
                if value.starts_with("LIST") || value.split_whitespace().count() > 1 {
                    return Err(e(
                        "data file",
                        "lists of data files are not supported".into(),
                    ));
                }
                data_file = Some(value.to_string());
            }
            "line skip" | "lineskip" => {
                line_skip = value
                    .parse()
                    .map_err(|_| e("line skip", format!("`{value}` is not a number")))?
            }
            "byte skip" | "byteskip" => {
                byte_skip = value
                    .parse()
                    .map_err(|_| e("byte skip", format!("`{value}` is not a number")))?;
                if byte_skip < -1 {
                    return Err(e("byte skip", format!("{byte_skip} is below -1")));
                }
            }
            _ => {} // kinds, centers, units, space origin, ...: not needed to render
        }
    }
    let voxel_type = voxel_type.ok_or_else(|| e("type", "missing".into()))?;
    let dimension = dimension.ok_or_else(|| e("dimension", "missing".into()))?;
    let sizes = sizes.ok_or_else(|| e("sizes", "missing".into()))?;
    let encoding = encoding.ok_or_else(|| e("encoding", "missing".into()))?;
    if sizes.len() != dimension {
        return Err(e(
            "sizes",
            format!("{} sizes for dimension {dimension}", sizes.len()),
        ));
    }
    // A leading axis of size 1 (a scalar "channel") is accepted.
    let (first, spatial) = match dimension {
        3 => (0, 0),
        4 if sizes[0] == 1 => (1, 1),
        _ => {
            return Err(e(
                "dimension",
                format!("{dimension}: only 3-D scalar volumes are supported"),
            ))
        }
    };
    let dims = [sizes[first], sizes[first + 1], sizes[first + 2]];
    check_dims(origin, "sizes", dims)?;
    let mut spacing = [1.0; 3];
    let mut orientation = AxisMap::RAS;
    // Signs taking the space's coordinates to RAS.
    let to_ras = match &space {
        Some(name) => nrrd_space_to_ras(name).map_err(|m| e("space", m))?,
        None => [1.0; 3],
    };
    if let Some(sd) = &space_dimension {
        if sd.trim() != "3" {
            return Err(e(
                "space dimension",
                format!("`{sd}`: only 3-D spaces are supported"),
            ));
        }
    }
    if let Some(d) = &directions {
        if d.len() != dimension {
            return Err(e(
                "space directions",
                format!("{} entries for dimension {dimension}", d.len()),
            ));
        }
        if spatial == 1 && d[0].is_some() {
            return Err(e(
                "space directions",
                "the leading non-spatial axis must be `none`".into(),
            ));
        }
        let mut m = [[0.0; 3]; 3];
        for a in 0..3 {
            let v = d[spatial + a].as_ref().ok_or_else(|| {
                e(
                    "space directions",
                    format!("axis {}: `none` for a spatial axis", spatial + a),
                )
            })?;
            if v.len() != 3 {
                return Err(e(
                    "space directions",
                    format!(
                        "axis {}: {} components, 3 expected (a 3-D space)",
                        spatial + a,
                        v.len()
                    ),
                ));
            }
            for r in 0..3 {
                m[r][a] = v[r] * to_ras[r];
            }
        }
        (orientation, spacing) = axis_map(m, dims).map_err(|m| e("space directions", m))?;
    } else if let Some(s) = &spacings {
        if s.len() != dimension {
            return Err(e(
                "spacings",
                format!("{} values for dimension {dimension}", s.len()),
            ));
        }
        for a in 0..3 {
            // NaN marks a non-spatial axis; keep 1.0 there.
            if !s[spatial + a].is_nan() {
                spacing[a] = s[spatial + a];
            }
        }
    }
    check_spacing(origin, "spacings", spacing)?;
    let endian = match endian {
        Some(v) => v,
        None if voxel_type.size() == 1 || encoding == NrrdEncoding::Ascii => Endian::Little,
        None => return Err(e("endian", "missing (needed for multi-byte types)".into())),
    };
    let data_at = match (end, &data_file) {
        (Some(p), _) => p,
        (None, Some(_)) => bytes.len(),
        (None, None) => {
            return Err(e(
                "header",
                "no blank line ends the header and no data file is named".into(),
            ))
        }
    };
    Ok((
        NrrdHeader {
            voxel_type,
            dims,
            encoding,
            endian,
            spacing,
            space,
            orientation,
            data_file,
            line_skip,
            byte_skip,
        },
        data_at,
    ))
}

/// The signs that take coordinates of the NRRD `space` to RAS, or why the space is refused.
/// `scanner-xyz` and `3D-right-handed` carry no anatomical orientation: their x, y, z are taken as
/// R, A, S, the same rule as a NIfTI file without qform or sform (ITK, and so 3D Slicer, takes them
/// as L, P, S instead). `3D-left-handed` cannot be put in RAS without a mirror nobody asked for.
fn nrrd_space_to_ras(space: &str) -> std::result::Result<[f64; 3], String> {
    match space.trim().to_ascii_lowercase().as_str() {
        "right-anterior-superior" | "ras" => Ok([1.0, 1.0, 1.0]),
        "left-anterior-superior" | "las" => Ok([-1.0, 1.0, 1.0]),
        "left-posterior-superior" | "lps" => Ok([-1.0, -1.0, 1.0]),
        "scanner-xyz" | "3d-right-handed" => Ok([1.0, 1.0, 1.0]),
        "3d-left-handed" => Err(format!(
            "`{space}`: a left-handed space with no anatomical axes cannot be put in RAS without \
             mirroring it"
        )),
        s if s.ends_with("-time") || matches!(s, "rast" | "last" | "lpst") => {
            Err(format!("`{space}`: only 3-D spaces are supported"))
        }
        _ => Err(format!(
            "`{space}` is not supported (right-anterior-superior, left-anterior-superior, \
             left-posterior-superior, scanner-xyz, 3D-right-handed)"
        )),
    }
}

fn parse_space_directions(value: &str, origin: &Path) -> Result<Vec<Option<Vec<f64>>>> {
    let e = |m: String| err(origin, "space directions", m);
    let mut out = Vec::new();
    let mut rest = value.trim();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
        } else if rest.starts_with('(') {
            let close = rest
                .find(')')
                .ok_or_else(|| e("a vector has no closing `)`".into()))?;
            let comps: Vec<f64> = rest[1..close]
                .split(',')
                .map(|v| {
                    v.trim()
                        .parse::<f64>()
                        .map_err(|_| e(format!("`{}` is not a number", v.trim())))
                })
                .collect::<Result<_>>()?;
            out.push(Some(comps));
            rest = rest[close + 1..].trim_start();
        } else {
            return Err(e(format!("unexpected `{rest}`")));
        }
        if out.len() > 16 {
            return Err(e("too many vectors".into()));
        }
    }
    Ok(out)
}

/// Reads an NRRD volume (`.nrrd` with attached data, or `.nhdr` naming a detached data file).
pub fn read_nrrd(path: &Path, bits: Option<u32>) -> Result<Volume> {
    let bytes = read_file(path)?;
    let (h, at) = parse_nrrd_header(&bytes, path)?;
    let (data_path, owned);
    let mut data: &[u8] = match &h.data_file {
        Some(f) => {
            let p = PathBuf::from(f);
            data_path = if p.is_absolute() {
                p
            } else {
                path.parent().unwrap_or(Path::new(".")).join(p)
            };
            owned = read_file(&data_path)?;
            &owned
        }
        None => {
            data_path = path.to_path_buf();
            &bytes[at..]
        }
    };
    for _ in 0..h.line_skip {
        let nl = data
            .iter()
            .position(|&b| b == b'\n')
            .ok_or_else(|| err(&data_path, "line skip", "fewer lines than skipped"))?;
        data = &data[nl + 1..];
    }
    let n = h.dims.iter().product::<usize>();
    let need = n * h.voxel_type.size();
    let decoded;
    let voxels: &[u8] = match h.encoding {
        NrrdEncoding::Raw => {
            if h.byte_skip == -1 {
                if data.len() < need {
                    return Err(err(
                        &data_path,
                        "data size",
                        format!("{} bytes, {need} needed", data.len()),
                    ));
                }
                &data[data.len() - need..]
            } else {
                let skip = h.byte_skip as usize;
                if skip > data.len() {
                    return Err(err(&data_path, "byte skip", "past the end of the data"));
                }
                &data[skip..]
            }
        }
        NrrdEncoding::Gzip => {
            let skip = h.byte_skip.max(0) as usize;
            decoded = gunzip(&data_path, data, need.saturating_add(skip))?;
            if skip > decoded.len() {
                return Err(err(&data_path, "byte skip", "past the end of the data"));
            }
            &decoded[skip..]
        }
        NrrdEncoding::Ascii => {
            let text = String::from_utf8_lossy(data);
            let mut out = Vec::with_capacity(need);
            for (i, tok) in text
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|t| !t.is_empty())
                .enumerate()
            {
                if i >= n {
                    return Err(err(
                        &data_path,
                        "data size",
                        format!("more than the {n} values the sizes give"),
                    ));
                }
                let v: f64 = tok
                    .parse()
                    .map_err(|_| err(&data_path, "data", format!("`{tok}` is not a number")))?;
                write_value(&mut out, h.voxel_type, v, Endian::Little);
            }
            decoded = out;
            return to_volume(
                &data_path,
                &decoded,
                Stored {
                    voxel_type: h.voxel_type,
                    endian: Endian::Little,
                    dims: h.dims,
                    spacing: h.spacing,
                    scale: None,
                    orient: h.orientation,
                },
                bits,
            );
        }
    };
    to_volume(
        &data_path,
        voxels,
        Stored {
            voxel_type: h.voxel_type,
            endian: h.endian,
            dims: h.dims,
            spacing: h.spacing,
            scale: None,
            orient: h.orientation,
        },
        bits,
    )
}

fn write_value(out: &mut Vec<u8>, t: VoxelType, v: f64, endian: Endian) {
    macro_rules! put {
        ($x:expr) => {
            match endian {
                Endian::Little => out.extend_from_slice(&$x.to_le_bytes()),
                Endian::Big => out.extend_from_slice(&$x.to_be_bytes()),
            }
        };
    }
    match t {
        VoxelType::U8 => out.push(v as u8),
        VoxelType::I8 => out.push(v as i8 as u8),
        VoxelType::U16 => put!(v as u16),
        VoxelType::I16 => put!(v as i16),
        VoxelType::U32 => put!(v as u32),
        VoxelType::I32 => put!(v as i32),
        VoxelType::F32 => put!(v as f32),
        VoxelType::F64 => put!(v),
    }
}

/// The voxels of `vol` as stored bytes: u8 when the volume has at most 8 bits, else u16.
fn voxel_bytes(vol: &Volume, endian: Endian) -> (VoxelType, Vec<u8>) {
    let t = if vol.bits <= 8 {
        VoxelType::U8
    } else {
        VoxelType::U16
    };
    let mut out = Vec::with_capacity(vol.len() * t.size());
    for &v in &vol.data {
        write_value(&mut out, t, f64::from(v), endian);
    }
    (t, out)
}

/// Writes the whole file to a temporary name beside `path` and renames it: no partial file is left.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| ModelError::Io {
        path: path.display().to_string(),
        source,
    };
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let tmp = dir.join(format!(
        ".{}.tmp",
        path.file_name()
            .map(|n| n.to_string_lossy())
            .unwrap_or_default()
    ));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = GzEncoder::new(Vec::new(), Compression::best());
    enc.write_all(bytes).expect("writing to memory");
    enc.finish().expect("writing to memory")
}

/// Writes `vol` as an NRRD file with attached data (u8 or u16, little endian), stored RAS as a
/// [`Volume`] is: `space: right-anterior-superior`, `space directions` the diagonal of the
/// spacings, `space origin` 0 (what 3D Slicer and ITK need to place it).
pub fn write_nrrd(path: &Path, vol: &Volume, encoding: NrrdEncoding, comment: &str) -> Result<()> {
    let (t, raw) = voxel_bytes(vol, Endian::Little);
    let mut out = Vec::new();
    out.extend_from_slice(b"NRRD0004\n");
    for line in comment.lines() {
        out.extend_from_slice(format!("# {line}\n").as_bytes());
    }
    let enc = match encoding {
        NrrdEncoding::Raw => "raw",
        NrrdEncoding::Gzip => "gzip",
        NrrdEncoding::Ascii => "ascii",
    };
    let [nx, ny, nz] = vol.dims;
    let [sx, sy, sz] = vol.spacing;
    out.extend_from_slice(
        format!(
            "type: {}\ndimension: 3\nspace: right-anterior-superior\nsizes: {nx} {ny} {nz}\n\
             space directions: ({sx},0,0) (0,{sy},0) (0,0,{sz})\nkinds: domain domain domain\n\
             space origin: (0,0,0)\nencoding: {enc}\nendian: little\n\n",
            if t == VoxelType::U8 {
                "uint8"
            } else {
                "uint16"
            }
        )
        .as_bytes(),
    );
    match encoding {
        NrrdEncoding::Raw => out.extend_from_slice(&raw),
        NrrdEncoding::Gzip => out.extend_from_slice(&gzip(&raw)),
        NrrdEncoding::Ascii => {
            for (i, v) in vol.data.iter().enumerate() {
                out.extend_from_slice(v.to_string().as_bytes());
                out.push(if (i + 1) % nx == 0 { b'\n' } else { b' ' });
            }
        }
    }
    write_atomically(path, &out)
}

/// Writes `vol` as a raw file (u8 when it has at most 8 bits, else u16 in `endian` order); returns
/// the stored type.
pub fn write_raw(path: &Path, vol: &Volume, endian: Endian) -> Result<VoxelType> {
    let (t, raw) = voxel_bytes(vol, endian);
    write_atomically(path, &raw)?;
    Ok(t)
}

// ------------------------------------------------------------------------------------------------
// NIfTI-1
// ------------------------------------------------------------------------------------------------

/// Which NIfTI-1 transform placed a volume (chosen as nibabel's `get_best_affine` does).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NiftiTransform {
    /// `sform_code > 0`: the affine `srow_x`, `srow_y`, `srow_z`.
    Sform,
    /// `sform_code` 0 and `qform_code > 0`: the quaternion, `pixdim` and `qfac` (`pixdim[0]`).
    Qform,
    /// Both codes 0 (the standard's "method 1"): `pixdim` only, axes taken as RAS.
    Pixdim,
}

/// The fields of a NIfTI-1 header that matter here.
#[derive(Debug, Clone, PartialEq)]
pub struct NiftiHeader {
    pub endian: Endian,
    pub dims: [usize; 3],
    pub voxel_type: VoxelType,
    /// Voxel size along each stored axis: the column lengths of the chosen affine (`pixdim` for a
    /// qform or no transform).
    pub spacing: [f64; 3],
    pub transform: NiftiTransform,
    /// How the stored axes lie in RAS (applied by [`read_nifti`]).
    pub orientation: AxisMap,
    /// Byte offset of the voxels in the (decompressed) `.nii` file.
    pub vox_offset: usize,
    /// `(scl_slope, scl_inter)` when the slope is set (non-zero) and not the identity.
    pub scale: Option<(f64, f64)>,
}

const NIFTI_HEADER: usize = 348;

/// Parses a NIfTI-1 single-file header from the start of `bytes` (decompressed).
pub fn parse_nifti_header(bytes: &[u8], origin: &Path) -> Result<NiftiHeader> {
    let e = |field: &str, m: String| err(origin, field, m);
    if bytes.len() < NIFTI_HEADER {
        return Err(e(
            "sizeof_hdr",
            format!(
                "{} bytes: shorter than the 348-byte NIfTI-1 header",
                bytes.len()
            ),
        ));
    }
    let le = i32::from_le_bytes(bytes[0..4].try_into().expect("4 bytes"));
    let be = i32::from_be_bytes(bytes[0..4].try_into().expect("4 bytes"));
    let endian = if le == 348 {
        Endian::Little
    } else if be == 348 {
        Endian::Big
    } else if le == 540 || be == 540 {
        return Err(e("sizeof_hdr", "540: NIfTI-2 is not supported".into()));
    } else {
        return Err(e(
            "sizeof_hdr",
            format!("{le}: not a NIfTI-1 file (348 expected)"),
        ));
    };
    let i16_at = |o: usize| {
        let a = [bytes[o], bytes[o + 1]];
        match endian {
            Endian::Little => i16::from_le_bytes(a),
            Endian::Big => i16::from_be_bytes(a),
        }
    };
    let f32_at = |o: usize| {
        let a = [bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]];
        f64::from(match endian {
            Endian::Little => f32::from_le_bytes(a),
            Endian::Big => f32::from_be_bytes(a),
        })
    };
    let magic = &bytes[344..348];
    if magic == b"ni1\0" {
        return Err(e(
            "magic",
            "`ni1`: header/image pairs (.hdr/.img) are not supported; use a single .nii".into(),
        ));
    }
    if magic != b"n+1\0" {
        return Err(e(
            "magic",
            format!("{magic:?}: not a single-file NIfTI-1 (`n+1`)"),
        ));
    }
    let dim: Vec<i16> = (0..8).map(|k| i16_at(40 + 2 * k)).collect();
    let ndim = dim[0];
    if !(3..=7).contains(&ndim) {
        return Err(e(
            "dim[0]",
            format!("{ndim}: only 3-D volumes are supported"),
        ));
    }
    if let Some((k, d)) = dim
        .iter()
        .enumerate()
        .take(ndim as usize + 1)
        .skip(4)
        .find(|(_, &d)| d > 1)
    {
        return Err(e(
            &format!("dim[{k}]"),
            format!("{d}: only one 3-D volume is supported (no time series)"),
        ));
    }
    let mut dims = [0usize; 3];
    for a in 0..3 {
        let d = dim[a + 1];
        if d < 1 {
            return Err(e(&format!("dim[{}]", a + 1), format!("{d}: must be >= 1")));
        }
        dims[a] = d as usize;
    }
    check_dims(origin, "dim", dims)?;
    let datatype = i16_at(70);
    let voxel_type = match datatype {
        2 => VoxelType::U8,
        4 => VoxelType::I16,
        8 => VoxelType::I32,
        16 => VoxelType::F32,
        64 => VoxelType::F64,
        256 => VoxelType::I8,
        512 => VoxelType::U16,
        768 => VoxelType::U32,
        other => {
            return Err(e(
                "datatype",
                format!("{other} is not supported (uint8, int8, uint16, int16, uint32, int32, float32, float64)"),
            ))
        }
    };
    let bitpix = i16_at(72);
    if bitpix as usize != voxel_type.size() * 8 {
        return Err(e(
            "bitpix",
            format!("{bitpix} does not match datatype {datatype}"),
        ));
    }
    let (transform, orientation, spacing) = nifti_orientation(dims, &i16_at, &f32_at, origin)?;
    let vox_offset = f32_at(108);
    if !(vox_offset.is_finite() && vox_offset >= NIFTI_HEADER as f64 && vox_offset < 1e12) {
        return Err(e(
            "vox_offset",
            format!("{vox_offset}: must be at least 348"),
        ));
    }
    let slope = f32_at(112);
    let inter = f32_at(116);
    let scale =
        if slope.is_finite() && inter.is_finite() && slope != 0.0 && (slope, inter) != (1.0, 0.0) {
            Some((slope, inter))
        } else {
            None
        };
    Ok(NiftiHeader {
        endian,
        dims,
        voxel_type,
        spacing,
        transform,
        orientation,
        vox_offset: vox_offset as usize,
        scale,
    })
}

/// Chooses the transform as nibabel's `Nifti1Header.get_best_affine` does (the sform when
/// `sform_code` is set, else the qform when `qform_code` is set, else `pixdim` alone) and finds how
/// the stored axes lie in RAS ([`axis_map`]). Header offsets: nifti1.h.
fn nifti_orientation(
    dims: [usize; 3],
    i16_at: &dyn Fn(usize) -> i16,
    f32_at: &dyn Fn(usize) -> f64,
    origin: &Path,
) -> Result<(NiftiTransform, AxisMap, [f64; 3])> {
    let e = |field: &str, m: String| err(origin, field, m);
    let (qform_code, sform_code) = (i16_at(252), i16_at(254));
    for (field, code) in [("qform_code", qform_code), ("sform_code", sform_code)] {
        if code < 0 {
            return Err(e(
                field,
                format!("{code}: transform codes are 0 or positive"),
            ));
        }
    }
    let pixdim = [f32_at(80), f32_at(84), f32_at(88)];
    if sform_code > 0 {
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = f32_at(280 + 16 * r + 4 * c);
            }
        }
        let (map, spacing) = axis_map(m, dims).map_err(|m| e("sform", m))?;
        return Ok((NiftiTransform::Sform, map, spacing));
    }
    // pixdim 0 means "not set" in many writers (nifti1_io.c reads it as 1 too).
    let spacing = pixdim.map(|p| if p == 0.0 { 1.0 } else { p.abs() });
    if qform_code > 0 {
        if let Some(a) = (0..3).find(|&a| pixdim[a] < 0.0) {
            // nibabel refuses these; nifti1_io.c silently reads 1.0.
            return Err(e(
                &format!("pixdim[{}]", a + 1),
                format!(
                    "{}: a negative voxel size with a qform is ambiguous (a flip or not?)",
                    pixdim[a]
                ),
            ));
        }
        let q = [f32_at(256), f32_at(260), f32_at(264)];
        let r = quaternion_matrix(q).map_err(|m| e("quatern_b/c/d", m))?;
        // qfac = pixdim[0]: -1 reverses the third axis, anything else counts as 1 (nifti1_io.c).
        let qfac = if f32_at(76) < 0.0 { -1.0 } else { 1.0 };
        check_spacing(origin, "pixdim", spacing)?;
        let scale = [spacing[0], spacing[1], spacing[2] * qfac];
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = r[i][j] * scale[j];
            }
        }
        // The spacings stay pixdim's: the f32 quaternion's columns are unit only to ~1e-7.
        let (map, _) = axis_map(m, dims).map_err(|m| e("qform", m))?;
        return Ok((NiftiTransform::Qform, map, spacing));
    }
    check_spacing(origin, "pixdim", spacing)?;
    Ok((NiftiTransform::Pixdim, AxisMap::RAS, spacing))
}

/// The rotation matrix of NIfTI's quaternion `(b, c, d)`, `a = sqrt(1 - b² - c² - d²)` (nifti1.h,
/// "QUATERNION REPRESENTATION OF ROTATION MATRIX"). A vector a little longer than 1 (f32 rounding,
/// up to 1e-6) is normalized with `a = 0`, a 180-degree turn, as nifti1_io.c does; a longer one is
/// refused, as nibabel refuses it.
pub fn quaternion_matrix(q: [f64; 3]) -> std::result::Result<[[f64; 3]; 3], String> {
    let [mut b, mut c, mut d] = q;
    if q.iter().any(|v| !v.is_finite()) {
        return Err(format!("({b}, {c}, {d}) is not finite"));
    }
    let n2 = b * b + c * c + d * d;
    if n2 > 1.0 + 1e-6 {
        return Err(format!(
            "({b}, {c}, {d}) is longer than 1: not a unit quaternion"
        ));
    }
    let mut a = 1.0 - n2;
    if a < 1e-7 {
        let n = n2.sqrt();
        (b, c, d) = (b / n, c / n, d / n);
        a = 0.0;
    } else {
        a = a.sqrt();
    }
    Ok([
        [
            a * a + b * b - c * c - d * d,
            2.0 * (b * c - a * d),
            2.0 * (b * d + a * c),
        ],
        [
            2.0 * (b * c + a * d),
            a * a + c * c - b * b - d * d,
            2.0 * (c * d - a * b),
        ],
        [
            2.0 * (b * d - a * c),
            2.0 * (c * d + a * b),
            a * a + d * d - b * b - c * c,
        ],
    ])
}

/// NIfTI's quaternion `(b, c, d)` of a rotation matrix (`det = +1`), with `a >= 0` as the
/// standard asks: the inverse of [`quaternion_matrix`] (Shepperd's method: divide by the largest of
/// the four components).
pub fn matrix_quaternion(r: [[f64; 3]; 3]) -> [f64; 3] {
    let trace = r[0][0] + r[1][1] + r[2][2];
    let four = [
        1.0 + trace,                       // 4a²
        1.0 + r[0][0] - r[1][1] - r[2][2], // 4b²
        1.0 - r[0][0] + r[1][1] - r[2][2], // 4c²
        1.0 - r[0][0] - r[1][1] + r[2][2], // 4d²
    ];
    let big = (0..4)
        .max_by(|&x, &y| four[x].total_cmp(&four[y]))
        .unwrap_or(0);
    let s = 0.5 * four[big].max(0.0).sqrt(); // the largest component
    let k = 0.25 / s;
    let (a, b, c, d) = match big {
        0 => (
            s,
            (r[2][1] - r[1][2]) * k,
            (r[0][2] - r[2][0]) * k,
            (r[1][0] - r[0][1]) * k,
        ),
        1 => (
            (r[2][1] - r[1][2]) * k,
            s,
            (r[0][1] + r[1][0]) * k,
            (r[0][2] + r[2][0]) * k,
        ),
        2 => (
            (r[0][2] - r[2][0]) * k,
            (r[0][1] + r[1][0]) * k,
            s,
            (r[1][2] + r[2][1]) * k,
        ),
        _ => (
            (r[1][0] - r[0][1]) * k,
            (r[0][2] + r[2][0]) * k,
            (r[1][2] + r[2][1]) * k,
            s,
        ),
    };
    if a < 0.0 {
        [-b, -c, -d]
    } else {
        [b, c, d]
    }
}

/// Reads a NIfTI-1 volume (`.nii`, or gzip-compressed `.nii.gz`).
pub fn read_nifti(path: &Path, bits: Option<u32>) -> Result<Volume> {
    let raw = read_file(path)?;
    let mut reader: Box<dyn Read + '_> = if raw.starts_with(&[0x1f, 0x8b]) {
        Box::new(GzDecoder::new(&raw[..]))
    } else {
        Box::new(&raw[..])
    };
    let gz_err = |e: std::io::Error| err(path, "gzip data", e);
    let mut bytes = Vec::new();
    reader
        .by_ref()
        .take(NIFTI_HEADER as u64)
        .read_to_end(&mut bytes)
        .map_err(gz_err)?;
    let h = parse_nifti_header(&bytes, path)?;
    // Decompress no more than the header says the file holds, so a hostile file cannot exhaust
    // memory.
    let total = h.vox_offset + h.dims.iter().product::<usize>() * h.voxel_type.size();
    reader
        .take((total - NIFTI_HEADER) as u64)
        .read_to_end(&mut bytes)
        .map_err(gz_err)?;
    let n = h.dims.iter().product::<usize>();
    let need = n * h.voxel_type.size();
    if bytes.len() < h.vox_offset + need {
        return Err(err(
            path,
            "data size",
            format!(
                "{} bytes after vox_offset {}, but {} x {} x {} x {} bytes ({}) = {need} needed",
                bytes.len().saturating_sub(h.vox_offset),
                h.vox_offset,
                h.dims[0],
                h.dims[1],
                h.dims[2],
                h.voxel_type.size(),
                h.voxel_type.name()
            ),
        ));
    }
    to_volume(
        path,
        &bytes[h.vox_offset..h.vox_offset + need],
        Stored {
            voxel_type: h.voxel_type,
            endian: h.endian,
            dims: h.dims,
            spacing: h.spacing,
            scale: h.scale,
            orient: h.orientation,
        },
        bits,
    )
}

/// The orientation fields [`write_nifti_with`] writes.
#[derive(Debug, Clone, PartialEq)]
pub struct NiftiXform {
    /// Voxel-to-world affine, its first three rows (nibabel's `img.affine[:3]`), world = RAS+ mm.
    pub affine: [[f64; 4]; 3],
    /// 0: no sform; 1: scanner anatomical; 2: aligned to another file (nibabel's default); ...
    pub sform_code: i16,
    /// As `sform_code`. The quaternion, `qfac`, `pixdim` and `qoffset` are derived from the affine
    /// whatever the code, as nibabel's `set_qform` does; a sheared affine is refused unless 0.
    pub qform_code: i16,
}

impl NiftiXform {
    /// How [`write_nifti`] places a volume (stored RAS): `diag(spacing)`, voxel 0 at the origin, both
    /// codes 1 (scanner anatomical), so every reader (nibabel, 3D Slicer, FSL) agrees.
    pub fn ras(spacing: [f64; 3]) -> Self {
        Self::from_axes(AxisMap::RAS, spacing)
    }

    /// The affine of a volume stored as `map` says (spacings in stored order), codes 1.
    pub fn from_axes(map: AxisMap, spacing: [f64; 3]) -> Self {
        let m = map.direction_matrix(spacing);
        let mut affine = [[0.0; 4]; 3];
        for r in 0..3 {
            affine[r][..3].copy_from_slice(&m[r]);
        }
        Self {
            affine,
            sform_code: 1,
            qform_code: 1,
        }
    }
}

/// Writes `vol` as a single-file NIfTI-1 (u8 or u16, little endian), gzip-compressed when the name
/// ends in `.gz`, stored RAS as a [`Volume`] is ([`NiftiXform::ras`]).
pub fn write_nifti(path: &Path, vol: &Volume, description: &str) -> Result<()> {
    write_nifti_with(path, vol, description, &NiftiXform::ras(vol.spacing))
}

/// Writes `vol`'s voxels as they are stored, placed by `xform` (which need not be RAS: the tests
/// write the same volume in other orientations, and oblique). `pixdim` is the affine's column
/// lengths; `vol.spacing` is not used.
pub fn write_nifti_with(
    path: &Path,
    vol: &Volume,
    description: &str,
    xform: &NiftiXform,
) -> Result<()> {
    let fail = |field: &str, m: String| err(path, field, m);
    let a = &xform.affine;
    if a.iter().flatten().any(|v| !v.is_finite()) {
        return Err(fail("affine", format!("{a:?} is not finite")));
    }
    let zooms: [f64; 3] =
        std::array::from_fn(|c| (0..3).map(|r| a[r][c] * a[r][c]).sum::<f64>().sqrt());
    if zooms.contains(&0.0) {
        return Err(fail("affine", format!("{a:?} has a zero column")));
    }
    // The qform: R = columns / zooms, the third reversed (qfac = -1) when R is a reflection.
    let mut r: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] / zooms[j]));
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    let qfac = if det < 0.0 { -1.0 } else { 1.0 };
    for row in r.iter_mut() {
        row[2] *= qfac;
    }
    let orthogonal = (0..3).all(|i| {
        (0..3).all(|j| {
            let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            (dot - f64::from(u8::from(i == j))).abs() < 1e-6
        })
    });
    if !orthogonal && xform.qform_code != 0 {
        return Err(fail(
            "qform_code",
            format!(
                "{}: a sheared affine cannot be a qform (write qform_code 0)",
                xform.qform_code
            ),
        ));
    }
    let quatern = if orthogonal {
        matrix_quaternion(r)
    } else {
        [0.0; 3]
    };
    let (t, raw) = voxel_bytes(vol, Endian::Little);
    let mut h = vec![0u8; NIFTI_HEADER + 4];
    let put_i16 = |h: &mut Vec<u8>, o: usize, v: i16| h[o..o + 2].copy_from_slice(&v.to_le_bytes());
    let put_f32 = |h: &mut Vec<u8>, o: usize, v: f32| h[o..o + 4].copy_from_slice(&v.to_le_bytes());
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    h[38] = b'r'; // "regular"
    put_i16(&mut h, 40, 3);
    for a in 0..3 {
        put_i16(&mut h, 42 + 2 * a, vol.dims[a] as i16);
    }
    for k in 4..8 {
        put_i16(&mut h, 40 + 2 * k, 1);
    }
    let (datatype, bitpix) = if t == VoxelType::U8 {
        (2, 8)
    } else {
        (512, 16)
    };
    put_i16(&mut h, 70, datatype);
    put_i16(&mut h, 72, bitpix);
    put_f32(&mut h, 76, qfac as f32);
    for (k, z) in zooms.iter().enumerate() {
        put_f32(&mut h, 80 + 4 * k, *z as f32);
    }
    put_f32(&mut h, 108, (NIFTI_HEADER + 4) as f32);
    put_f32(&mut h, 112, 1.0); // scl_slope
    h[123] = 2; // xyzt_units: millimetres
    let d = description.as_bytes();
    h[148..148 + d.len().min(79)].copy_from_slice(&d[..d.len().min(79)]);
    put_i16(&mut h, 252, xform.qform_code);
    put_i16(&mut h, 254, xform.sform_code);
    for k in 0..3 {
        put_f32(&mut h, 256 + 4 * k, quatern[k] as f32);
        put_f32(&mut h, 268 + 4 * k, a[k][3] as f32); // qoffset_x/y/z
    }
    for (row, srow) in a.iter().enumerate() {
        for (c, v) in srow.iter().enumerate() {
            put_f32(&mut h, 280 + 16 * row + 4 * c, *v as f32);
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h.extend_from_slice(&raw);
    let gz = path
        .file_name()
        .is_some_and(|n| n.to_string_lossy().to_ascii_lowercase().ends_with(".gz"));
    write_atomically(path, &if gz { gzip(&h) } else { h })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{head_phantom, sphere_phantom};

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cube5-volume-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn nrrd_round_trips_in_every_encoding() {
        let vol = head_phantom(12, 12).unwrap();
        for (enc, name) in [
            (NrrdEncoding::Raw, "a.nrrd"),
            (NrrdEncoding::Gzip, "b.nrrd"),
            (NrrdEncoding::Ascii, "c.nrrd"),
        ] {
            let p = scratch(name);
            write_nrrd(&p, &vol, enc, "test").unwrap();
            let back = read_nrrd(&p, Some(12)).unwrap();
            assert_eq!(back, vol, "{enc:?}");
        }
    }

    #[test]
    fn nifti_round_trips_plain_and_gzip() {
        let mut vol = sphere_phantom(10, 8).unwrap();
        vol.spacing = [0.5, 0.75, 2.0];
        for name in ["s.nii", "s.nii.gz"] {
            let p = scratch(name);
            write_nifti(&p, &vol, "sphere").unwrap();
            assert_eq!(read_nifti(&p, None).unwrap(), vol, "{name}");
        }
    }

    #[test]
    fn raw_size_must_match_dims_times_type() {
        let vol = head_phantom(8, 12).unwrap();
        let p = scratch("h.raw");
        assert_eq!(write_raw(&p, &vol, Endian::Big).unwrap(), VoxelType::U16);
        let mut spec = RawSpec {
            dims: [8, 8, 8],
            voxel_type: VoxelType::U16,
            endian: Endian::Big,
            spacing: [1.0; 3],
            offset: 0,
        };
        assert_eq!(read_raw(&p, &spec, Some(12)).unwrap(), vol);
        spec.dims = [8, 8, 9];
        let e = read_raw(&p, &spec, None).unwrap_err().to_string();
        assert!(
            e.contains("h.raw") && e.contains("file size") && e.contains("1024 bytes"),
            "{e}"
        );
        spec.dims = [8, 8, 8];
        spec.endian = Endian::Little;
        // Little-endian reading of big-endian 12-bit data overflows 12 bits: refused, not wrapped.
        assert!(read_raw(&p, &spec, Some(12)).is_err());
    }

    #[test]
    fn signed_and_float_data_are_mapped_onto_the_width() {
        let p = scratch("f.nrrd");
        let mut text =
            b"NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\nencoding: raw\nendian: big\n\n"
                .to_vec();
        text.extend_from_slice(&(-1.5f32).to_be_bytes());
        text.extend_from_slice(&(2.5f32).to_be_bytes());
        std::fs::write(&p, &text).unwrap();
        let v = read_nrrd(&p, Some(8)).unwrap();
        assert_eq!(v.data, vec![0, 255]);
        assert_eq!(v.bits, 8);
    }

    #[test]
    fn header_errors_name_the_field() {
        let p = Path::new("x.nrrd");
        let cases: [(&[u8], &str); 6] = [
            (b"P6\n", "magic"),
            (b"NRRD0004\ntype: quaternion\n\n", "type"),
            (
                b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2\nencoding: raw\n\n",
                "sizes",
            ),
            (
                b"NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n",
                "endian",
            ),
            (
                b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n\n",
                "encoding",
            ),
            (
                b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 0\nencoding: raw\n\n",
                "sizes",
            ),
        ];
        for (bytes, field) in cases {
            let e = parse_nrrd_header(bytes, p).unwrap_err().to_string();
            assert!(e.contains(&format!("x.nrrd: {field}")), "{e}");
        }
        let mut h = vec![0u8; 352];
        h[0..4].copy_from_slice(&348i32.to_le_bytes());
        h[344..348].copy_from_slice(b"n+1\0");
        let e = parse_nifti_header(&h, Path::new("y.nii"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("y.nii: dim[0]"), "{e}");
        let e = parse_nifti_header(&h[..100], Path::new("y.nii"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("sizeof_hdr"), "{e}");
    }
}
