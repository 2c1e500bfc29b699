//! The three readings of a checked description: SV localparams, a Rust module, Markdown tables.

use super::desc::{camel, screaming, stored_mask, Access, Checked, Expr, Field, Resolved};
use std::fmt::Write;

/// Lines are wrapped at this column (STYLE.md, rustfmt's default).
const COLUMNS: usize = 100;

/// `text` as comment lines `prefix ...`, wrapped at [`COLUMNS`].
fn wrap(out: &mut String, prefix: &str, text: &str) {
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && prefix.len() + line.len() + 1 + word.len() > COLUMNS {
            let _ = writeln!(out, "{prefix}{line}");
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        let _ = writeln!(out, "{prefix}{line}");
    }
}

/// A field in words: `nx (m + 1)` or `axis_k [1:0]`.
fn field_text(f: &Field) -> String {
    match (&f.lsb, &f.width) {
        (Resolved::Num(l), Resolved::Num(1)) => format!("{} [{l}]", f.name),
        (Resolved::Num(l), Resolved::Num(w)) => format!("{} [{}:{l}]", f.name, l + w - 1),
        (_, w) => format!("{} ({})", f.name, w.text()),
    }
}

fn fields_numeric(fs: &[Field]) -> impl Iterator<Item = (&Field, u64, u64)> {
    fs.iter().filter_map(|f| match (&f.lsb, &f.width) {
        (Resolved::Num(l), Resolved::Num(w)) => Some((f, *l, *w)),
        _ => None,
    })
}

/// The SV text between the markers of the block's package, indented by `indent`.
pub fn sv(b: &Checked, indent: &str) -> String {
    let d = &b.desc;
    let mut out = String::new();
    let doc = format!("{indent}/// ");
    for c in &d.constant {
        wrap(&mut out, &doc, &c.doc);
        let value = b.exprs[&c.name].render(&|n: &str| n.to_string());
        let _ = writeln!(out, "{indent}localparam int unsigned {} = {value};", c.name);
        out.push('\n');
    }
    for en in &d.enums {
        wrap(&mut out, &doc, &en.doc);
        if let Some(w) = &en.width_param {
            let _ = writeln!(out, "{indent}localparam int unsigned {w} = {};", en.width);
        }
        let pad = en.value.iter().map(|v| v.name.len()).max().unwrap_or(0);
        let decls: Vec<(String, &str)> = en
            .value
            .iter()
            .map(|v| {
                let decl = format!(
                    "{indent}localparam logic [{}:0] {}{:<pad$} = {}'d{};",
                    en.width - 1,
                    en.name,
                    v.name,
                    en.width,
                    v.value
                );
                (decl, v.doc.as_str())
            })
            .collect();
        // Trailing comments when every one fits, else each above its line.
        let trailing = decls
            .iter()
            .all(|(d, c)| c.is_empty() || d.len() + 4 + c.len() <= COLUMNS);
        for (decl, comment) in decls {
            if trailing || comment.is_empty() {
                push_trailing(&mut out, decl, comment);
            } else {
                wrap(&mut out, &format!("{indent}// "), comment);
                let _ = writeln!(out, "{decl}");
            }
        }
        out.push('\n');
    }
    if !d.register.is_empty() {
        let base = d.block.base_doc.as_deref().unwrap_or("byte address / 4 =");
        wrap(
            &mut out,
            &doc,
            &format!("Registers by word offset ({base} the offset), access, fields LSB first."),
        );
        let pad = d.register.iter().map(|r| r.name.len()).max().unwrap_or(0);
        for (r, fs) in d.register.iter().zip(&b.fields) {
            let decl = format!(
                "{indent}localparam int unsigned Reg{:<pad$} = {};",
                r.name, r.offset
            );
            let fields: Vec<String> = fs.iter().map(field_text).collect();
            let comment = if fields.is_empty() {
                r.access.as_str().to_string()
            } else {
                format!("{}: {}", r.access.as_str(), fields.join(", "))
            };
            push_trailing(&mut out, decl, &comment);
        }
        let resets: Vec<_> = d.register.iter().filter(|r| r.reset.is_some()).collect();
        if !resets.is_empty() {
            out.push('\n');
            let _ = writeln!(out, "{indent}/// Reset values.");
            for r in resets {
                let w = d.block.data_w;
                let _ = writeln!(
                    out,
                    "{indent}localparam logic [{}:0] Reg{}Reset = {w}'h{:x};",
                    w - 1,
                    r.name,
                    r.reset.unwrap_or(0)
                );
            }
        }
        let numeric: Vec<(String, u64, u64)> = d
            .register
            .iter()
            .zip(&b.fields)
            .flat_map(|(r, fs)| {
                fields_numeric(fs)
                    .map(|(f, l, w)| (format!("Reg{}{}", r.name, camel(&f.name)), l, w))
                    .collect::<Vec<_>>()
            })
            .collect();
        if !numeric.is_empty() {
            out.push('\n');
            let _ = writeln!(
                out,
                "{indent}/// Fields whose place does not depend on parameters: lowest bit, width."
            );
            let pad = numeric.iter().map(|(n, _, _)| n.len()).max().unwrap_or(0) + 3;
            for (n, l, w) in numeric {
                let _ = writeln!(
                    out,
                    "{indent}localparam int unsigned {:<pad$} = {l};",
                    format!("{n}Lsb")
                );
                let _ = writeln!(
                    out,
                    "{indent}localparam int unsigned {:<pad$} = {w};",
                    format!("{n}W")
                );
            }
        }
    }
    if d.block.axil {
        out.push('\n');
        sv_axil(&mut out, b, indent);
    }
    while out.ends_with("\n\n") {
        out.pop();
    }
    out
}

