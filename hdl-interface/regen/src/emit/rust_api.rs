//! `src/regs_api.rs`: the typed register interface of the `stereocal-hdl` crate (`no_std`).
//!
//! A `Registers` trait with one method per field and per operation the field's access type
//! allows, provided on top of the hand-written `RegisterBus` transport and blanket-implemented
//! for every bus (so the soft-core's `Mmio` and the in-memory `RegisterBank` both have it).
//! Reads and writes go through `RegisterBus::read_field` / `write_field`, the one
//! implementation of field extraction, range checks and the read-modify-write rules.

use std::fmt::Write;

use super::rust::doc_lines;
use super::{camel_case, readable};
use crate::description::{Access, Description, Field, Register};
use crate::BANNER;

/// Name of the generated trait.
pub const TRAIT_NAME: &str = "Registers";

/// What a generated method does with its field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Operation {
    /// `register_field()`: the field's value (`ro`, `rw`, `w1c`).
    Get,
    /// `set_register_field(v)` (`rw`).
    Set,
    /// `clear_register_field()` (`w1c`, one bit) or `clear_register_field(bits)` (wider).
    Clear,
    /// `fire_register_field()` (`wo`, one bit: writes the strobe).
    Fire,
    /// `write_register_field(v)` (`wo`, wider than one bit).
    Write,
}

/// The methods a field gets in the trait, with their names. Fields of a `pops_on_read`
/// register get none: the register is read once, whole, by [`pop_method`].
pub fn field_methods(r: &Register, f: &Field) -> Vec<(Operation, String)> {
    if r.pops_on_read {
        return Vec::new();
    }
    let base = format!("{}_{}", r.name, f.name).to_ascii_lowercase();
    let ops: &[Operation] = match f.access {
        Access::Ro => &[Operation::Get],
        Access::Rw => &[Operation::Get, Operation::Set],
        Access::W1c => &[Operation::Get, Operation::Clear],
        Access::Wo if f.width() == 1 => &[Operation::Fire],
        Access::Wo => &[Operation::Write],
    };
    ops.iter()
        .map(|&op| {
            let name = match op {
                Operation::Get => base.clone(),
                Operation::Set => format!("set_{base}"),
                Operation::Clear => format!("clear_{base}"),
                Operation::Fire => format!("fire_{base}"),
                Operation::Write => format!("write_{base}"),
            };
            (op, name)
        })
        .collect()
}

/// `pop_register` for a `pops_on_read` register.
pub fn pop_method(r: &Register) -> Option<String> {
    r.pops_on_read
        .then(|| format!("pop_{}", r.name.to_ascii_lowercase()))
}

/// The word type a `pops_on_read` register's value comes in, and its accessors (one per
/// field, lower-case field name).
pub fn word_type(r: &Register) -> Option<(String, Vec<String>)> {
    r.pops_on_read.then(|| {
        (
            camel_case(&r.name),
            r.fields
                .iter()
                .map(|f| f.name.to_ascii_lowercase())
                .collect(),
        )
    })
}

/// How a field's value is typed in the API.
enum ValueType {
    Bool,
    /// The field's enum; `exhaustive` when it names every value the bits can hold.
    Enum {
        path: String,
        exhaustive: bool,
    },
    /// `u8`, `u16` or `u32`, the narrowest that holds the field.
    Int(&'static str),
}

fn value_type(r: &Register, f: &Field) -> ValueType {
    if !f.enums.is_empty() {
        let exhaustive =
            u64::try_from(f.enums.len()).unwrap_or(u64::MAX) == u64::from(f.max_value()) + 1;
        return ValueType::Enum {
            path: format!(
                "regs::{}::{}",
                r.name.to_ascii_lowercase(),
                camel_case(&f.name)
            ),
            exhaustive,
        };
    }
    match f.width() {
        1 => ValueType::Bool,
        2..=8 => ValueType::Int("u8"),
        9..=16 => ValueType::Int("u16"),
        _ => ValueType::Int("u32"),
    }
}

impl ValueType {
    /// The getter's return type.
    fn get_type(&self) -> String {
        match self {
            ValueType::Bool => "bool".to_string(),
            ValueType::Enum {
                path,
                exhaustive: true,
            } => path.clone(),
            ValueType::Enum {
                path,
                exhaustive: false,
            } => format!("Option<{path}>"),
            ValueType::Int(t) => (*t).to_string(),
        }
    }

    /// The setter's argument type.
    fn set_type(&self) -> String {
        match self {
            ValueType::Bool => "bool".to_string(),
            ValueType::Enum { path, .. } => path.clone(),
            ValueType::Int(t) => (*t).to_string(),
        }
    }

