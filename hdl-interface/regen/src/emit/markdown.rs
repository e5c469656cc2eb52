//! `generated/registers.md`: one table per register and per stream port.

use std::fmt::Write;

use super::{hex32_grouped, readable};
use crate::description::Description;
use crate::BANNER;

/// Cell text safe inside a Markdown table row.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

pub fn emit(d: &Description) -> String {
    let mut o = String::new();
    let b = &d.block;
    let _ = writeln!(o, "<!-- {BANNER}. -->\n");
    let _ = writeln!(o, "# `{}` registers\n", b.name);
    let _ = writeln!(o, "{}\n", b.doc);
    let _ = writeln!(
        o,
        "Base address `{}` (AXI4-lite window of `{:#X}` bytes on the soft-core bus), {}-bit registers, map version {}.{}. \
         Offsets are bytes from the base. Bits not listed are reserved: they read 0 and ignore writes.\n",
        hex32_grouped(b.base_address),
        b.window_size,
        b.register_width,
        b.version_major,
        b.version_minor
    );
    o.push_str(
        "Access: `ro` the bus cannot write it; `rw` reads back what was written; \
                `w1c` set by the fabric, cleared by writing 1; `wo` a strobe that reads 0.\n\n",
    );

    o.push_str("## Parameters\n\n| Parameter | Value |\n|---|---|\n");
    for (name, value) in &d.params {
        let _ = writeln!(o, "| `{name}` | {value} |");
    }

    o.push_str("\n## Register summary\n\n| Offset | Name | Access | Reset | Description |\n|---|---|---|---|---|\n");
    for r in &d.registers {
        let _ = writeln!(
            o,
            "| `{:#04X}` | [{}](#{}) | {} | `{}` | {} |",
            r.offset,
            r.name,
            r.name.to_ascii_lowercase(),
            r.access.as_str(),
            hex32_grouped(r.reset),
            cell(&r.doc)
        );
    }

    for r in &d.registers {
        let _ = writeln!(o, "\n## {}\n", r.name);
        let pops = if r.pops_on_read {
            " A bus read removes the FIFO's head."
        } else {
            ""
        };
        let _ = writeln!(
            o,
            "Offset `{:#04X}`, access {}, reset `{}`. {}{pops}\n",
            r.offset,
            r.access.as_str(),
            hex32_grouped(r.reset),
            r.doc
        );
        o.push_str(
            "| Bits | Field | Access | Reset | Valid | Description |\n|---|---|---|---|---|---|\n",
        );
        for f in r.fields.iter().rev() {
            let bits = if f.msb == f.lsb {
                format!("{}", f.lsb)
            } else {
                format!("{}:{}", f.msb, f.lsb)
            };
            let valid = if f.has_range {
                format!("{}..={}", f.min, f.max)
            } else {
                String::from("any")
            };
            let mut doc = cell(&f.doc);
            for e in &f.enums {
                let _ = write!(doc, "<br>`{}` = {}: {}", e.name, e.value, cell(&e.doc));
            }
            let _ = writeln!(
                o,
                "| {bits} | {} | {} | {} | {valid} | {doc} |",
                f.name,
                f.access.as_str(),
                readable(f.reset)
            );
        }
    }

    o.push_str("\n## Stream ports\n\nA word moves on a clock where VALID and READY are both 1. Directions are seen from the fabric.\n\n");
    o.push_str("| Port | Signal | Direction | Width | Description |\n|---|---|---|---|---|\n");
    for p in &d.ports {
        for s in &p.signals {
            let _ = writeln!(
                o,
                "| {} | {} | {} | {} | {} |",
                p.name,
                s.name,
                s.direction.as_str(),
                s.width,
                cell(&s.doc)
            );
        }
    }
    for p in d.ports.iter().filter(|p| !p.fields.is_empty()) {
        let _ = writeln!(o, "\n### {} DATA layout\n\n{}\n", p.name, p.doc);
        o.push_str("| Bits | Field | Description |\n|---|---|---|\n");
        for f in p.fields.iter().rev() {
            let bits = if f.msb == f.lsb {
                format!("{}", f.lsb)
            } else {
                format!("{}:{}", f.msb, f.lsb)
            };
            let _ = writeln!(o, "| {bits} | {} | {} |", f.name, cell(&f.doc));
        }
    }
    o
}
