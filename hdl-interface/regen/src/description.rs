//! The register-map description: parsed from TOML, then checked and resolved into a model the
//! emitters can print without further decisions.
//!
//! Everything an emitter needs (masks per access type, resolved ranges, fields copied from a
//! port layout) is computed here once, so the four outputs cannot disagree.

use std::collections::{BTreeMap, BTreeSet};

use serde::Deserialize;

use crate::emit::rust_api;
use crate::error::RegenError;

/// Access type of a register field, as seen from the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Access {
    Ro,
    Rw,
    W1c,
    Wo,
}

impl Access {
    pub fn as_str(self) -> &'static str {
        match self {
            Access::Ro => "ro",
            Access::Rw => "rw",
            Access::W1c => "w1c",
            Access::Wo => "wo",
        }
    }
}

/// Direction of a stream-port signal, seen from the fabric.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    In,
    Out,
}

impl Direction {
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::In => "in",
            Direction::Out => "out",
        }
    }
}

/// A range bound: a literal or the name of a `[params]` entry.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
enum RawBound {
    Value(u32),
    Param(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDescription {
    block: RawBlock,
    #[serde(default)]
    params: BTreeMap<String, u32>,
    #[serde(rename = "register")]
    registers: Vec<RawRegister>,
    #[serde(rename = "port", default)]
    ports: Vec<RawPort>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBlock {
    name: String,
    doc: String,
    base_address: u32,
    window_size: u32,
    register_width: u32,
    version_major: u32,
    version_minor: u32,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRegister {
    name: String,
    offset: u32,
    access: Access,
    reset: u32,
    doc: String,
    #[serde(default)]
    pops_on_read: bool,
    fields_from_port: Option<String>,
    #[serde(rename = "field", default)]
    fields: Vec<RawField>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawField {
    name: String,
    bits: [u32; 2],
    access: Option<Access>,
    reset: u32,
    doc: String,
    range: Option<[RawBound; 2]>,
    #[serde(rename = "enum", default)]
    enums: Vec<RawEnumValue>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEnumValue {
    name: String,
    value: u32,
    doc: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPort {
    name: String,
    direction: Direction,
    doc: String,
    #[serde(rename = "signal")]
    signals: Vec<RawSignal>,
    #[serde(rename = "field", default)]
    fields: Vec<RawPortField>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSignal {
    name: String,
    width: u32,
    direction: Direction,
    doc: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPortField {
    name: String,
    bits: [u32; 2],
    doc: String,
}

/// The checked description.
#[derive(Debug)]
pub struct Description {
    pub block: Block,
    /// `[params]`, sorted by name.
    pub params: Vec<(String, u32)>,
    /// Sorted by offset.
    pub registers: Vec<Register>,
    pub ports: Vec<Port>,
}

#[derive(Debug)]
pub struct Block {
    pub name: String,
    pub doc: String,
    pub base_address: u32,
    pub window_size: u32,
    pub register_width: u32,
    pub version_major: u32,
    pub version_minor: u32,
}

#[derive(Debug)]
pub struct Register {
    pub name: String,
    pub offset: u32,
    pub access: Access,
    pub reset: u32,
    pub doc: String,
    pub pops_on_read: bool,
    /// Sorted by least significant bit.
    pub fields: Vec<Field>,
}

impl Register {
    /// Union of the masks of the fields with the given access.
    pub fn mask_of(&self, access: Access) -> u32 {
        self.fields
            .iter()
            .filter(|f| f.access == access)
            .fold(0, |m, f| m | f.mask())
    }
}

#[derive(Debug)]
pub struct Field {
    pub name: String,
    pub msb: u32,
    pub lsb: u32,
    pub access: Access,
    pub reset: u32,
    pub doc: String,
    /// Valid values, inclusive; the whole field when the description gives no range.
    pub min: u32,
    pub max: u32,
    /// True when the description gave a range.
    pub has_range: bool,
    pub enums: Vec<EnumValue>,
}

impl Field {
    pub fn width(&self) -> u32 {
        self.msb - self.lsb + 1
    }

    /// Largest value the field's bits hold.
    pub fn max_value(&self) -> u32 {
        bits_max(self.width())
    }

    /// The field's bits in its register.
    pub fn mask(&self) -> u32 {
        self.max_value() << self.lsb
    }
}

#[derive(Debug)]
pub struct EnumValue {
    pub name: String,
    pub value: u32,
    pub doc: String,
}

#[derive(Debug)]
pub struct Port {
    pub name: String,
    pub direction: Direction,
    pub doc: String,
    pub signals: Vec<Signal>,
    /// Layout of the DATA signal, sorted by least significant bit.
    pub fields: Vec<PortField>,
}

#[derive(Debug)]
pub struct Signal {
    pub name: String,
    pub width: u32,
    pub direction: Direction,
    pub doc: String,
}

#[derive(Debug)]
pub struct PortField {
    pub name: String,
    pub msb: u32,
    pub lsb: u32,
    pub doc: String,
}

impl PortField {
    pub fn width(&self) -> u32 {
        self.msb - self.lsb + 1
    }

    pub fn mask(&self) -> u32 {
        bits_max(self.width()) << self.lsb
    }
}

fn bits_max(width: u32) -> u32 {
    if width >= 32 {
        u32::MAX
    } else {
        (1u32 << width) - 1
    }
}

/// Parses and checks a description.
pub fn parse(source: &str) -> Result<Description, RegenError> {
    let raw: RawDescription =
        toml::from_str(source).map_err(|e| RegenError::Parse(e.to_string()))?;
    resolve(raw)
}

fn invalid(at: impl Into<String>, what: impl Into<String>) -> RegenError {
    RegenError::Invalid {
        at: at.into(),
        what: what.into(),
    }
}

/// Names become identifiers in four languages: upper-case ASCII, digits and underscores,
/// starting with a letter.
fn check_name(at: &str, name: &str) -> Result<(), RegenError> {
    let mut chars = name.chars();
    let first_ok = chars.next().is_some_and(|c| c.is_ascii_uppercase());
    if first_ok
        && chars.all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
        && !name.ends_with('_')
    {
        Ok(())
    } else {
        Err(invalid(
            at,
            format!("name `{name}` must be UPPER_SNAKE_CASE ASCII starting with a letter"),
        ))
    }
}

fn check_bits(at: &str, bits: [u32; 2], word_width: u32) -> Result<(u32, u32), RegenError> {
    let [msb, lsb] = bits;
    if msb < lsb {
        return Err(invalid(
            at,
            format!("bits = [{msb}, {lsb}]: msb is below lsb"),
        ));
    }
    if msb >= word_width {
        return Err(invalid(
            at,
            format!("bits = [{msb}, {lsb}]: bit {msb} is outside the {word_width}-bit word"),
        ));
    }
    Ok((msb, lsb))
}

fn check_unique<'a>(
    at: &str,
    kind: &str,
    names: impl Iterator<Item = &'a str>,
) -> Result<(), RegenError> {
    let mut seen = BTreeSet::new();
    for name in names {
        if !seen.insert(name) {
            return Err(invalid(at, format!("{kind} `{name}` appears twice")));
        }
    }
    Ok(())
}

fn resolve(raw: RawDescription) -> Result<Description, RegenError> {
    let b = raw.block;
    if b.register_width != 32 {
        return Err(invalid("block", "register_width must be 32"));
    }
    if b.window_size == 0 || b.window_size > 0x1_0000 || !b.window_size.is_power_of_two() {
        return Err(invalid(
            "block",
            format!(
                "window_size {:#x} must be a power of two up to 0x10000 (offsets are u16)",
                b.window_size
            ),
        ));
    }
    if b.base_address % b.window_size != 0 {
        return Err(invalid(
            "block",
            "base_address must be aligned to window_size",
        ));
    }
    if b.version_major > 0xFF || b.version_minor > 0xFF {
        return Err(invalid(
            "block",
            "version_major and version_minor must fit in 8 bits",
        ));
    }
    let block = Block {
        name: b.name,
        doc: b.doc,
        base_address: b.base_address,
        window_size: b.window_size,
        register_width: b.register_width,
        version_major: b.version_major,
        version_minor: b.version_minor,
    };
    for name in raw.params.keys() {
        check_name(&format!("params.{name}"), &name.to_ascii_uppercase())?;
        if name.chars().any(|c| c.is_ascii_uppercase()) {
            return Err(invalid(
                format!("params.{name}"),
                "parameter names are lower_snake_case",
            ));
        }
    }

    let ports = resolve_ports(raw.ports)?;

    let mut registers = Vec::with_capacity(raw.registers.len());
    for r in raw.registers {
        registers.push(resolve_register(r, &block, &raw.params, &ports)?);
    }
    registers.sort_by_key(|r| r.offset);
    check_unique(
        "register",
        "register",
        registers.iter().map(|r| r.name.as_str()),
    )?;
    for pair in registers.windows(2) {
        if pair[0].offset == pair[1].offset {
            return Err(invalid(
                format!("register {}", pair[1].name),
                format!("offset {:#04x} is also {}'s", pair[1].offset, pair[0].name),
            ));
        }
    }
    check_version_register(&registers, &block)?;

    let d = Description {
        block,
        params: raw.params.into_iter().collect(),
        registers,
        ports,
    };
    check_generated_names(&d)?;
    Ok(d)
}

/// The emitters flatten names (`REGISTER_FIELD_MASK` in C and Verilog, `FIELD` next to
/// `OFFSET` in a Rust module), so distinct entries can meet in one identifier: register `A_B`
/// field `C` and register `A` field `B_C`, or a field called `OFFSET`. Every identifier each
/// emitter derives is listed here with the entry it comes from; a repeat is an error naming
/// both entries.
fn check_generated_names(d: &Description) -> Result<(), RegenError> {
    let mut flat: BTreeMap<String, String> = BTreeMap::new();
    let mut claim = |scope: &str, name: String, origin: String| -> Result<(), RegenError> {
        match flat.insert(format!("{scope}{name}"), origin.clone()) {
            Some(previous) if previous != origin => Err(invalid(
                origin,
                format!("generates the identifier `{name}`, which {previous} also generates"),
            )),
            _ => Ok(()),
        }
    };
    for name in [
        "BASE_ADDR",
        "BASE_ADDRESS",
        "WINDOW_SIZE",
        "OFFSET_BITS",
        "REGISTER_WIDTH",
        "VERSION_MAJOR",
        "VERSION_MINOR",
        "REGISTERS",
        "PORTS",
    ] {
        claim("", name.to_string(), "block".to_string())?;
    }
    for (name, _) in &d.params {
        claim("", name.to_ascii_uppercase(), format!("params.{name}"))?;
    }
    for r in &d.registers {
        let origin = format!("register {}", r.name);
        // The Rust module name, and the C/Verilog macros.
        claim("", r.name.clone(), origin.clone())?;
        for suffix in ["OFFSET", "RESET"] {
            claim("", format!("{}_{suffix}", r.name), origin.clone())?;
        }
        let module = format!("{}::", r.name);
        for name in ["OFFSET", "RESET", "REGISTER"] {
            claim(&module, name.to_string(), origin.clone())?;
        }
        for f in &r.fields {
            let origin = format!("register {} field {}", r.name, f.name);
            claim(&module, f.name.clone(), origin.clone())?;
            if !f.enums.is_empty() {
                claim(&module, format!("{}_RESET", f.name), origin.clone())?;
            }
            for suffix in [
                "SHIFT", "LSB", "MSB", "WIDTH", "MASK", "RESET", "MIN", "MAX",
            ] {
                claim(
                    "",
                    format!("{}_{}_{suffix}", r.name, f.name),
                    origin.clone(),
                )?;
            }
            for e in &f.enums {
                claim(
                    "",
                    format!("{}_{}_{}", r.name, f.name, e.name),
                    format!("{origin} enum {}", e.name),
                )?;
            }
        }
    }
    // The typed trait of `regs_api.rs`: its methods share the trait's namespace with the
    // `RegisterBus` methods it builds on; the words of `pops_on_read` registers are types next
    // to it, each with an accessor per field.
    let api = rust_api::TRAIT_NAME;
    claim("regs_api::", api.to_string(), "block".to_string())?;
    for name in ["read", "write", "read_field", "write_field"] {
        claim(
            &format!("{api}::"),
            name.to_string(),
            "RegisterBus".to_string(),
        )?;
    }
    for r in &d.registers {
        let origin = format!("register {}", r.name);
        check_rust_identifier(&origin, &r.name.to_ascii_lowercase())?;
        if let Some(pop) = rust_api::pop_method(r) {
            claim(&format!("{api}::"), pop, origin.clone())?;
        }
        if let Some((ty, accessors)) = rust_api::word_type(r) {
            claim("regs_api::", ty.clone(), origin.clone())?;
            for (f, accessor) in r.fields.iter().zip(accessors) {
                let forigin = format!("{origin} field {}", f.name);
                check_rust_identifier(&forigin, &accessor)?;
                claim(&format!("regs_api::{ty}::"), accessor, forigin)?;
            }
        }
        for f in &r.fields {
            let forigin = format!("{origin} field {}", f.name);
            for (_, name) in rust_api::field_methods(r, f) {
                claim(&format!("{api}::"), name, forigin.clone())?;
            }
        }
    }
    // The ports and internal names of the Verilog register block.
    for (name, origin) in crate::emit::verilog_regs::identifiers(d) {
        claim("sc_regs:", name, origin)?;
    }
    for p in &d.ports {
        let origin = format!("port {}", p.name);
        let module = format!("ports::{}::", p.name);
        for s in &p.signals {
            claim(
                "",
                format!("{}_{}_WIDTH", p.name, s.name),
                format!("{origin} signal {}", s.name),
            )?;
            claim(
                &module,
                format!("{}_WIDTH", s.name),
                format!("{origin} signal {}", s.name),
            )?;
        }
        for f in &p.fields {
            let forigin = format!("{origin} field {}", f.name);
            claim(&module, f.name.clone(), forigin.clone())?;
            for suffix in ["LSB", "MSB", "WIDTH"] {
                claim(
                    "",
                    format!("{}_{}_{suffix}", p.name, f.name),
                    forigin.clone(),
                )?;
            }
        }
    }
    Ok(())
}

/// Lower-case names become Rust modules and methods, where a keyword does not compile.
fn check_rust_identifier(at: &str, name: &str) -> Result<(), RegenError> {
    const KEYWORDS: [&str; 51] = [
        "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate",
        "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if", "impl",
        "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub",
        "ref", "return", "self", "static", "struct", "super", "trait", "true", "try", "type",
        "typeof", "union", "unsafe", "unsized", "use", "virtual", "where", "while",
    ];
    if KEYWORDS.contains(&name) {
        return Err(invalid(
            at,
            format!("generates the Rust identifier `{name}`, which is a keyword"),
        ));
    }
    Ok(())
}

/// VERSION's MAJOR/MINOR resets must be the block's version, so the map's version lives in one
/// place a reader can find.
fn check_version_register(registers: &[Register], block: &Block) -> Result<(), RegenError> {
    let version = registers
        .iter()
        .find(|r| r.name == "VERSION")
        .ok_or_else(|| invalid("register", "a VERSION register is required"))?;
    for (name, want) in [
        ("MAJOR", block.version_major),
        ("MINOR", block.version_minor),
    ] {
        let field = version
            .fields
            .iter()
            .find(|f| f.name == name)
            .ok_or_else(|| invalid("register VERSION", format!("field {name} is required")))?;
        if field.reset != want {
            return Err(invalid(
                format!("register VERSION field {name}"),
                format!(
                    "reset {} differs from block.version_{} = {want}",
                    field.reset,
                    name.to_ascii_lowercase()
                ),
            ));
        }
    }
    Ok(())
}

fn resolve_bound(
    at: &str,
    bound: &RawBound,
    params: &BTreeMap<String, u32>,
) -> Result<u32, RegenError> {
    match bound {
        RawBound::Value(v) => Ok(*v),
        RawBound::Param(name) => params.get(name).copied().ok_or_else(|| {
            invalid(
                at,
                format!("range names `{name}`, which is not in [params]"),
            )
        }),
    }
}

fn resolve_register(
    r: RawRegister,
    block: &Block,
    params: &BTreeMap<String, u32>,
    ports: &[Port],
) -> Result<Register, RegenError> {
    let at = format!("register {}", r.name);
    check_name(&at, &r.name)?;
    if r.offset % 4 != 0 {
        return Err(invalid(
            &at,
            format!("offset {:#x} is not 32-bit aligned", r.offset),
        ));
    }
    if r.offset + 4 > block.window_size {
        return Err(invalid(
            &at,
            format!(
                "offset {:#x} is outside the {:#x}-byte window",
                r.offset, block.window_size
            ),
        ));
    }

    let mut fields = Vec::new();
    if let Some(port_name) = &r.fields_from_port {
        let port = ports.iter().find(|p| &p.name == port_name).ok_or_else(|| {
            invalid(
                &at,
                format!("fields_from_port names `{port_name}`, which is not a port"),
            )
        })?;
        for pf in &port.fields {
            fields.push(Field {
                name: pf.name.clone(),
                msb: pf.msb,
                lsb: pf.lsb,
                access: r.access,
                reset: 0,
                doc: pf.doc.clone(),
                min: 0,
                max: bits_max(pf.width()),
                has_range: false,
                enums: Vec::new(),
            });
        }
    }
    for f in r.fields {
        fields.push(resolve_field(&at, f, r.access, params)?);
    }
    if fields.is_empty() {
        return Err(invalid(&at, "a register needs at least one field"));
    }
    fields.sort_by_key(|f| f.lsb);
    check_unique(&at, "field", fields.iter().map(|f| f.name.as_str()))?;
    for pair in fields.windows(2) {
        if pair[1].lsb <= pair[0].msb {
            return Err(invalid(
                &at,
                format!("fields {} and {} overlap", pair[0].name, pair[1].name),
            ));
        }
    }
    let composed = fields.iter().fold(0u32, |acc, f| acc | (f.reset << f.lsb));
    if composed != r.reset {
        return Err(invalid(
            &at,
            format!(
                "reset {:#010x} differs from its fields' resets, which compose to {composed:#010x}",
                r.reset
            ),
        ));
    }
    if r.pops_on_read && fields.iter().any(|f| f.access != Access::Ro) {
        return Err(invalid(&at, "pops_on_read registers must be read-only"));
    }
    Ok(Register {
        name: r.name,
        offset: r.offset,
        access: r.access,
        reset: r.reset,
        doc: r.doc,
        pops_on_read: r.pops_on_read,
        fields,
    })
}

fn resolve_field(
    reg_at: &str,
    f: RawField,
    default_access: Access,
    params: &BTreeMap<String, u32>,
) -> Result<Field, RegenError> {
    let at = format!("{reg_at} field {}", f.name);
    check_name(&at, &f.name)?;
    let (msb, lsb) = check_bits(&at, f.bits, 32)?;
    let max_value = bits_max(msb - lsb + 1);
    if f.reset > max_value {
        return Err(invalid(
            &at,
            format!("reset {} does not fit in {} bits", f.reset, msb - lsb + 1),
        ));
    }
    let (min, max, has_range) = match &f.range {
        None => (0, max_value, false),
        Some([lo, hi]) => {
            let lo = resolve_bound(&at, lo, params)?;
            let hi = resolve_bound(&at, hi, params)?;
            if lo > hi {
                return Err(invalid(&at, format!("range [{lo}, {hi}] is empty")));
            }
            if hi > max_value {
                return Err(invalid(
                    &at,
                    format!("range maximum {hi} does not fit in {} bits", msb - lsb + 1),
                ));
            }
            (lo, hi, true)
        }
    };
    let access = f.access.unwrap_or(default_access);
    // A ro field's reset is what the fabric shows before it writes; it need not be "valid".
    if access != Access::Ro && (f.reset < min || f.reset > max) {
        return Err(invalid(
            &at,
            format!("reset {} is outside the range [{min}, {max}]", f.reset),
        ));
    }
    let mut enums = Vec::with_capacity(f.enums.len());
    for e in f.enums {
        let eat = format!("{at} enum {}", e.name);
        check_name(&eat, &e.name)?;
        if e.value > max_value {
            return Err(invalid(
                &eat,
                format!("value {} does not fit in the field", e.value),
            ));
        }
        enums.push(EnumValue {
            name: e.name,
            value: e.value,
            doc: e.doc,
        });
    }
    check_unique(&at, "enum value", enums.iter().map(|e| e.name.as_str()))?;
    let mut values: Vec<u32> = enums.iter().map(|e| e.value).collect();
    values.sort_unstable();
    if values.windows(2).any(|w| w[0] == w[1]) {
        return Err(invalid(&at, "two enum names share a value"));
    }
    if !enums.is_empty() && !enums.iter().any(|e| e.value == f.reset) {
        return Err(invalid(
            &at,
            format!("reset {} is none of the enum values", f.reset),
        ));
    }
    Ok(Field {
        name: f.name,
        msb,
        lsb,
        access,
        reset: f.reset,
        doc: f.doc,
        min,
        max,
        has_range,
        enums,
    })
}

fn resolve_ports(raw: Vec<RawPort>) -> Result<Vec<Port>, RegenError> {
    let mut ports = Vec::with_capacity(raw.len());
    for p in raw {
        let at = format!("port {}", p.name);
        check_name(&at, &p.name)?;
        let mut signals = Vec::with_capacity(p.signals.len());
        for s in p.signals {
            check_name(&format!("{at} signal {}", s.name), &s.name)?;
            if s.width == 0 || s.width > 32 {
                return Err(invalid(
                    format!("{at} signal {}", s.name),
                    "width must be 1..=32",
                ));
            }
            signals.push(Signal {
                name: s.name,
                width: s.width,
                direction: s.direction,
                doc: s.doc,
            });
        }
        check_unique(&at, "signal", signals.iter().map(|s| s.name.as_str()))?;
        let data_width = signals.iter().find(|s| s.name == "DATA").map(|s| s.width);
        let mut fields = Vec::with_capacity(p.fields.len());
        for f in p.fields {
            let fat = format!("{at} field {}", f.name);
            check_name(&fat, &f.name)?;
            let width = data_width
                .ok_or_else(|| invalid(&fat, "a port with a DATA layout needs a DATA signal"))?;
            let (msb, lsb) = check_bits(&fat, f.bits, width)?;
            fields.push(PortField {
                name: f.name,
                msb,
                lsb,
                doc: f.doc,
            });
        }
        fields.sort_by_key(|f| f.lsb);
        check_unique(&at, "field", fields.iter().map(|f| f.name.as_str()))?;
        for pair in fields.windows(2) {
            if pair[1].lsb <= pair[0].msb {
                return Err(invalid(
                    &at,
                    format!("fields {} and {} overlap", pair[0].name, pair[1].name),
                ));
            }
        }
        ports.push(Port {
            name: p.name,
            direction: p.direction,
            doc: p.doc,
            signals,
            fields,
        });
    }
    check_unique("port", "port", ports.iter().map(|p| p.name.as_str()))?;
    Ok(ports)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = r#"
[block]
name = "b"
doc = "d"
base_address = 0x4000_0000
window_size = 0x100
register_width = 32
version_major = 1
version_minor = 2

[params]
max_width = 100

[[register]]
name = "VERSION"
offset = 0
access = "ro"
reset = 0x0102
doc = "v"
[[register.field]]
name = "MINOR"
bits = [7, 0]
reset = 2
doc = "m"
[[register.field]]
name = "MAJOR"
bits = [15, 8]
reset = 1
doc = "M"

[[register]]
name = "WIDTH"
offset = 4
access = "rw"
reset = 50
doc = "w"
[[register.field]]
name = "VALUE"
bits = [15, 0]
reset = 50
range = [1, "max_width"]
doc = "x"
"#;

    fn error_of(source: &str) -> String {
        parse(source)
            .expect_err("description must be rejected")
            .to_string()
    }

    #[test]
    fn minimal_description_resolves_ranges_and_masks() {
        let d = parse(MINIMAL).unwrap();
        let width = &d.registers[1];
        assert_eq!(width.fields[0].max, 100);
        assert_eq!(width.mask_of(Access::Rw), 0xFFFF);
        assert_eq!(d.registers[0].mask_of(Access::Ro), 0xFFFF);
    }

    #[test]
    fn unknown_key_is_named() {
        let e = error_of(&MINIMAL.replace("doc = \"x\"", "doc = \"x\"\ncolour = 1"));
        assert!(e.contains("colour"), "{e}");
    }

    #[test]
    fn reset_must_compose_from_fields() {
        let e = error_of(&MINIMAL.replace("reset = 0x0102", "reset = 0x0103"));
        assert!(
            e.contains("register VERSION") && e.contains("compose"),
            "{e}"
        );
    }

    #[test]
    fn overlapping_fields_are_rejected() {
        let e = error_of(&MINIMAL.replace("bits = [15, 8]", "bits = [15, 7]"));
        assert!(e.contains("overlap"), "{e}");
    }

    #[test]
    fn misaligned_offset_is_rejected() {
        let e = error_of(&MINIMAL.replace("offset = 4", "offset = 6"));
        assert!(e.contains("register WIDTH") && e.contains("aligned"), "{e}");
    }

    #[test]
    fn unknown_parameter_is_named() {
        let e = error_of(&MINIMAL.replace("\"max_width\"]", "\"max_wdth\"]"));
        assert!(e.contains("max_wdth"), "{e}");
    }

    #[test]
    fn reset_outside_range_is_rejected() {
        let e = error_of(&MINIMAL.replace("reset = 50", "reset = 500"));
        assert!(e.contains("register WIDTH"), "{e}");
    }

    #[test]
    fn colliding_generated_identifiers_are_rejected() {
        let e = error_of(&MINIMAL.replace("name = \"VALUE\"", "name = \"OFFSET\""));
        assert!(e.contains("`OFFSET`"), "{e}");
        let split = MINIMAL.replace("name = \"WIDTH\"", "name = \"VERSION_MAJOR\"");
        let e = error_of(&split);
        assert!(e.contains("VERSION_MAJOR"), "{e}");
    }

    #[test]
    fn colliding_trait_methods_are_rejected() {
        // Register SET_WIDTH field VALUE has the getter `set_width_value`, which is also
        // WIDTH.VALUE's setter.
        let extra = r#"
[[register]]
name = "SET_WIDTH"
offset = 8
access = "ro"
reset = 0
doc = "s"
[[register.field]]
name = "VALUE"
bits = [0, 0]
reset = 0
doc = "v"
"#;
        let e = error_of(&format!("{MINIMAL}{extra}"));
        assert!(e.contains("`set_width_value`"), "{e}");
        // A getter named like a `RegisterBus` method.
        let e = error_of(
            &MINIMAL
                .replace("name = \"WIDTH\"", "name = \"READ\"")
                .replace("name = \"VALUE\"", "name = \"FIELD\""),
        );
        assert!(e.contains("`read_field`"), "{e}");
    }

    #[test]
    fn colliding_register_block_ports_are_rejected() {
        // Register BUS field ADDR would be the Verilog port `bus_addr` of sc_regs.
        let e = error_of(
            &MINIMAL
                .replace("name = \"WIDTH\"", "name = \"BUS\"")
                .replace("name = \"VALUE\"", "name = \"ADDR\""),
        );
        assert!(e.contains("`bus_addr`"), "{e}");
    }

    #[test]
    fn keywords_are_rejected_as_rust_names() {
        let e = error_of(&MINIMAL.replace("name = \"WIDTH\"", "name = \"LOOP\""));
        assert!(e.contains("`loop`") && e.contains("keyword"), "{e}");
    }

    #[test]
    fn version_fields_must_match_block_version() {
        let e = error_of(&MINIMAL.replace("version_minor = 2", "version_minor = 3"));
        assert!(e.contains("version_minor"), "{e}");
    }
}