/// One word offset of an `axil` block: `(access, stored mask, reset)`, `None` where no register is.
type Slot = Option<(Access, u64, Option<u64>)>;

/// Every word offset of an `axil` block.
fn axil_slots(b: &Checked) -> Vec<Slot> {
    let d = &b.desc;
    let words = d.register.iter().map(|r| r.offset + 1).max().unwrap_or(0);
    let mut slots = vec![None; words as usize];
    for (r, fs) in d.register.iter().zip(&b.fields) {
        slots[r.offset as usize] = Some((r.access, stored_mask(fs, d.block.data_w), r.reset));
    }
    slots
}

/// The offset of register `name` (checked to exist by `desc::check_axil`).
fn offset_of(b: &Checked, name: &str) -> u64 {
    b.desc
        .register
        .iter()
        .find(|r| r.name == name)
        .map_or(0, |r| r.offset)
}

/// The tables `cube5_axil_regs` takes as parameters.
fn sv_axil(out: &mut String, b: &Checked, indent: &str) {
    let slots = axil_slots(b);
    let n = slots.len();
    wrap(
        out,
        &format!("{indent}/// "),
        "Tables of the AXI4-Lite register block (rtl/cube5/cube5_axil_regs.sv, docs/accel-regs.md): \
         one entry per word offset 0 .. AxilWords - 1, bit `[i]` or word `[i*32 +: 32]` for \
         offset `i`, the highest offset first.",
    );
    let _ = writeln!(out, "{indent}localparam int unsigned AxilWords = {n};");
    let bits = |f: &dyn Fn(Access) -> bool| -> String {
        slots
            .iter()
            .rev()
            .map(|s| match s {
                Some((a, _, _)) if f(*a) => '1',
                _ => '0',
            })
            .collect()
    };
    let tables: [(&str, String, &str); 5] = [
        ("AxilMapped", bits(&|_| true), "a register is at the offset"),
        (
            "AxilStored",
            bits(&|a| a != Access::RO),
            "the block keeps its value (RW, WO, W1C)",
        ),
        (
            "AxilReadable",
            bits(&|a| a != Access::WO),
            "a read answers OKAY (RW, RO, W1C)",
        ),
        (
            "AxilRo",
            bits(&|a| a == Access::RO),
            "a read returns `ro_i` (RO)",
        ),
        (
            "AxilW1c",
            bits(&|a| a == Access::W1C),
            "writing 1 clears a bit, `w1c_set_i` sets it (W1C)",
        ),
    ];
    for (name, v, doc) in tables {
        let _ = writeln!(out, "{indent}// {doc}");
        let _ = writeln!(
            out,
            "{indent}localparam logic [{}:0] {name} = {n}'b{v};",
            n - 1
        );
    }
    let has_reset: String = slots
        .iter()
        .rev()
        .map(|s| match s {
            Some((_, _, Some(_))) => '1',
            _ => '0',
        })
        .collect();
    let _ = writeln!(
        out,
        "{indent}// reset sets the register to its AxilReset word"
    );
    let _ = writeln!(
        out,
        "{indent}localparam logic [{}:0] AxilHasReset = {n}'b{has_reset};",
        n - 1
    );
    let words = |f: &dyn Fn(&Slot) -> u64| -> String {
        let w: Vec<String> = slots
            .iter()
            .rev()
            .map(|s| format!("32'h{:08x}", f(s)))
            .collect();
        w.join(", ")
    };
    for (name, doc, v) in [
        (
            "AxilMask",
            "the bits a register keeps (its fields; all where a field's place depends on parameters)",
            words(&|s| s.map_or(0, |(_, m, _)| m)),
        ),
        (
            "AxilReset",
            "reset values",
            words(&|s| s.and_then(|(_, _, r)| r).unwrap_or(0)),
        ),
    ] {
        let _ = writeln!(out, "{indent}// {doc}");
        let _ = writeln!(out, "{indent}localparam logic [{}:0] {name} = {{", n * 32 - 1);
        let mut line = String::new();
        for (i, w) in v.split(", ").enumerate() {
            let sep = if i + 1 == n { "" } else { "," };
            if !line.is_empty() && indent.len() + 4 + line.len() + w.len() + 2 > COLUMNS {
                let _ = writeln!(out, "{indent}    {}", line.trim_end());
                line.clear();
            }
            let _ = write!(line, "{w}{sep} ");
        }
        let _ = writeln!(out, "{indent}    {}", line.trim_end());
        let _ = writeln!(out, "{indent}}};");
    }
    let (has, st, en) = match &b.desc.block.irq {
        Some(irq) => (1, offset_of(b, &irq.status), offset_of(b, &irq.enable)),
        None => (0, 0, 0),
    };
    let _ = writeln!(
        out,
        "{indent}// irq_o = |(word AxilIrqStatus & word AxilIrqEnable) when AxilHasIrq"
    );
    let _ = writeln!(out, "{indent}localparam int unsigned AxilHasIrq = {has};");
    let _ = writeln!(out, "{indent}localparam int unsigned AxilIrqStatus = {st};");
    let _ = writeln!(out, "{indent}localparam int unsigned AxilIrqEnable = {en};");
}

