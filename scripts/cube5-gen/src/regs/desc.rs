//! The description of one block (`rtl/**/<block>.regs.toml`): reading, checking, names.

use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One `<block>.regs.toml`, as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Desc {
    pub block: Block,
    #[serde(default)]
    pub constant: Vec<Constant>,
    #[serde(default, rename = "enum")]
    pub enums: Vec<Enum>,
    #[serde(default)]
    pub register: Vec<Register>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    /// The RTL unit, e.g. `cube5_frame`.
    pub name: String,
    pub doc: String,
    /// The SV package that holds the generated part, relative to the description.
    pub sv_package: String,
    /// The generated Rust file, relative to the repository root.
    pub rust: String,
    /// Markdown pages with a generated part, relative to the repository root.
    #[serde(default)]
    pub docs: Vec<DocTarget>,
    /// Bytes per register word (the bus data width / 8).
    #[serde(default = "default_word_bytes")]
    pub word_bytes: u64,
    /// Byte address of register offset 0 on a byte-addressed bus (AXI4-Lite); 0 if absent.
    #[serde(default)]
    pub base: u64,
    /// How the docs name the base of word offsets on a word-addressed port, e.g. "`2^AlphaW` +".
    #[serde(default)]
    pub base_doc: Option<String>,
    /// Bits of a register: no numeric field may reach above it.
    #[serde(default = "default_data_w")]
    pub data_w: u32,
    /// Generate the tables of the AXI4-Lite register block `cube5_axil_regs` into the package
    /// (one entry per word offset; docs/accel-regs.md, "The register block").
    #[serde(default)]
    pub axil: bool,
    /// The interrupt of an `axil` block: `irq_o` = OR of (status & enable).
    #[serde(default)]
    pub irq: Option<Irq>,
}

/// The registers whose AND, ORed over the bits, is an `axil` block's level interrupt.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Irq {
    /// A W1C register: the interrupt status.
    pub status: String,
    /// An RW register: the enable of each status bit.
    pub enable: String,
}

/// Largest word offset of an `axil` block (its tables hold one entry per offset).
pub const AXIL_MAX_WORDS: u64 = 256;

