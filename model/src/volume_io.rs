//! Volume files: raw voxels, NRRD (raw, gzip and ASCII encodings, attached or detached data) and
//! NIfTI-1 (`.nii`, `.nii.gz`), read into a [`Volume`]; writers for NRRD, NIfTI and raw so the tests
//! and the shipped examples (`scenes/data/`) are made from the embedded phantoms.
//!
//! Voxel values: unsigned integer types of at most 16 bits are kept exactly (the volume's width is
//! the one asked for, or the smallest of 8..=16 that holds the largest value); signed, 32-bit and
//! floating-point types (after NIfTI's `scl_slope`/`scl_inter`) are mapped linearly from their
//! range `[min, max]` onto `0 ..= 2^bits - 1` (12 bits unless asked), rounding to nearest.
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

/// How stored voxels are laid out.
struct Stored {
    voxel_type: VoxelType,
    endian: Endian,
    dims: [usize; 3],
    spacing: [f64; 3],
    /// NIfTI's `(scl_slope, scl_inter)`.
    scale: Option<(f64, f64)>,
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
    Volume::new(dims, spacing, width, out).map_err(|e| err(path, "volume", e))
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
    pub spacing: [f64; 3],
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
    let mut directions: Option<Vec<Option<f64>>> = None;
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
            "sizes" => {
                sizes = Some(
                    value
                        .split_whitespace()
                        .map(|v| {
                            v.parse::<usize>()
                                .map_err(|_| e("sizes", format!("`{v}` is not a size")))
                        })
                        .collect::<Result<_>>()?,
                )
            }
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
            "spacings" => {
                spacings = Some(
                    value
                        .split_whitespace()
                        .map(|v| {
                            v.parse::<f64>()
                                .map_err(|_| e("spacings", format!("`{v}` is not a number")))
                        })
                        .collect::<Result<_>>()?,
                )
            }
            "space directions" => directions = Some(parse_space_directions(value, origin)?),
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
            _ => {} // space, kinds, centers, units, origin, ...: not needed to render
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
    if let Some(s) = &spacings {
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
    } else if let Some(d) = &directions {
        let spatial_dirs: Vec<f64> = d.iter().flatten().copied().collect();
        if spatial_dirs.len() != 3 {
            return Err(e(
                "space directions",
                format!("{} spatial vectors, 3 expected", spatial_dirs.len()),
            ));
        }
        spacing.copy_from_slice(&spatial_dirs);
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
            data_file,
            line_skip,
            byte_skip,
        },
        data_at,
    ))
}

fn parse_space_directions(value: &str, origin: &Path) -> Result<Vec<Option<f64>>> {
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
            out.push(Some(comps.iter().map(|c| c * c).sum::<f64>().sqrt()));
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

/// Writes `vol` as an NRRD file with attached data (u8 or u16, little endian).
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
            "type: {}\ndimension: 3\nsizes: {nx} {ny} {nz}\nspacings: {sx} {sy} {sz}\n\
             encoding: {enc}\nendian: little\n\n",
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

/// The fields of a NIfTI-1 header that matter here.
#[derive(Debug, Clone, PartialEq)]
pub struct NiftiHeader {
    pub endian: Endian,
    pub dims: [usize; 3],
    pub voxel_type: VoxelType,
    pub spacing: [f64; 3],
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
    let mut spacing = [1.0; 3];
    for (a, s) in spacing.iter_mut().enumerate() {
        let p = f32_at(76 + 4 * (a + 1)).abs();
        // pixdim 0 means "not set" in many writers.
        if p != 0.0 {
            *s = p;
        }
    }
    check_spacing(origin, "pixdim", spacing)?;
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
        vox_offset: vox_offset as usize,
        scale,
    })
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
        },
        bits,
    )
}

/// Writes `vol` as a single-file NIfTI-1 (u8 or u16, little endian), gzip-compressed when the name
/// ends in `.gz`.
pub fn write_nifti(path: &Path, vol: &Volume, description: &str) -> Result<()> {
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
    put_f32(&mut h, 76, 1.0); // qfac
    for a in 0..3 {
        put_f32(&mut h, 80 + 4 * a, vol.spacing[a] as f32);
    }
    put_f32(&mut h, 108, (NIFTI_HEADER + 4) as f32);
    put_f32(&mut h, 112, 1.0); // scl_slope
    h[123] = 2; // xyzt_units: millimetres
    let d = description.as_bytes();
    h[148..148 + d.len().min(79)].copy_from_slice(&d[..d.len().min(79)]);
    put_i16(&mut h, 254, 1); // sform_code: scanner
    for a in 0..3 {
        // srow_x/y/z: a diagonal of the spacings.
        put_f32(&mut h, 280 + 16 * a + 4 * a, vol.spacing[a] as f32);
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