/// `decl  // comment`, or the comment on the line above when that would pass [`COLUMNS`].
fn push_trailing(out: &mut String, decl: String, comment: &str) {
    if comment.is_empty() {
        let _ = writeln!(out, "{decl}");
    } else if decl.len() + 4 + comment.len() <= COLUMNS {
        let _ = writeln!(out, "{decl}  // {comment}");
    } else {
        let indent: String = decl.chars().take_while(|c| *c == ' ').collect();
        wrap(out, &format!("{indent}// "), comment);
        let _ = writeln!(out, "{decl}");
    }
}

/// The whole generated Rust module of a block.
pub fn rust(b: &Checked) -> String {
    let d = &b.desc;
    let mut out = String::new();
    wrap(
        &mut out,
        "//! ",
        &format!(
            "Generated by `cube5-gen regs` from `{}`: do not edit; change the description and \
             run `make regs`.",
            b.rel.display()
        ),
    );
    out.push_str("//!\n");
    wrap(&mut out, "//! ", &d.block.doc);

    let has_fields = b
        .fields
        .iter()
        .any(|fs| fields_numeric(fs).next().is_some());
    let mut uses = Vec::new();
    if !d.register.is_empty() {
        uses.push("Access");
    }
    if has_fields {
        uses.push("Field");
    }
    if !d.register.is_empty() {
        uses.push("Register");
    }
    match uses.len() {
        0 => {}
        1 => {
            let _ = write!(out, "\nuse super::{};\n", uses[0]);
        }
        _ => {
            let _ = write!(out, "\nuse super::{{{}}};\n", uses.join(", "));
        }
    }

    for c in &d.constant {
        out.push('\n');
        wrap(&mut out, "/// ", &c.doc);
        let e = &b.exprs[&c.name];
        let mut names = Vec::new();
        e.names(&mut names);
        let same_type = names.iter().all(|n| {
            d.constant
                .iter()
                .any(|o| &o.name == n && o.rust_type == c.rust_type)
        });
        let value = if same_type {
            e.render(&|n: &str| screaming(n))
        } else {
            b.values[&c.name].to_string()
        };
        let _ = writeln!(
            out,
            "pub const {}: {} = {value};",
            screaming(&c.name),
            c.rust_type
        );
    }

    for en in &d.enums {
        out.push('\n');
        wrap(&mut out, "// ", &en.doc);
        if let Some(w) = &en.width_param {
            let _ = writeln!(out, "pub const {}: u32 = {};", screaming(w), en.width);
        }
        for v in &en.value {
            if !v.doc.is_empty() {
                wrap(&mut out, "/// ", &v.doc);
            }
            let _ = writeln!(
                out,
                "pub const {}_{}: u32 = {};",
                en.rust_prefix,
                screaming(&v.name),
                v.value
            );
        }
    }

    if !d.register.is_empty() {
        out.push('\n');
        let base = d.block.base_doc.as_deref().unwrap_or("byte address / 4 =");
        wrap(
            &mut out,
            "// ",
            &format!("Registers by word offset ({base} the offset)."),
        );
        for (r, fs) in d.register.iter().zip(&b.fields) {
            let fields: Vec<String> = fs.iter().map(field_text).collect();
            wrap(
                &mut out,
                "/// ",
                &format!(
                    "`{}` ({}): {}. Fields: {}.",
                    r.name,
                    r.access.as_str(),
                    r.doc,
                    fields.join(", ")
                ),
            );
            let _ = writeln!(
                out,
                "pub const REG_{}: u32 = {};",
                screaming(&r.name),
                r.offset
            );
            for (f, l, w) in fields_numeric(fs) {
                let text = if f.doc.is_empty() {
                    format!("Field `{}` of `{}`.", f.name, r.name)
                } else {
                    format!("Field `{}` of `{}`: {}.", f.name, r.name, f.doc)
                };
                wrap(&mut out, "/// ", &text);
                let name = format!("REG_{}_{}", screaming(&r.name), screaming(&f.name));
                let line = format!("pub const {name}: Field = Field::new({l}, {w});");
                if line.len() <= COLUMNS {
                    let _ = writeln!(out, "{line}");
                } else {
                    let _ = writeln!(out, "pub const {name}: Field =\n    Field::new({l}, {w});");
                }
            }
        }
        out.push('\n');
        out.push_str("/// Every register, by offset.\n");
        let _ = writeln!(
            out,
            "pub const REGISTERS: [Register; {}] = [",
            d.register.len()
        );
        let mut regs: Vec<_> = d.register.iter().collect();
        regs.sort_by_key(|r| r.offset);
        for r in regs {
            let reset = match r.reset {
                Some(v) => format!("Some({v:#x})"),
                None => "None".into(),
            };
            let _ = writeln!(
                out,
                "    Register::new(\"{}\", {}, Access::{}, {reset}),",
                r.name,
                r.offset,
                r.access.rust()
            );
        }
        out.push_str("];\n");
    }
    if d.block.axil {
        rust_axil(&mut out, b);
    }
    out
}