    /// The expression turning the unshifted field bits `bits` (a `u32` already masked to the
    /// field) into the getter's type. `indent` is the indentation of the expression.
    fn decode_expr(&self, f: &Field, bits: &str, indent: &str) -> String {
        match self {
            ValueType::Bool => format!("{bits} != 0"),
            ValueType::Enum {
                path,
                exhaustive: true,
            } => {
                let mut values: Vec<_> = f.enums.iter().collect();
                values.sort_by_key(|e| e.value);
                let mut o = format!("match {bits} {{\n");
                for (i, e) in values.iter().enumerate() {
                    // The bits are masked to the field, so the last value is the only other.
                    let pattern = if i + 1 == values.len() {
                        "_".to_string()
                    } else {
                        e.value.to_string()
                    };
                    let _ = writeln!(
                        o,
                        "{indent}    {pattern} => {path}::{},",
                        camel_case(&e.name)
                    );
                }
                o.push_str(indent);
                o.push('}');
                o
            }
            ValueType::Enum {
                path,
                exhaustive: false,
            } => format!("{path}::from_bits({bits})"),
            // The bits are masked to the field, which the type holds.
            ValueType::Int("u32") => bits.to_string(),
            ValueType::Int(t) => format!("{bits} as {t}"),
        }
    }

    /// The expression turning the setter's argument `var` into the unshifted `u32` bits.
    fn encode_expr(&self, var: &str) -> String {
        match self {
            ValueType::Bool => format!("u32::from({var})"),
            ValueType::Enum { .. } => format!("{var}.bits()"),
            ValueType::Int("u32") => var.to_string(),
            ValueType::Int(_) => format!("u32::from({var})"),
        }
    }
}

/// `[msb:lsb] access, reset R[, valid MIN..=MAX]`, as `regs.rs` describes a field.
fn field_summary(f: &Field) -> String {
    let range = if f.has_range {
        format!(", valid {}..={}", f.min, f.max)
    } else {
        String::new()
    };
    format!(
        "`[{}:{}]` {}, reset {}{range}",
        f.msb,
        f.lsb,
        f.access.as_str(),
        readable(f.reset)
    )
}

pub fn emit(d: &Description) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "// {BANNER}.");
    let _ = writeln!(
        o,
        "//! Typed register access for `{}`: [`{TRAIT_NAME}`], one method per field and operation,",
        d.block.name
    );
    o.push_str(
        "//! on every [`RegisterBus`] (the soft-core's [`Mmio`](crate::Mmio), the in-memory\n\
         //! [`RegisterBank`](crate::RegisterBank), `&mut` either).\n\
         //!\n\
         //! Names are `register_field` in lower case, with a prefix for what the method does; the\n\
         //! access type of the field decides which methods exist:\n\
         //! - `rw`: `register_field()` reads, `set_register_field(value)` writes;\n\
         //! - `ro`: `register_field()` only;\n\
         //! - `w1c`: `register_field()` reads the flag, `clear_register_field()` clears it;\n\
         //! - `wo`: `fire_register_field()` writes a one-bit strobe (`write_register_field(value)`\n\
         //!   for a wider one); it reads as 0, so it has no getter;\n\
         //! - a `pops_on_read` register has one `pop_register()` that reads it once and returns a\n\
         //!   word with a typed accessor per field (a read per field would pop once per field).\n\
         //!\n\
         //! A one-bit field is a `bool`, a field with an enum is that enum ([`regs`]; an `Option`\n\
         //! when the enum does not name every value the bits hold), any other field the narrowest\n\
         //! of `u8`, `u16`, `u32` that holds its bits. Getters return what the register holds.\n\
         //! Writes go through [`RegisterBus::write_field`]: a value outside the field's range is\n\
         //! [`Error::FieldOutOfRange`] and nothing is written; the register's other `rw` fields\n\
         //! keep their values and no other `w1c` flag is cleared or `wo` strobe fired. For a field\n\
         //! without a range whose type fits its bits the write cannot fail.\n",
    );
    o.push_str("\nuse crate::{regs, Error, RegisterBus};\n\n");

    let _ = writeln!(
        o,
        "/// Typed access to every field of the register map; see the [module](self) for the"
    );
    let _ = writeln!(
        o,
        "/// naming and typing rules. Implemented for every [`RegisterBus`]."
    );
    let _ = writeln!(o, "pub trait {TRAIT_NAME}: RegisterBus {{");
    let mut first = true;
    for r in &d.registers {
        if !first {
            o.push('\n');
        }
        first = false;
        let _ = writeln!(o, "    // {} (offset {:#04X}): {}", r.name, r.offset, r.doc);
        if let Some(pop) = pop_method(r) {
            emit_pop(&mut o, r, &pop);
            continue;
        }
        for f in &r.fields {
            for (op, name) in field_methods(r, f) {
                emit_method(&mut o, r, f, op, &name);
            }
        }
    }
    o.push_str("}\n\n");
    let _ = writeln!(o, "impl<B: RegisterBus + ?Sized> {TRAIT_NAME} for B {{}}");

    for r in &d.registers {
        if let Some((ty, accessors)) = word_type(r) {
            emit_word(&mut o, r, &ty, &accessors);
        }
    }
    o
}

