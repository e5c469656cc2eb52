//! `rtl/sc_regs.v`: the register block of the fabric, as synthesizable Verilog-2005.
//!
//! The module is the register file behind the fabric's AXI4-lite slave: a standard AXI4-lite
//! front end (not generated: it is the same for any map) turns the AW/W/B and AR/R channels
//! into the one-clock strobes of a simple synchronous bus:
//!
//! - `bus_we` (one clock) with `bus_addr` (byte offset) and `bus_wdata`: a write, applied at
//!   that rising edge. Whole words only (the front end ignores WSTRB, as the map's registers
//!   are written whole by the Rust and C drivers).
//! - `bus_re` (one clock) with `bus_addr`: a read; `bus_rdata` holds the word from the next
//!   clock on (registered) until the next read.
//!
//! Per field, by access type (`<reg>_<field>` in lower case):
//!
//! - `rw`: `output reg`, the stored value, reset to the field's reset by `rst`.
//! - `ro`: `input wire` from the fabric, sampled when read. VERSION is the exception: its
//!   fields are the constants of the map (the generator checks MAJOR/MINOR against the
//!   block's version), so it has no ports.
//! - `w1c`: `output reg`, the sticky flag(s); `input wire <reg>_<field>_set` from the fabric
//!   sets them (a set on the clock of a clearing write wins: no event is lost). A bus write
//!   clears the bits written 1; `flags_clear` (one clock, the fabric's soft reset) clears
//!   every flag.
//! - `wo`: `output reg`, high (the written value) for the one clock after a write to the
//!   register, 0 otherwise; reads 0.
//! - `pops_on_read` registers: their fields are `ro` inputs (the FIFO head), plus
//!   `output wire <reg>_pop`, high while `bus_re` addresses the register: the FIFO removes its
//!   head at the same rising edge at which `bus_rdata` captures it (a FIFO must ignore a pop
//!   while empty).
//!
//! Reserved bits read 0 and ignore writes; unmapped offsets read 0 and ignore writes.

use std::fmt::Write;

use crate::description::{Access, Description, Field, Register};
use crate::BANNER;

/// Name of the generated module (and file, `rtl/<name>.v`).
pub const MODULE: &str = "sc_regs";

/// The bus-side ports (and the flag clear), always present.
pub const BUS_PORTS: [&str; 8] = [
    "clk",
    "rst",
    "flags_clear",
    "bus_addr",
    "bus_wdata",
    "bus_we",
    "bus_re",
    "bus_rdata",
];

/// Registers whose value is the map's constant rather than a fabric input.
fn is_constant(r: &Register) -> bool {
    r.name == "VERSION"
}

fn port_base(r: &Register, f: &Field) -> String {
    format!("{}_{}", r.name, f.name).to_ascii_lowercase()
}

/// Internal names: decoded write and read strobes per register.
fn write_strobe(r: &Register) -> String {
    format!("wr_{}", r.name.to_ascii_lowercase())
}

fn read_strobe(r: &Register) -> String {
    format!("rd_{}", r.name.to_ascii_lowercase())
}

fn writable(r: &Register) -> bool {
    r.fields.iter().any(|f| f.access != Access::Ro)
}

/// Every identifier the module declares besides [`BUS_PORTS`], with what it comes from; the
/// description's collision check claims them, so no two can be equal.
pub fn identifiers(d: &Description) -> Vec<(String, String)> {
    let mut ids: Vec<(String, String)> = BUS_PORTS
        .iter()
        .map(|p| (p.to_string(), "sc_regs bus port".to_string()))
        .collect();
    ids.push(("word".to_string(), "sc_regs word index".to_string()));
    ids.push(("rdata_next".to_string(), "sc_regs read mux".to_string()));
    for r in &d.registers {
        let origin = format!("register {}", r.name);
        if writable(r) {
            ids.push((write_strobe(r), origin.clone()));
        }
        if r.pops_on_read {
            ids.push((read_strobe(r), origin.clone()));
            ids.push((
                format!("{}_pop", r.name.to_ascii_lowercase()),
                origin.clone(),
            ));
        }
        if is_constant(r) {
            continue;
        }
        for f in &r.fields {
            let forigin = format!("{origin} field {}", f.name);
            let base = port_base(r, f);
            if f.access == Access::W1c {
                ids.push((format!("{base}_set"), forigin.clone()));
            }
            ids.push((base, forigin));
        }
    }
    ids
}

/// `W'hV`, the field's width and value.
fn literal(width: u32, value: u32) -> String {
    format!("{width}'h{value:X}")
}

/// `[msb:lsb]` of a bus word, or `[bit]` for one bit.
fn slice(f: &Field) -> String {
    if f.msb == f.lsb {
        format!("[{}]", f.lsb)
    } else {
        format!("[{}:{}]", f.msb, f.lsb)
    }
}

/// `[W-1:0]` for a port declaration (blank for one bit), padded so the names line up.
fn range(width: u32) -> String {
    let r = if width == 1 {
        String::new()
    } else {
        format!("[{}:0]", width - 1)
    };
    format!("{r:<6}")
}