/// The `axil` block's masks and interrupt, for the host driver and the register file model.
fn rust_axil(out: &mut String, b: &Checked) {
    let slots = axil_slots(b);
    out.push('\n');
    wrap(
        out,
        "/// ",
        "The bits each word offset keeps (AXI4-Lite register block, docs/accel-regs.md): its \
         fields, every bit where a field's place depends on parameters, 0 where no register is.",
    );
    let _ = writeln!(out, "pub const AXIL_MASK: [u32; {}] = [", slots.len());
    // Eight to a line, as rustfmt lays them out.
    let masks: Vec<String> = slots
        .iter()
        .map(|s| format!("{:#010x}", s.map_or(0, |(_, m, _)| m)))
        .collect();
    for row in masks.chunks(8) {
        let _ = writeln!(out, "    {},", row.join(", "));
    }
    out.push_str("];\n");
    out.push('\n');
    out.push_str(
        "/// The interrupt: `irq_o` is high while (status & enable) != 0, as (status, enable) \
         offsets.\n",
    );
    let v = match &b.desc.block.irq {
        Some(irq) => format!(
            "Some(({}, {}))",
            offset_of(b, &irq.status),
            offset_of(b, &irq.enable)
        ),
        None => "None".into(),
    };
    let _ = writeln!(out, "pub const AXIL_IRQ: Option<(u32, u32)> = {v};");
}