fn default_word_bytes() -> u64 {
    4
}
fn default_data_w() -> u32 {
    32
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DocTarget {
    pub path: String,
    /// `constants`, `enums`, `enum:<Name>`, `registers`, in the order they appear.
    pub show: Vec<String>,
}

/// An integer or an expression over earlier constants (`+ - *`, parentheses).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Int(u64),
    Expr(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constant {
    /// UpperCamelCase (the SV name); the Rust name is its SCREAMING_SNAKE_CASE.
    pub name: String,
    pub value: Value,
    /// Rust type: `u32` or `u64`. The SV type is `int unsigned`.
    #[serde(default = "default_rust_type")]
    pub rust_type: String,
    pub doc: String,
}

fn default_rust_type() -> String {
    "u32".into()
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Enum {
    /// Prefix of the SV names (`CfgRegion` -> `CfgRegionFrame`).
    pub name: String,
    /// Prefix of the Rust names (`REGION` -> `REGION_FRAME`).
    pub rust_prefix: String,
    /// Bits of the encoding: SV `logic [width-1:0]`.
    pub width: u32,
    /// If set, an `int unsigned` localparam of this name holds `width`.
    #[serde(default)]
    pub width_param: Option<String>,
    /// `<block>.<Enum>` whose values these must repeat (same name, same value).
    #[serde(default)]
    pub subset_of: Option<String>,
    pub doc: String,
    pub value: Vec<EnumValue>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnumValue {
    pub name: String,
    pub value: u64,
    #[serde(default)]
    pub doc: String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub enum Access {
    RW,
    RO,
    WO,
    W1C,
}

impl Access {
    pub fn as_str(self) -> &'static str {
        match self {
            Access::RW => "RW",
            Access::RO => "RO",
            Access::WO => "WO",
            Access::W1C => "W1C",
        }
    }
    pub fn rust(self) -> &'static str {
        match self {
            Access::RW => "Rw",
            Access::RO => "Ro",
            Access::WO => "Wo",
            Access::W1C => "W1c",
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Register {
    pub name: String,
    /// Word offset; the byte address is `base + offset * word_bytes`.
    pub offset: u64,
    pub access: Access,
    /// Reset value; absent for registers that reset does not change.
    #[serde(default)]
    pub reset: Option<u64>,
    pub doc: String,
    #[serde(default)]
    pub field: Vec<FieldDesc>,
    /// `<block>.<Register>`: take that register's fields (placed as there) instead of `field`.
    #[serde(default)]
    pub like: Option<String>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldDesc {
    pub name: String,
    /// Lowest bit; absent: right above the previous field (0 for the first).
    #[serde(default)]
    pub lsb: Option<Value>,
    pub width: Value,
    #[serde(default)]
    pub doc: String,
}

/// A field with its placement resolved: numbers where every term is a known constant.
#[derive(Debug, Clone)]
pub struct Field {
    pub name: String,
    pub lsb: Resolved,
    pub width: Resolved,
    pub doc: String,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Resolved {
    Num(u64),
    /// A width in the unit's parameters (`m + 1`): documented, not checked, not generated as code.
    Sym(String),
}

impl Resolved {
    pub fn text(&self) -> String {
        match self {
            Resolved::Num(n) => n.to_string(),
            Resolved::Sym(s) => s.clone(),
        }
    }
}

/// A checked block: the description plus what follows from it.
#[derive(Debug)]
pub struct Checked {
    pub desc: Desc,
    /// The description's path relative to the repository root.
    pub rel: PathBuf,
    /// Its file name (the markers name it).
    pub file_name: String,
    pub values: BTreeMap<String, u64>,
    pub exprs: BTreeMap<String, Expr>,
    /// Per register, its fields with placement resolved.
    pub fields: Vec<Vec<Field>>,
}

/// Read and check one description; `rel` is its path relative to `root`.
pub fn load(root: &Path, rel: &Path) -> Result<Checked, String> {
    let path = root.join(rel);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", rel.display()))?;
    parse(&text, rel)
}

/// Check a description's text; errors are one line and name the file (and the item). A register
/// with `like` is refused: [`parse_with`] resolves it.
pub fn parse(text: &str, rel: &Path) -> Result<Checked, String> {
    parse_with(text, rel, &|like| {
        Err(format!("like {like}: no such register"))
    })
}

/// Whether a description has a register with `like` (it must be checked after the blocks it
/// names).
pub fn has_likes(text: &str) -> bool {
    toml::from_str::<Desc>(text).is_ok_and(|d| d.register.iter().any(|r| r.like.is_some()))
}

/// The fields of register `<block>.<Register>` in `blocks`, placed as there, for `like`.
pub fn like_fields(blocks: &[Checked], like: &str) -> Result<Vec<FieldDesc>, String> {
    let (blk, name) = like
        .split_once('.')
        .ok_or_else(|| format!("like {like} is not <block>.<Register>"))?;
    let b = blocks
        .iter()
        .find(|b| b.desc.block.name == blk)
        .ok_or_else(|| format!("like {like}: no block {blk}"))?;
    let i = b
        .desc
        .register
        .iter()
        .position(|r| r.name == name)
        .ok_or_else(|| format!("like {like}: no register {name} in {blk}"))?;
    let value = |r: &Resolved| match r {
        Resolved::Num(n) => Value::Int(*n),
        Resolved::Sym(s) => Value::Expr(s.clone()),
    };
    Ok(b.fields[i]
        .iter()
        .map(|f| FieldDesc {
            name: f.name.clone(),
            lsb: Some(value(&f.lsb)),
            width: value(&f.width),
            doc: f.doc.clone(),
        })
        .collect())
}

/// [`parse`], with `likes` giving the fields a `like` names.
pub fn parse_with(
    text: &str,
    rel: &Path,
    likes: &dyn Fn(&str) -> Result<Vec<FieldDesc>, String>,
) -> Result<Checked, String> {
    let file = rel.display().to_string();
    let desc: Desc = toml::from_str(text)
        .map_err(|e| format!("{file}: {}", e.to_string().replace('\n', " ").trim_end()))?;
    let err = |what: String| format!("{file}: {what}");

    // Names: one namespace per language (SV localparams, Rust constants).
    let mut sv_names = BTreeSet::new();
    let mut claim = |name: String, what: &str| -> Result<(), String> {
        if !sv_names.insert(name.clone()) {
            return Err(err(format!("{what}: name {name} defined twice")));
        }
        Ok(())
    };

    let mut values = BTreeMap::new();
    let mut exprs = BTreeMap::new();
    for c in &desc.constant {
        check_ident(&c.name).map_err(|e| err(format!("constant {}: {e}", c.name)))?;
        claim(c.name.clone(), &format!("constant {}", c.name))?;
        if c.rust_type != "u32" && c.rust_type != "u64" {
            return Err(err(format!(
                "constant {}: rust_type {} is not u32 or u64",
                c.name, c.rust_type
            )));
        }
        let e = match &c.value {
            Value::Int(n) => Expr::Num(*n),
            Value::Expr(s) => {
                Expr::parse(s).map_err(|e| err(format!("constant {}: {e}", c.name)))?
            }
        };
        let v = e
            .eval(&values)
            .map_err(|e| err(format!("constant {}: {e}", c.name)))?;
        if c.rust_type == "u32" && v > u64::from(u32::MAX) {
            return Err(err(format!("constant {}: {v} does not fit u32", c.name)));
        }
        values.insert(c.name.clone(), v);
        exprs.insert(c.name.clone(), e);
    }

    for en in &desc.enums {
        let what = format!("enum {}", en.name);
        check_ident(&en.name).map_err(|e| err(format!("{what}: {e}")))?;
        if en.width == 0 || en.width > 32 {
            return Err(err(format!("{what}: width {} outside 1..=32", en.width)));
        }
        if let Some(w) = &en.width_param {
            claim(w.clone(), &what)?;
        }
        let mut seen = BTreeMap::new();
        for v in &en.value {
            check_ident(&v.name).map_err(|e| err(format!("{what}: {e}")))?;
            claim(format!("{}{}", en.name, v.name), &what)?;
            if v.value >> en.width != 0 {
                return Err(err(format!(
                    "{what}: {} = {} does not fit {} bits",
                    v.name, v.value, en.width
                )));
            }
            if let Some(other) = seen.insert(v.value, &v.name) {
                return Err(err(format!(
                    "{what}: {} and {} both encode {}",
                    other, v.name, v.value
                )));
            }
        }
    }

    let b = &desc.block;
    if b.word_bytes == 0 || !b.word_bytes.is_power_of_two() {
        return Err(err(format!(
            "block: word_bytes {} is not a power of two",
            b.word_bytes
        )));
    }
    if b.base & (b.word_bytes - 1) != 0 {
        return Err(err(format!(
            "block: base {:#x} is not word-aligned",
            b.base
        )));
    }
    let mut offsets = BTreeMap::new();
    let mut fields = Vec::new();
    for r in &desc.register {
        let what = format!("register {}", r.name);
        check_ident(&r.name).map_err(|e| err(format!("{what}: {e}")))?;
        claim(format!("Reg{}", r.name), &what)?;
        if let Some(other) = offsets.insert(r.offset, &r.name) {
            return Err(err(format!(
                "{what}: offset {} already taken by register {other}",
                r.offset
            )));
        }
        let liked;
        let field_descs = match &r.like {
            None => &r.field,
            Some(_) if !r.field.is_empty() => {
                return Err(err(format!("{what}: like and field both given")))
            }
            Some(l) => {
                liked = likes(l).map_err(|e| err(format!("{what}: {e}")))?;
                &liked
            }
        };
        let fs = place_fields(field_descs, &values, b.data_w)
            .map_err(|e| err(format!("{what}: {e}")))?;
        if let Some(reset) = r.reset {
            if b.data_w < 64 && reset >> b.data_w != 0 {
                return Err(err(format!(
                    "{what}: reset {reset:#x} wider than {} bits",
                    b.data_w
                )));
            }
        }
        fields.push(fs);
    }

    check_axil(&desc).map_err(|e| err(format!("block: {e}")))?;

    for d in &b.docs {
        for s in &d.show {
            let known = match s.strip_prefix("enum:") {
                Some(name) => desc.enums.iter().any(|e| e.name == name),
                None => matches!(s.as_str(), "constants" | "enums" | "registers"),
            };
            if !known {
                return Err(err(format!("block: docs {}: unknown section {s}", d.path)));
            }
        }
    }

    let file_name = rel
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Checked {
        desc,
        rel: rel.to_path_buf(),
        file_name,
        values,
        exprs,
        fields,
    })
}

/// An `axil` block: 32-bit words, offsets below [`AXIL_MAX_WORDS`], an interrupt whose status is
/// W1C and whose enable is RW. `irq` without `axil` is refused.
fn check_axil(d: &Desc) -> Result<(), String> {
    let b = &d.block;
    if !b.axil {
        return match b.irq {
            Some(_) => Err("irq needs axil = true".into()),
            None => Ok(()),
        };
    }
    if b.data_w != 32 || b.word_bytes != 4 {
        return Err(format!(
            "axil needs data_w = 32 and word_bytes = 4 (has {} and {})",
            b.data_w, b.word_bytes
        ));
    }
    if let Some(r) = d.register.iter().find(|r| r.offset >= AXIL_MAX_WORDS) {
        return Err(format!(
            "axil: register {} at offset {} (at most {})",
            r.name,
            r.offset,
            AXIL_MAX_WORDS - 1
        ));
    }
    if let Some(irq) = &b.irq {
        for (name, want) in [(&irq.status, Access::W1C), (&irq.enable, Access::RW)] {
            match d.register.iter().find(|r| &r.name == name) {
                Some(r) if r.access == want => {}
                Some(r) => {
                    return Err(format!(
                        "irq: register {name} is {}, not {}",
                        r.access.as_str(),
                        want.as_str()
                    ))
                }
                None => return Err(format!("irq: no register {name}")),
            }
        }
    }
    Ok(())
}

/// The bits of a register that hold state: its numeric fields, or every bit when a field's place
/// depends on parameters or there are no fields.
pub fn stored_mask(fs: &[Field], data_w: u32) -> u64 {
    let all = if data_w >= 64 {
        u64::MAX
    } else {
        (1u64 << data_w) - 1
    };
    if fs.is_empty() {
        return all;
    }
    let mut m = 0u64;
    for f in fs {
        match (&f.lsb, &f.width) {
            (Resolved::Num(l), Resolved::Num(w)) => {
                m |= (u64::MAX >> (64 - w)) << l;
            }
            _ => return all,
        }
    }
    m
}

/// Resolve lsb and width of each field; refuse overlaps and fields above `data_w`.
fn place_fields(
    field: &[FieldDesc],
    values: &BTreeMap<String, u64>,
    data_w: u32,
) -> Result<Vec<Field>, String> {
    let resolve = |v: &Value| -> Result<Resolved, String> {
        match v {
            Value::Int(n) => Ok(Resolved::Num(*n)),
            Value::Expr(s) => {
                let e = Expr::parse(s)?;
                Ok(match e.eval(values) {
                    Ok(n) => Resolved::Num(n),
                    Err(_) => Resolved::Sym(s.trim().to_string()),
                })
            }
        }
    };
    let mut out: Vec<Field> = Vec::new();
    let mut names = BTreeSet::new();
    let mut next = Resolved::Num(0);
    for f in field {
        if !names.insert(f.name.as_str()) {
            return Err(format!("field {} defined twice", f.name));
        }
        let width = resolve(&f.width)?;
        if width == Resolved::Num(0) {
            return Err(format!("field {} has width 0", f.name));
        }
        let lsb = match &f.lsb {
            Some(v) => resolve(v)?,
            None => next.clone(),
        };
        next = match (&lsb, &width) {
            (Resolved::Num(l), Resolved::Num(w)) => Resolved::Num(l + w),
            _ => Resolved::Sym(format!("{} + {}", paren(&lsb), paren(&width))),
        };
        if let (Resolved::Num(l), Resolved::Num(w)) = (&lsb, &width) {
            if l + w > u64::from(data_w) {
                return Err(format!(
                    "field {} (bits {}..={}) above the {data_w}-bit register",
                    f.name,
                    l,
                    l + w - 1
                ));
            }
            for o in &out {
                if let (Resolved::Num(ol), Resolved::Num(ow)) = (&o.lsb, &o.width) {
                    if *l < ol + ow && *ol < l + w {
                        return Err(format!("fields {} and {} overlap", o.name, f.name));
                    }
                }
            }
        }
        out.push(Field {
            name: f.name.clone(),
            lsb,
            width,
            doc: f.doc.clone(),
        });
    }
    Ok(out)
}

fn paren(r: &Resolved) -> String {
    match r {
        Resolved::Num(n) => n.to_string(),
        Resolved::Sym(s) if s.contains(' ') => format!("({s})"),
        Resolved::Sym(s) => s.clone(),
    }
}

/// Subsets named by `subset_of` repeat the other block's names and values.
pub fn check_subsets(blocks: &[Checked]) -> Result<(), String> {
    for b in blocks {
        for en in &b.desc.enums {
            let Some(of) = &en.subset_of else { continue };
            let what = format!("{}: enum {}", b.rel.display(), en.name);
            let (blk, name) = of
                .split_once('.')
                .ok_or_else(|| format!("{what}: subset_of {of} is not <block>.<Enum>"))?;
            let other = blocks
                .iter()
                .find(|o| o.desc.block.name == blk)
                .and_then(|o| o.desc.enums.iter().find(|e| e.name == name))
                .ok_or_else(|| format!("{what}: subset_of {of}: no such enum"))?;
            for v in &en.value {
                match other.value.iter().find(|o| o.name == v.name) {
                    Some(o) if o.value == v.value && other.width == en.width => {}
                    _ => {
                        return Err(format!(
                            "{what}: {} = {} ({} bits) is not in {of}",
                            v.name, v.value, en.width
                        ))
                    }
                }
            }
        }
    }
    Ok(())
}

fn check_ident(s: &str) -> Result<(), String> {
    let ok = s.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(format!("{s:?} is not an identifier"))
    }
}

/// `axis_k` / `AxisK` -> words `[axis, k]`; digits stay with their word (`tf2d`).
fn words(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut prev_lower = false;
    for c in s.chars() {
        if c == '_' {
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
            prev_lower = false;
            continue;
        }
        if c.is_ascii_uppercase() && prev_lower && !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
        prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        cur.push(c);
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// `ComposLatency` -> `COMPOS_LATENCY`, `axis_k` -> `AXIS_K`.
pub fn screaming(s: &str) -> String {
    words(s)
        .iter()
        .map(|w| w.to_ascii_uppercase())
        .collect::<Vec<_>>()
        .join("_")
}

/// `axis_k` -> `AxisK`, `LutBypass` -> `LutBypass`.
pub fn camel(s: &str) -> String {
    words(s)
        .iter()
        .map(|w| {
            let mut c = w.chars();
            match c.next() {
                Some(f) => f.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// A constant expression: integers, names of earlier constants, `+ - *`, parentheses.
#[derive(Debug, Clone)]
pub enum Expr {
    Num(u64),
    Name(String),
    Bin(char, Box<Expr>, Box<Expr>),
    Paren(Box<Expr>),
}

impl Expr {
    pub fn parse(s: &str) -> Result<Expr, String> {
        let toks = tokens(s)?;
        let mut pos = 0;
        let e = parse_sum(&toks, &mut pos).map_err(|e| format!("{s:?}: {e}"))?;
        if pos != toks.len() {
            return Err(format!("{s:?}: unexpected {:?}", toks[pos]));
        }
        Ok(e)
    }

    pub fn eval(&self, values: &BTreeMap<String, u64>) -> Result<u64, String> {
        match self {
            Expr::Num(n) => Ok(*n),
            Expr::Name(n) => values
                .get(n)
                .copied()
                .ok_or_else(|| format!("{n} is not an earlier constant")),
            Expr::Paren(e) => e.eval(values),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval(values)?, b.eval(values)?);
                let r = match op {
                    '+' => a.checked_add(b),
                    '-' => a.checked_sub(b),
                    _ => a.checked_mul(b),
                };
                r.ok_or_else(|| format!("{a} {op} {b} overflows"))
            }
        }
    }

    /// The names it uses.
    pub fn names(&self, out: &mut Vec<String>) {
        match self {
            Expr::Num(_) => {}
            Expr::Name(n) => out.push(n.clone()),
            Expr::Paren(e) => e.names(out),
            Expr::Bin(_, a, b) => {
                a.names(out);
                b.names(out);
            }
        }
    }

    /// The text with each name mapped by `name`.
    pub fn render(&self, name: &dyn Fn(&str) -> String) -> String {
        match self {
            Expr::Num(n) => n.to_string(),
            Expr::Name(n) => name(n),
            Expr::Paren(e) => format!("({})", e.render(name)),
            Expr::Bin(op, a, b) => format!("{} {op} {}", a.render(name), b.render(name)),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Num(u64),
    Name(String),
    Op(char),
}

fn tokens(s: &str) -> Result<Vec<Tok>, String> {
    let mut out = Vec::new();
    let cs: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        let c = cs[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() {
            let st = i;
            while i < cs.len() && cs[i].is_ascii_digit() {
                i += 1;
            }
            let t: String = cs[st..i].iter().collect();
            out.push(Tok::Num(
                t.parse().map_err(|_| format!("{s:?}: bad number {t}"))?,
            ));
        } else if c.is_ascii_alphabetic() || c == '_' {
            let st = i;
            while i < cs.len() && (cs[i].is_ascii_alphanumeric() || cs[i] == '_') {
                i += 1;
            }
            out.push(Tok::Name(cs[st..i].iter().collect()));
        } else if "+-*()".contains(c) {
            out.push(Tok::Op(c));
            i += 1;
        } else {
            return Err(format!("{s:?}: unexpected {c:?}"));
        }
    }
    Ok(out)
}

fn parse_sum(t: &[Tok], pos: &mut usize) -> Result<Expr, String> {
    let mut e = parse_prod(t, pos)?;
    while let Some(Tok::Op(op @ ('+' | '-'))) = t.get(*pos) {
        *pos += 1;
        e = Expr::Bin(*op, Box::new(e), Box::new(parse_prod(t, pos)?));
    }
    Ok(e)
}

fn parse_prod(t: &[Tok], pos: &mut usize) -> Result<Expr, String> {
    let mut e = parse_atom(t, pos)?;
    while let Some(Tok::Op('*')) = t.get(*pos) {
        *pos += 1;
        e = Expr::Bin('*', Box::new(e), Box::new(parse_atom(t, pos)?));
    }
    Ok(e)
}

fn parse_atom(t: &[Tok], pos: &mut usize) -> Result<Expr, String> {
    let tok = t.get(*pos).cloned();
    *pos += 1;
    match tok {
        Some(Tok::Num(n)) => Ok(Expr::Num(n)),
        Some(Tok::Name(n)) => Ok(Expr::Name(n)),
        Some(Tok::Op('(')) => {
            let e = parse_sum(t, pos)?;
            if t.get(*pos) != Some(&Tok::Op(')')) {
                return Err("missing )".into());
            }
            *pos += 1;
            Ok(Expr::Paren(Box::new(e)))
        }
        Some(other) => Err(format!("unexpected {other:?}")),
        None => Err("unexpected end".into()),
    }
}