/// The word a read of `r` returns, as a concatenation from bit 31 down.
fn read_word(r: &Register) -> String {
    let mut parts = Vec::new();
    let mut next = 32u32; // first bit above what is still to place
    for f in r.fields.iter().rev() {
        if f.msb + 1 < next {
            parts.push(literal(next - f.msb - 1, 0));
        }
        let value = if is_constant(r) {
            literal(f.width(), f.reset)
        } else {
            match f.access {
                Access::Wo => literal(f.width(), 0),
                _ => port_base(r, f),
            }
        };
        parts.push(value);
        next = f.lsb;
    }
    if next > 0 {
        parts.push(literal(next, 0));
    }
    if parts.len() == 1 {
        parts.remove(0)
    } else {
        format!("{{{}}}", parts.join(", "))
    }
}

/// Bits of `bus_wdata` no writable field takes, for the lint waiver.
fn unused_wdata_bits(d: &Description) -> u32 {
    let used = d
        .registers
        .iter()
        .flat_map(|r| r.fields.iter())
        .filter(|f| f.access != Access::Ro)
        .fold(0u32, |m, f| m | f.mask());
    !used
}

pub fn emit(d: &Description) -> String {
    let b = &d.block;
    let ob = b.window_size.trailing_zeros().max(2);
    let word_bits = ob - 2;
    let mut o = String::new();
    let _ = writeln!(o, "// {BANNER}.");
    let _ = writeln!(
        o,
        "// Register block of `{}` (map version {}.{}): {}",
        b.name, b.version_major, b.version_minor, b.doc
    );
    o.push_str(
        "//
// The register file behind the fabric's AXI4-lite slave. A standard AXI4-lite front end turns
// the AW/W/B and AR/R channels into this simple synchronous bus (whole words; WSTRB ignored):
//   bus_we  one clock: write bus_wdata to byte offset bus_addr at this rising edge;
//   bus_re  one clock: read bus_addr; bus_rdata holds the word from the next clock on.
// `rst` (synchronous, active high; the front end drives it from !ARESETN) puts every stored
// field to its reset value.
//
// Ports per field, <register>_<field> in lower case, by access type:
//   rw    output reg   stored value
//   ro    input  wire  from the fabric, sampled when read (VERSION: constants, no ports)
//   w1c   output reg   sticky flag; input <reg>_<field>_set sets it (a set wins over a clearing
//                      write on the same clock); a bus write of 1 clears it, and flags_clear
//                      (one clock: the fabric's soft reset) clears every flag
//   wo    output reg   the written value for the one clock after a write, else 0; reads 0
//   pops_on_read registers: ro fields (the FIFO head) and output <reg>_pop, high while bus_re
//   addresses the register, so the FIFO removes the head at the edge bus_rdata captures it.
// Reserved bits and unmapped offsets read 0 and ignore writes.
",
    );
    o.push_str("`default_nettype none\n\n");
    let _ = writeln!(o, "module {MODULE} (");
    let mut ports: Vec<(String, String)> = vec![
        ("input  wire        clk".into(), String::new()),
        (
            "input  wire        rst".into(),
            "synchronous, active high".into(),
        ),
        (
            format!("input  wire {} bus_addr", range(ob)),
            "byte offset; bits [1:0] are ignored (aligned words)".into(),
        ),
        ("input  wire [31:0] bus_wdata".into(), String::new()),
        (
            "input  wire        bus_we".into(),
            "write strobe, one clock".into(),
        ),
        (
            "input  wire        bus_re".into(),
            "read strobe, one clock".into(),
        ),
        (
            "output reg  [31:0] bus_rdata".into(),
            "registered: the word read on the last bus_re".into(),
        ),
    ];
    let has_flags = d
        .registers
        .iter()
        .any(|r| r.fields.iter().any(|f| f.access == Access::W1c));
    if has_flags {
        ports.insert(
            2,
            (
                "input  wire        flags_clear".into(),
                "one clock: clear every w1c flag (a set on that clock wins)".into(),
            ),
        );
    }
    for r in &d.registers {
        if is_constant(r) {
            continue;
        }
        let pops = if r.pops_on_read { ", pops on read" } else { "" };
        let header = format!(
            "{} at 0x{:02X} ({}{pops})",
            r.name,
            r.offset,
            r.access.as_str()
        );
        let mut first = true;
        let mut push = |decl: String, comment: String, ports: &mut Vec<(String, String)>| {
            let comment = if first {
                first = false;
                format!("{header}: {comment}")
            } else {
                comment
            };
            ports.push((decl, comment));
        };
        for f in &r.fields {
            let base = port_base(r, f);
            let w = range(f.width());
            let bits = format!("[{}:{}]", f.msb, f.lsb);
            match f.access {
                Access::Rw => push(
                    format!("output reg  {w} {base}"),
                    format!("{bits} rw, reset {}", literal(f.width(), f.reset)),
                    &mut ports,
                ),
                Access::Ro => push(
                    format!("input  wire {w} {base}"),
                    format!("{bits} ro"),
                    &mut ports,
                ),
                Access::W1c => {
                    push(
                        format!("output reg  {w} {base}"),
                        format!("{bits} w1c flag"),
                        &mut ports,
                    );
                    push(
                        format!("input  wire {w} {base}_set"),
                        "sets the flag".to_string(),
                        &mut ports,
                    );
                }
                Access::Wo => push(
                    format!("output reg  {w} {base}"),
                    format!("{bits} wo strobe"),
                    &mut ports,
                ),
            }
        }
        if r.pops_on_read {
            push(
                format!(
                    "output wire {} {}_pop",
                    range(1),
                    r.name.to_ascii_lowercase()
                ),
                "remove the head at this edge".to_string(),
                &mut ports,
            );
        }
    }
    let last = ports.len() - 1;
    for (i, (decl, comment)) in ports.iter().enumerate() {
        let sep = if i == last { "" } else { "," };
        // Not every bit of the address and data reaches a register (see below).
        if decl.ends_with("bus_addr") {
            o.push_str("    /* verilator lint_off UNUSEDSIGNAL */\n");
        }
        if comment.is_empty() {
            let _ = writeln!(o, "    {decl}{sep}");
        } else {
            let _ = writeln!(o, "    {decl}{sep} // {comment}");
        }
        if decl.ends_with("bus_wdata") {
            o.push_str("    /* verilator lint_on UNUSEDSIGNAL */\n");
        }
    }
    o.push_str(");\n\n");
    let _ = writeln!(
        o,
        "    // bus_wdata bits no writable field takes: {:#010X}.",
        unused_wdata_bits(d)
    );
    let _ = writeln!(
        o,
        "    wire [{}:0] word = bus_addr[{}:2];",
        word_bits - 1,
        ob - 1
    );

    // Decoded strobes.
    o.push('\n');
    for r in &d.registers {
        let index = format!("{word_bits}'d{}", r.offset / 4);
        if writable(r) {
            let _ = writeln!(
                o,
                "    wire {} = bus_we && (word == {index}); // {}",
                write_strobe(r),
                r.name
            );
        }
        if r.pops_on_read {
            let _ = writeln!(
                o,
                "    wire {} = bus_re && (word == {index}); // {}",
                read_strobe(r),
                r.name
            );
            let _ = writeln!(
                o,
                "    assign {}_pop = {};",
                r.name.to_ascii_lowercase(),
                read_strobe(r)
            );
        }
    }

    // Stored fields.
    for r in &d.registers {
        if is_constant(r) || !writable(r) {
            continue;
        }
        let _ = writeln!(o, "\n    // {} (0x{:02X}): {}", r.name, r.offset, r.doc);
        let wr = write_strobe(r);
        for f in &r.fields {
            let base = port_base(r, f);
            let w = f.width();
            let reset = literal(w, f.reset);
            let bits = slice(f);
            match f.access {
                Access::Ro => {}
                Access::Rw => {
                    let _ = writeln!(o, "    always @(posedge clk) begin");
                    let _ = writeln!(o, "        if (rst) {base} <= {reset};");
                    let _ = writeln!(o, "        else if ({wr}) {base} <= bus_wdata{bits};");
                    let _ = writeln!(o, "    end");
                }
                Access::W1c => {
                    let _ = writeln!(o, "    always @(posedge clk) begin");
                    let _ = writeln!(o, "        if (rst) {base} <= {reset};");
                    let _ = writeln!(
                        o,
                        "        else {base} <= ({base} & ~(({wr} ? bus_wdata{bits} : {}) | {{{w}{{flags_clear}}}})) | {base}_set;",
                        literal(w, 0)
                    );
                    let _ = writeln!(o, "    end");
                }
                Access::Wo => {
                    let _ = writeln!(o, "    always @(posedge clk) begin");
                    let _ = writeln!(o, "        if (rst) {base} <= {};", literal(w, 0));
                    let _ = writeln!(
                        o,
                        "        else {base} <= {wr} ? bus_wdata{bits} : {};",
                        literal(w, 0)
                    );
                    let _ = writeln!(o, "    end");
                }
            }
        }
    }

    // Read mux.
    o.push_str("\n    // What a read returns, by word index.\n");
    o.push_str("    reg [31:0] rdata_next;\n");
    o.push_str("    always @(*) begin\n");
    o.push_str("        case (word)\n");
    for r in &d.registers {
        let _ = writeln!(
            o,
            "            {word_bits}'d{}: rdata_next = {}; // {}",
            r.offset / 4,
            read_word(r),
            r.name
        );
    }
    o.push_str("            default: rdata_next = 32'h0;\n");
    o.push_str("        endcase\n");
    o.push_str("    end\n\n");
    o.push_str("    always @(posedge clk) begin\n");
    o.push_str("        if (rst) bus_rdata <= 32'h0;\n");
    o.push_str("        else if (bus_re) bus_rdata <= rdata_next;\n");
    o.push_str("    end\n");
    o.push_str("endmodule\n\n`default_nettype wire\n");
    o
}
