//! `src/regs.rs`: constants and typed descriptors for the `stereocal-hdl` crate (`no_std`).

use std::fmt::Write;

use super::{camel_case, hex32_grouped, readable};
use crate::description::{Access, Description, Field, Register};
use crate::BANNER;

fn access_variant(a: Access) -> &'static str {
    match a {
        Access::Ro => "Access::Ro",
        Access::Rw => "Access::Rw",
        Access::W1c => "Access::W1c",
        Access::Wo => "Access::Wo",
    }
}

pub(super) fn doc_lines(out: &mut String, indent: &str, text: &str) {
    for line in text.lines() {
        if line.is_empty() {
            let _ = writeln!(out, "{indent}///");
        } else {
            let _ = writeln!(out, "{indent}/// {line}");
        }
    }
}

pub fn emit(d: &Description) -> String {
    let mut o = String::new();
    let b = &d.block;
    let _ = writeln!(o, "// {BANNER}.");
    let _ = writeln!(o, "//! Register map of `{}`: {}", b.name, b.doc);
    let _ = writeln!(o, "//!");
    let _ = writeln!(
        o,
        "//! One module per register (byte offset, reset value, one [`Field`](crate::Field) per field, enums),"
    );
    let _ = writeln!(
        o,
        "//! [`REGISTERS`] for table-driven code, and [`ports`] for the stream-port layouts."
    );
    o.push_str("\nuse crate::Register;\n\n");

    let _ = writeln!(
        o,
        "/// Address of the fabric's AXI4-lite register window on the soft-core's bus."
    );
    let _ = writeln!(
        o,
        "pub const BASE_ADDRESS: usize = {};",
        hex32_grouped(b.base_address)
    );
    let _ = writeln!(
        o,
        "/// Bytes in the register window; every offset is below it."
    );
    let _ = writeln!(o, "pub const WINDOW_SIZE: u32 = {:#X};", b.window_size);
    let _ = writeln!(o, "/// Bits per register.");
    let _ = writeln!(o, "pub const REGISTER_WIDTH: u32 = {};", b.register_width);
    let _ = writeln!(
        o,
        "/// Register-map version this crate was generated for (VERSION.MAJOR / VERSION.MINOR)."
    );
    let _ = writeln!(o, "pub const VERSION_MAJOR: u32 = {};", b.version_major);
    let _ = writeln!(o, "pub const VERSION_MINOR: u32 = {};", b.version_minor);
    for (name, value) in &d.params {
        let _ = writeln!(o, "/// Synthesis parameter `{name}` of the description.");
        let _ = writeln!(o, "pub const {}: u32 = {value};", name.to_ascii_uppercase());
    }
    o.push('\n');

    for r in &d.registers {
        emit_register(&mut o, r);
    }

    let _ = writeln!(o, "/// Every register, sorted by offset.");
    let _ = writeln!(
        o,
        "pub static REGISTERS: [Register; {}] = [",
        d.registers.len()
    );
    for r in &d.registers {
        let _ = writeln!(o, "    {}::REGISTER,", r.name.to_ascii_lowercase());
    }
    o.push_str("];\n\n");

    o.push_str("/// Stream ports: signal widths and the bit layout of each DATA word.\n");
    o.push_str("pub mod ports {");
    for p in &d.ports {
        o.push('\n');
        doc_lines(
            &mut o,
            "    ",
            &format!(
                "{} Direction: {} of the fabric.",
                p.doc,
                p.direction.as_str()
            ),
        );
        let _ = writeln!(o, "    pub mod {} {{", p.name.to_ascii_lowercase());
        if !p.fields.is_empty() {
            o.push_str("        use crate::BitRange;\n\n");
        }
        for s in &p.signals {
            doc_lines(
                &mut o,
                "        ",
                &format!(
                    "Width of `{}` ({}): {}",
                    s.name,
                    s.direction.as_str(),
                    s.doc
                ),
            );
            let _ = writeln!(o, "        pub const {}_WIDTH: u32 = {};", s.name, s.width);
        }
        for f in &p.fields {
            doc_lines(
                &mut o,
                "        ",
                &format!("`DATA[{}:{}]`: {}", f.msb, f.lsb, f.doc),
            );
            let _ = writeln!(
                o,
                "        pub const {}: BitRange = BitRange {{ lsb: {}, width: {} }};",
                f.name,
                f.lsb,
                f.width()
            );
        }
        o.push_str("    }\n");
    }
    o.push_str("}\n");
    o
}

