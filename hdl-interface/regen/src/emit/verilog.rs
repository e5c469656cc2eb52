//! `generated/stereocal_regs.vh`: Verilog-2005 localparams, every name prefixed `SC_`.
//!
//! localparams are only legal inside a module, so the file is meant to be `include`d in a
//! module body and has no include guard (a guard would hide it from the second module of a
//! compilation unit).

use std::fmt::Write;

use crate::description::Description;
use crate::BANNER;

/// Bits needed for a byte offset inside the window.
fn offset_bits(window_size: u32) -> u32 {
    window_size.trailing_zeros().max(1)
}

pub fn emit(d: &Description) -> String {
    let mut o = String::new();
    let b = &d.block;
    let ob = offset_bits(b.window_size);
    let _ = writeln!(o, "// {BANNER}.");
    let _ = writeln!(o, "// Register map of `{}`: {}", b.name, b.doc);
    o.push_str("// Include inside a module body: `include \"stereocal_regs.vh\"\n");
    o.push_str("// Offsets are bytes from SC_BASE_ADDR; *_MASK values are already shifted.\n");
    o.push_str("// verilator lint_off UNUSEDPARAM\n");
    let _ = writeln!(
        o,
        "localparam [31:0] SC_BASE_ADDR = 32'h{:08X};",
        b.base_address
    );
    let _ = writeln!(o, "localparam integer SC_WINDOW_SIZE = {};", b.window_size);
    let _ = writeln!(o, "localparam integer SC_OFFSET_BITS = {ob};");
    let _ = writeln!(
        o,
        "localparam integer SC_REGISTER_WIDTH = {};",
        b.register_width
    );
    let _ = writeln!(
        o,
        "localparam [7:0] SC_VERSION_MAJOR = 8'd{};",
        b.version_major
    );
    let _ = writeln!(
        o,
        "localparam [7:0] SC_VERSION_MINOR = 8'd{};",
        b.version_minor
    );
    for (name, value) in &d.params {
        let _ = writeln!(
            o,
            "localparam integer SC_{} = {value};",
            name.to_ascii_uppercase()
        );
    }
    for r in &d.registers {
        o.push('\n');
        let pops = if r.pops_on_read { ", read pops" } else { "" };
        let _ = writeln!(o, "// {} ({}{pops}): {}", r.name, r.access.as_str(), r.doc);
        let p = format!("SC_{}", r.name);
        let _ = writeln!(
            o,
            "localparam [{}:0] {p}_OFFSET = {ob}'h{:02X};",
            ob - 1,
            r.offset
        );
        let _ = writeln!(o, "localparam [31:0] {p}_RESET = 32'h{:08X};", r.reset);
        for f in &r.fields {
            let fp = format!("{p}_{}", f.name);
            let range = if f.has_range {
                format!(", valid {}..{}", f.min, f.max)
            } else {
                String::new()
            };
            let _ = writeln!(
                o,
                "// [{}:{}] {}{range}: {}",
                f.msb,
                f.lsb,
                f.access.as_str(),
                f.doc
            );
            let _ = writeln!(o, "localparam integer {fp}_LSB = {};", f.lsb);
            let _ = writeln!(o, "localparam integer {fp}_MSB = {};", f.msb);
            let _ = writeln!(o, "localparam integer {fp}_WIDTH = {};", f.width());
            let _ = writeln!(o, "localparam [31:0] {fp}_MASK = 32'h{:08X};", f.mask());
            let w = f.width();
            let _ = writeln!(
                o,
                "localparam [{}:0] {fp}_RESET = {w}'h{:X};",
                w - 1,
                f.reset
            );
            for e in &f.enums {
                let _ = writeln!(
                    o,
                    "localparam [{}:0] {fp}_{} = {w}'d{}; // {}",
                    w - 1,
                    e.name,
                    e.value,
                    e.doc
                );
            }
        }
    }
    for port in &d.ports {
        o.push('\n');
        let _ = writeln!(
            o,
            "// Stream port {} ({}): {}",
            port.name,
            port.direction.as_str(),
            port.doc
        );
        let p = format!("SC_{}", port.name);
        for s in &port.signals {
            let _ = writeln!(
                o,
                "localparam integer {p}_{}_WIDTH = {}; // {}: {}",
                s.name,
                s.width,
                s.direction.as_str(),
                s.doc
            );
        }
        for f in &port.fields {
            let _ = writeln!(o, "// DATA[{}:{}]: {}", f.msb, f.lsb, f.doc);
            let _ = writeln!(o, "localparam integer {p}_{}_LSB = {};", f.name, f.lsb);
            let _ = writeln!(o, "localparam integer {p}_{}_MSB = {};", f.name, f.msb);
            let _ = writeln!(
                o,
                "localparam integer {p}_{}_WIDTH = {};",
                f.name,
                f.width()
            );
        }
    }
    o.push_str("// verilator lint_on UNUSEDPARAM\n");
    o
}