/// `model/src/regs/mod.rs`: the blocks' modules and the types they share.
pub fn rust_mod(modules: &[String]) -> String {
    let mut out = String::from(RUST_MOD_HEAD);
    for m in modules {
        let _ = writeln!(out, "pub mod {m};");
    }
    out.push_str(RUST_MOD_TAIL);
    out
}

const RUST_MOD_HEAD: &str = "\
//! Register maps and shared constants of the RTL blocks, generated by `cube5-gen regs` from
//! `rtl/**/<block>.regs.toml`: do not edit; change the descriptions and run `make regs`
//! (docs/adding-a-unit.md, \"Registers and shared constants\").

";

const RUST_MOD_TAIL: &str = "
/// The types every map uses (hand-written in `model/src/regmap.rs`).
pub use crate::regmap::{Access, Field, Register};
";

/// The Markdown text of one docs section (`constants`, `enums`, `enum:<Name>`, `registers`).
pub fn md(b: &Checked, section: &str) -> String {
    let d = &b.desc;
    let mut out = String::new();
    match section {
        "constants" => {
            out.push_str("| constant | Rust | value | meaning |\n");
            out.push_str("|----------|------|------:|---------|\n");
            for c in &d.constant {
                let e = &b.exprs[&c.name];
                let value = match e {
                    Expr::Num(n) => n.to_string(),
                    _ => format!(
                        "`{}` = {}",
                        e.render(&|n: &str| n.to_string()),
                        b.values[&c.name]
                    ),
                };
                let _ = writeln!(
                    out,
                    "| `{}` | `{}` | {value} | {} |",
                    c.name,
                    screaming(&c.name),
                    c.doc
                );
            }
        }
        "enums" => {
            out.push_str("| encoding | bits | value | SV | Rust | meaning |\n");
            out.push_str("|----------|-----:|------:|----|------|---------|\n");
            for en in &d.enums {
                for v in &en.value {
                    let _ = writeln!(
                        out,
                        "| {} | {} | {} | `{}{}` | `{}_{}` | {} |",
                        en.name,
                        en.width,
                        v.value,
                        en.name,
                        v.name,
                        en.rust_prefix,
                        screaming(&v.name),
                        v.doc
                    );
                }
            }
        }
        "registers" => {
            let base = d.block.base_doc.as_deref().unwrap_or("");
            out.push_str(
                "| offset | byte | register | access | reset | fields (LSB first) | meaning |\n",
            );
            out.push_str(
                "|-------:|-----:|----------|--------|------:|--------------------|---------|\n",
            );
            for (r, fs) in d.register.iter().zip(&b.fields) {
                let offset = if base.is_empty() {
                    r.offset.to_string()
                } else {
                    format!("{base} {}", r.offset)
                };
                let byte = d.block.base + r.offset * d.block.word_bytes;
                let reset = match r.reset {
                    Some(v) => format!("`{v:#x}`"),
                    None => "kept".into(),
                };
                let fields: Vec<String> = fs
                    .iter()
                    .map(|f| {
                        let t = field_text(f);
                        match t.split_once(' ') {
                            Some((n, rest)) => {
                                format!("`{n}` {}", rest.replace('(', "(`").replace(')', "`)"))
                            }
                            None => format!("`{t}`"),
                        }
                    })
                    .collect();
                let mut meaning = r.doc.clone();
                for f in fs.iter().filter(|f| !f.doc.is_empty()) {
                    let _ = write!(meaning, "; `{}`: {}", f.name, f.doc);
                }
                let _ = writeln!(
                    out,
                    "| {offset} | `{byte:#05x}` | `{}` | {} | {reset} | {} | {meaning} |",
                    r.name,
                    r.access.as_str(),
                    fields.join(", ")
                );
            }
        }
        _ => {
            let name = section.trim_start_matches("enum:");
            if let Some(en) = d.enums.iter().find(|e| e.name == name) {
                let _ = writeln!(
                    out,
                    "| {} | name | meaning |",
                    screaming(&en.name).to_lowercase()
                );
                out.push_str("|-----:|------|---------|\n");
                for v in &en.value {
                    let _ = writeln!(out, "| {} | `{}` | {} |", v.value, v.name, v.doc);
                }
            }
        }
    }
    out.pop();
    out
}