fn emit_register(o: &mut String, r: &Register) {
    doc_lines(
        o,
        "",
        &format!("{} Offset {:#04X}, {}.", r.doc, r.offset, r.access.as_str()),
    );
    let _ = writeln!(o, "pub mod {} {{", r.name.to_ascii_lowercase());
    o.push_str("    use crate::{Access, BitRange, Field, Register};\n\n");
    let _ = writeln!(o, "    /// Byte offset from [`super::BASE_ADDRESS`].");
    let _ = writeln!(o, "    pub const OFFSET: u16 = {:#04X};", r.offset);
    let _ = writeln!(o, "    /// Value after reset.");
    let _ = writeln!(o, "    pub const RESET: u32 = {};", hex32_grouped(r.reset));
    let _ = writeln!(o, "    /// Offset, reset and access masks.");
    let _ = writeln!(o, "    pub const REGISTER: Register = Register {{");
    let _ = writeln!(o, "        name: \"{}\",", r.name);
    o.push_str("        offset: OFFSET,\n        reset: RESET,\n");
    for (name, access) in [
        ("ro_mask", Access::Ro),
        ("rw_mask", Access::Rw),
        ("w1c_mask", Access::W1c),
        ("wo_mask", Access::Wo),
    ] {
        let _ = writeln!(o, "        {name}: {},", hex32_grouped(r.mask_of(access)));
    }
    let _ = writeln!(o, "        pops_on_read: {},", r.pops_on_read);
    o.push_str("    };\n");
    for f in &r.fields {
        emit_field(o, r, f);
    }
    o.push_str("}\n\n");
}

fn emit_field(o: &mut String, r: &Register, f: &Field) {
    o.push('\n');
    let range = if f.has_range {
        format!(", valid {}..={}", f.min, f.max)
    } else {
        String::new()
    };
    doc_lines(
        o,
        "    ",
        &format!(
            "`[{}:{}]` {}, reset {}{range}: {}",
            f.msb,
            f.lsb,
            f.access.as_str(),
            readable(f.reset),
            f.doc
        ),
    );
    let _ = writeln!(o, "    pub const {}: Field = Field {{", f.name);
    let _ = writeln!(o, "        name: \"{}.{}\",", r.name, f.name);
    o.push_str("        offset: OFFSET,\n");
    let _ = writeln!(
        o,
        "        bits: BitRange {{ lsb: {}, width: {} }},",
        f.lsb,
        f.width()
    );
    let _ = writeln!(o, "        access: {},", access_variant(f.access));
    let _ = writeln!(o, "        reset: {},", f.reset);
    let _ = writeln!(o, "        min: {},", f.min);
    let _ = writeln!(o, "        max: {},", f.max);
    o.push_str("    };\n");
    if f.enums.is_empty() {
        return;
    }
    let ty = camel_case(&f.name);
    o.push('\n');
    let _ = writeln!(o, "    /// Values of [`{}`].", f.name);
    o.push_str("    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]\n    #[repr(u32)]\n");
    let _ = writeln!(o, "    pub enum {ty} {{");
    for e in &f.enums {
        doc_lines(o, "        ", &e.doc);
        let _ = writeln!(o, "        {} = {},", camel_case(&e.name), e.value);
    }
    o.push_str("    }\n\n");
    let _ = writeln!(o, "    impl {ty} {{");
    o.push_str("        /// The field's code for this value.\n");
    o.push_str("        pub const fn bits(self) -> u32 {\n            self as u32\n        }\n\n");
    o.push_str("        /// The value a code names, if any.\n");
    o.push_str(
        "        pub const fn from_bits(bits: u32) -> Option<Self> {\n            match bits {\n",
    );
    for e in &f.enums {
        let _ = writeln!(
            o,
            "                {} => Some(Self::{}),",
            e.value,
            camel_case(&e.name)
        );
    }
    o.push_str("                _ => None,\n            }\n        }\n    }\n\n");
    let reset = f
        .enums
        .iter()
        .find(|e| e.value == f.reset)
        .map(|e| camel_case(&e.name))
        .unwrap_or_default();
    let _ = writeln!(o, "    /// [`{}`] after reset.", f.name);
    let _ = writeln!(o, "    pub const {}_RESET: {ty} = {ty}::{reset};", f.name);
}
