//! `generated/stereocal_regs.h`: C99 macros, every name prefixed `STEREOCAL_`.

use std::fmt::Write;

use crate::description::Description;
use crate::BANNER;

/// Comment text made safe inside `/* ... */`.
fn comment(text: &str) -> String {
    text.replace("*/", "* /").replace('\n', " ")
}

pub fn emit(d: &Description) -> String {
    let mut o = String::new();
    let b = &d.block;
    let _ = writeln!(o, "/* {BANNER}. */");
    let _ = writeln!(o, "/* Register map of `{}`: {} */", b.name, comment(&b.doc));
    o.push_str("#ifndef STEREOCAL_REGS_H\n#define STEREOCAL_REGS_H\n\n");
    o.push_str(
        "/* Offsets are bytes from STEREOCAL_BASE_ADDR; MASK macros are already shifted. */\n",
    );
    let _ = writeln!(o, "#define STEREOCAL_BASE_ADDR 0x{:08X}u", b.base_address);
    let _ = writeln!(o, "#define STEREOCAL_WINDOW_SIZE 0x{:X}u", b.window_size);
    let _ = writeln!(o, "#define STEREOCAL_REGISTER_WIDTH {}u", b.register_width);
    let _ = writeln!(o, "#define STEREOCAL_VERSION_MAJOR {}u", b.version_major);
    let _ = writeln!(o, "#define STEREOCAL_VERSION_MINOR {}u", b.version_minor);
    for (name, value) in &d.params {
        let _ = writeln!(
            o,
            "#define STEREOCAL_{} {value}u",
            name.to_ascii_uppercase()
        );
    }
    for r in &d.registers {
        o.push('\n');
        let _ = writeln!(
            o,
            "/* {} ({}): {} */",
            r.name,
            r.access.as_str(),
            comment(&r.doc)
        );
        let p = format!("STEREOCAL_{}", r.name);
        let _ = writeln!(o, "#define {p}_OFFSET 0x{:02X}u", r.offset);
        let _ = writeln!(o, "#define {p}_RESET 0x{:08X}u", r.reset);
        for f in &r.fields {
            let fp = format!("{p}_{}", f.name);
            let range = if f.has_range {
                format!(", valid {}..{}", f.min, f.max)
            } else {
                String::new()
            };
            let _ = writeln!(
                o,
                "/* [{}:{}] {}{range}: {} */",
                f.msb,
                f.lsb,
                f.access.as_str(),
                comment(&f.doc)
            );
            let _ = writeln!(o, "#define {fp}_SHIFT {}u", f.lsb);
            let _ = writeln!(o, "#define {fp}_WIDTH {}u", f.width());
            let _ = writeln!(o, "#define {fp}_MASK 0x{:08X}u", f.mask());
            let _ = writeln!(o, "#define {fp}_RESET 0x{:X}u", f.reset);
            if f.has_range {
                let _ = writeln!(o, "#define {fp}_MIN {}u", f.min);
                let _ = writeln!(o, "#define {fp}_MAX {}u", f.max);
            }
            for e in &f.enums {
                let _ = writeln!(
                    o,
                    "#define {fp}_{} {}u /* {} */",
                    e.name,
                    e.value,
                    comment(&e.doc)
                );
            }
        }
    }
    for port in &d.ports {
        o.push('\n');
        let _ = writeln!(
            o,
            "/* Stream port {} ({}): {} */",
            port.name,
            port.direction.as_str(),
            comment(&port.doc)
        );
        let p = format!("STEREOCAL_PORT_{}", port.name);
        for s in &port.signals {
            let _ = writeln!(o, "#define {p}_{}_WIDTH {}u", s.name, s.width);
        }
        for f in &port.fields {
            let _ = writeln!(o, "#define {p}_{}_SHIFT {}u", f.name, f.lsb);
            let _ = writeln!(o, "#define {p}_{}_WIDTH {}u", f.name, f.width());
            let _ = writeln!(o, "#define {p}_{}_MASK 0x{:08X}u", f.name, f.mask());
        }
    }
    o.push_str("\n#endif /* STEREOCAL_REGS_H */\n");
    o
}