fn emit_method(o: &mut String, r: &Register, f: &Field, op: Operation, name: &str) {
    let module = format!("regs::{}", r.name.to_ascii_lowercase());
    let field = format!("&{module}::{}", f.name);
    let ty = value_type(r, f);
    let summary = field_summary(f);
    let qualified = format!("{}.{}", r.name, f.name);
    o.push('\n');
    match op {
        Operation::Get => {
            doc_lines(o, "    ", &format!("{qualified} {summary}: {}", f.doc));
            let _ = writeln!(o, "    fn {name}(&mut self) -> {} {{", ty.get_type());
            let bits = format!("self.read_field({field})");
            let _ = writeln!(o, "        {}", ty.decode_expr(f, &bits, "        "));
            o.push_str("    }\n");
        }
        Operation::Set | Operation::Write => {
            let doc = if op == Operation::Set {
                let getter = format!("{}_{}", r.name, f.name).to_ascii_lowercase();
                format!("Writes {qualified} ({summary}); see [`Self::{getter}`].")
            } else {
                format!("Writes the {qualified} strobe ({summary}): {}", f.doc)
            };
            doc_lines(o, "    ", &doc);
            let _ = writeln!(
                o,
                "    fn {name}(&mut self, value: {}) -> Result<(), Error> {{",
                ty.set_type()
            );
            let _ = writeln!(
                o,
                "        self.write_field({field}, {})",
                ty.encode_expr("value")
            );
            o.push_str("    }\n");
        }
        Operation::Clear if f.width() == 1 => {
            doc_lines(
                o,
                "    ",
                &format!("Clears the {qualified} flag (writes 1 to it; the other flags stay)."),
            );
            let _ = writeln!(o, "    fn {name}(&mut self) -> Result<(), Error> {{");
            let _ = writeln!(o, "        self.write_field({field}, 1)");
            o.push_str("    }\n");
        }
        Operation::Clear => {
            doc_lines(
                o,
                "    ",
                &format!("Clears the {qualified} bits set in `bits` (the other flags stay)."),
            );
            let _ = writeln!(
                o,
                "    fn {name}(&mut self, bits: {}) -> Result<(), Error> {{",
                ty.set_type()
            );
            let _ = writeln!(
                o,
                "        self.write_field({field}, {})",
                ty.encode_expr("bits")
            );
            o.push_str("    }\n");
        }
        Operation::Fire => {
            doc_lines(
                o,
                "    ",
                &format!("Fires the {qualified} strobe (writes 1 to it): {}", f.doc),
            );
            let _ = writeln!(o, "    fn {name}(&mut self) -> Result<(), Error> {{");
            let _ = writeln!(o, "        self.write_field({field}, 1)");
            o.push_str("    }\n");
        }
    }
}

fn emit_pop(o: &mut String, r: &Register, name: &str) {
    let ty = camel_case(&r.name);
    o.push('\n');
    doc_lines(
        o,
        "    ",
        &format!(
            "Reads {} once (the read pops the FIFO's head) and returns the whole word.",
            r.name
        ),
    );
    let _ = writeln!(o, "    fn {name}(&mut self) -> {ty} {{");
    let _ = writeln!(
        o,
        "        {ty}(self.read(regs::{}::OFFSET))",
        r.name.to_ascii_lowercase()
    );
    o.push_str("    }\n");
}

fn emit_word(o: &mut String, r: &Register, ty: &str, accessors: &[String]) {
    let module = format!("regs::{}", r.name.to_ascii_lowercase());
    o.push('\n');
    doc_lines(
        o,
        "",
        &format!(
            "A value of {}, as [`{TRAIT_NAME}::{}`] read it: {}",
            r.name,
            pop_method(r).unwrap_or_default(),
            r.doc
        ),
    );
    o.push_str("#[derive(Clone, Copy, Debug, PartialEq, Eq)]\n");
    let _ = writeln!(o, "pub struct {ty}(pub u32);\n");
    let _ = writeln!(o, "impl {ty} {{");
    for (i, (f, accessor)) in r.fields.iter().zip(accessors).enumerate() {
        if i > 0 {
            o.push('\n');
        }
        let vt = value_type(r, f);
        doc_lines(
            o,
            "    ",
            &format!("{} {}: {}", f.name, field_summary(f), f.doc),
        );
        let _ = writeln!(
            o,
            "    pub const fn {accessor}(self) -> {} {{",
            vt.get_type()
        );
        let bits = format!("{module}::{}.extract(self.0)", f.name);
        let _ = writeln!(o, "        {}", vt.decode_expr(f, &bits, "        "));
        o.push_str("    }\n");
    }
    o.push_str("}\n");
}
