//! The release firmware ELF links no panicking path: no `core::panicking::*`, no slice-index
//! or `copy_from_slice` length failure, no `unwrap_failed`/`expect_failed`, no
//! `RefCell` borrow panic and no panic handler (`rust_begin_unwind`). With no call into
//! any of them, the linker's `--gc-sections` drops the handler too, which is the proof that
//! no input (a pixel, a link byte, a register value) can make the firmware panic.
//!
//! Builds the ELF like the QEMU tests do ([`stereocal_hil::firmware_elf_or_skip`]), reads its symbol
//! table with `object`, and decodes every function's RV32IMC calls and jumps (`jal`,
//! `auipc`+`jalr`, `c.jal`, `c.j`, branches) to name the callers of each panicking symbol in
//! the failure message, with the project source line the call was inlined from (DWARF inline
//! records, read with `gimli`). Run: `cargo test --release -p stereocal-hil --test
//! firmware_panic_free -- --nocapture`.
//!
//! Calls made by the handler's own formatting (into `rust_begin_unwind` or `PanicInfo`'s
//! `Display`) are not entry points and are not listed as callers; the test still requires that
//! no panicking symbol is present at all.

use std::collections::BTreeMap;

use object::{Object, ObjectSection, ObjectSymbol, SymbolKind};

#[test]
fn firmware_panic_free() {
    let Some(elf) = stereocal_hil::firmware_elf_or_skip("firmware_panic_free") else {
        return;
    };
    let data = std::fs::read(&elf).unwrap_or_else(|e| panic!("{}: {e}", elf.display()));
    let report = PanicReport::of(&data);
    eprintln!("{}", report.summary());
    let offending = report.offending();
    assert!(
        offending.is_empty(),
        "{} links panicking paths:\n{}",
        elf.display(),
        offending.join("\n")
    );
    assert!(report.panicking.is_empty(), "{}", report.summary());
}

/// One function of the ELF.
struct Function {
    addr: u64,
    size: u64,
    name: String,
}

/// The panicking symbols of an ELF and the calls into them.
struct PanicReport {
    /// Panicking symbol name -> calls into it.
    panicking: BTreeMap<String, Vec<Call>>,
}

/// One call into a panicking symbol.
struct Call {
    /// The function containing the call instruction.
    caller: String,
    /// The call instruction's address.
    at: u64,
    /// The innermost project source line the call was inlined from (`path:line`), if the
    /// DWARF inline records name one.
    source: Option<String>,
}

impl PanicReport {
    fn of(data: &[u8]) -> Self {
        let file = object::File::parse(data).expect("the firmware ELF parses");
        let mut functions: Vec<Function> = file
            .symbols()
            .filter(|s| s.kind() == SymbolKind::Text && s.size() > 0)
            .filter_map(|s| {
                Some(Function {
                    addr: s.address(),
                    size: s.size(),
                    name: demangle(s.name().ok()?),
                })
            })
            .collect();
        functions.sort_by_key(|f| f.addr);
        functions.dedup_by_key(|f| f.addr);
        let by_addr: BTreeMap<u64, &str> = functions
            .iter()
            .map(|f| (f.addr, f.name.as_str()))
            .collect();

        let inlines = Inlines::of(&file);
        let mut panicking: BTreeMap<String, Vec<Call>> = functions
            .iter()
            .filter(|f| is_panicking(&f.name))
            .map(|f| (f.name.clone(), Vec::new()))
            .collect();

        for f in &functions {
            let Some(bytes) = function_bytes(&file, f) else {
                continue;
            };
            for (at, target) in control_transfers(f.addr, bytes) {
                if let Some(callee) = by_addr.get(&target) {
                    if let Some(calls) = panicking.get_mut(*callee) {
                        calls.push(Call {
                            caller: f.name.clone(),
                            at,
                            source: inlines.project_source(at),
                        });
                    }
                }
            }
        }
        Self { panicking }
    }

    /// Every panicking symbol reached from a function that is not panic machinery, with its
    /// callers; and every panicking symbol with no call at all (referenced some other way, so
    /// the decoding cannot vouch for it).
    fn offending(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (symbol, calls) in &self.panicking {
            if calls.is_empty() {
                out.push(format!("  {symbol}: present, but no decoded call into it"));
                continue;
            }
            if handler_internal(symbol) {
                continue;
            }
            let roots: Vec<&Call> = self.roots(calls).collect();
            if !roots.is_empty() {
                out.push(format!("  {symbol}, called from:"));
                for call in roots {
                    out.push(format!("    {call}"));
                }
            }
        }
        out
    }

    /// The calls into a symbol from outside the panic machinery.
    fn roots<'a>(&'a self, calls: &'a [Call]) -> impl Iterator<Item = &'a Call> + 'a {
        calls
            .iter()
            .filter(|call| !self.panicking.contains_key(&call.caller))
    }

    fn summary(&self) -> String {
        let roots: Vec<&Call> = self
            .panicking
            .iter()
            .filter(|(symbol, _)| !handler_internal(symbol))
            .flat_map(|(_, calls)| self.roots(calls))
            .collect();
        let mut out = format!(
            "firmware_panic_free: {} panicking symbols, {} call sites into them from outside \
             the panic machinery",
            self.panicking.len(),
            roots.len()
        );
        for (symbol, calls) in &self.panicking {
            out.push_str(&format!("\n  {symbol} ({} calls)", calls.len()));
        }
        out.push_str("\n  call sites:");
        for call in roots {
            out.push_str(&format!("\n    {call}"));
        }
        out
    }
}

impl std::fmt::Display for Call {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:#010x} {}", self.at, self.caller)?;
        if let Some(source) = &self.source {
            write!(f, " ({source})")?;
        }
        Ok(())
    }
}

/// Symbols only the panic handler reaches (through `panic_fmt`): not entry points.
fn handler_internal(symbol: &str) -> bool {
    symbol.contains("rust_begin_unwind") || symbol.contains("panic_info")
}

/// The DWARF inline records of the ELF: which inlined call covers which addresses.
struct Inlines {
    /// (start, end, nesting depth, call site `path:line`).
    records: Vec<(u64, u64, isize, String)>,
}

type Reader<'a> = gimli::EndianSlice<'a, gimli::LittleEndian>;

impl Inlines {
    fn of(file: &object::File<'_>) -> Self {
        let load = |id: gimli::SectionId| -> Result<Reader<'_>, gimli::Error> {
            let data = file
                .section_by_name(id.name())
                .and_then(|s| s.data().ok())
                .unwrap_or(&[]);
            Ok(gimli::EndianSlice::new(data, gimli::LittleEndian))
        };
        let mut records = Vec::new();
        // Without debug info the failure message has no source lines, nothing else changes.
        let _ = Self::read(&load, &mut records);
        Self { records }
    }

    fn read<'a>(
        load: &dyn Fn(gimli::SectionId) -> Result<Reader<'a>, gimli::Error>,
        records: &mut Vec<(u64, u64, isize, String)>,
    ) -> Result<(), gimli::Error> {
        let dwarf = gimli::Dwarf::load(load)?;
        let mut units = dwarf.units();
        while let Some(header) = units.next()? {
            let unit = dwarf.unit(header)?;
            let mut entries = unit.entries();
            let mut depth = 0isize;
            while let Some((delta, entry)) = entries.next_dfs()? {
                depth += delta;
                if entry.tag() != gimli::DW_TAG_inlined_subroutine {
                    continue;
                }
                let Some(gimli::AttributeValue::FileIndex(index)) =
                    entry.attr_value(gimli::DW_AT_call_file)?
                else {
                    continue;
                };
                let Some(path) = file_path(&dwarf, &unit, index) else {
                    continue;
                };
                let line = match entry.attr_value(gimli::DW_AT_call_line)? {
                    Some(gimli::AttributeValue::Udata(line)) => line,
                    _ => 0,
                };
                let site = format!("{path}:{line}");
                let mut ranges = dwarf.die_ranges(&unit, entry)?;
                while let Some(range) = ranges.next()? {
                    records.push((range.begin, range.end, depth, site.clone()));
                }
            }
        }
        Ok(())
    }

    /// The innermost inlined call covering `at` that sits in project code (not the Rust
    /// library or a registry crate), relative to the workspace.
    fn project_source(&self, at: u64) -> Option<String> {
        let mut covering: Vec<&(u64, u64, isize, String)> = self
            .records
            .iter()
            .filter(|(start, end, _, _)| (*start..*end).contains(&at))
            .collect();
        covering.sort_by_key(|(_, _, depth, _)| std::cmp::Reverse(*depth));
        covering
            .into_iter()
            .map(|(_, _, _, site)| site)
            .find(|site| {
                !site.contains("/rustc/")
                    && !site.contains("/.cargo/registry/")
                    && !site.contains("/library/")
            })
            .map(|site| {
                let workspace = concat!(env!("CARGO_MANIFEST_DIR"), "/../");
                site.strip_prefix(workspace)
                    .or_else(|| site.split_once("/work/main/").map(|(_, rest)| rest))
                    .unwrap_or(site)
                    .to_string()
            })
    }
}

/// The path of file `index` of `unit`'s line program.
fn file_path(
    dwarf: &gimli::Dwarf<Reader<'_>>,
    unit: &gimli::Unit<Reader<'_>>,
    index: u64,
) -> Option<String> {
    let header = unit.line_program.as_ref()?.header();
    let file = header.file(index)?;
    let mut path = String::new();
    if let Some(dir) = file.directory(header) {
        path.push_str(&dwarf.attr_string(unit, dir).ok()?.to_string_lossy());
        path.push('/');
    }
    path.push_str(
        &dwarf
            .attr_string(unit, file.path_name())
            .ok()?
            .to_string_lossy(),
    );
    Some(path)
}

/// Whether a demangled symbol is one of core's panicking functions or the panic handler.
fn is_panicking(name: &str) -> bool {
    if name.contains("rust_begin_unwind") {
        return true;
    }
    if !name.starts_with("core::") && !name.starts_with("<core::") {
        return false;
    }
    name.split("::").any(|ident| {
        let ident = ident.trim_matches(|c| c == '<' || c == '>');
        ident == "panicking"
            || ident == "panic_info"
            || ident.starts_with("panic_")
            || ident.ends_with("_fail")
            || ident.ends_with("_failed")
    })
}

/// A function's bytes in its section.
fn function_bytes<'a>(file: &object::File<'a>, f: &Function) -> Option<&'a [u8]> {
    let section = file.sections().find(|s| {
        s.address() <= f.addr && f.addr + f.size <= s.address() + s.size() && s.size() > 0
    })?;
    let data = section.data().ok()?;
    let start = usize::try_from(f.addr - section.address()).ok()?;
    data.get(start..start + usize::try_from(f.size).ok()?)
}

/// Every direct call, jump and branch in RV32IMC code at `base`, as (address, target).
/// `auipc rd` followed later in the function by `jalr rs1 = rd` is a far call or tail call.
fn control_transfers(base: u64, bytes: &[u8]) -> Vec<(u64, u64)> {
    let mut out = Vec::new();
    let mut auipc: [Option<u64>; 32] = [None; 32];
    let mut at = 0usize;
    while at + 2 <= bytes.len() {
        let pc = base + at as u64;
        let low = u16::from_le_bytes([bytes[at], bytes[at + 1]]);
        if low & 0b11 != 0b11 {
            at += 2;
            if low & 0b11 == 0b01 {
                let funct3 = low >> 13;
                let bit = |i: u32| i64::from((low >> i) & 1);
                match funct3 {
                    // c.jal (RV32 only) and c.j
                    0b001 | 0b101 => {
                        let imm = (bit(12) << 11)
                            | (bit(11) << 4)
                            | (bit(10) << 9)
                            | (bit(9) << 8)
                            | (bit(8) << 10)
                            | (bit(7) << 6)
                            | (bit(6) << 7)
                            | (bit(5) << 3)
                            | (bit(4) << 2)
                            | (bit(3) << 1)
                            | (bit(2) << 5);
                        out.push((pc, offset(pc, sign_extend(imm, 12))));
                    }
                    // c.beqz, c.bnez
                    0b110 | 0b111 => {
                        let imm = (bit(12) << 8)
                            | (bit(11) << 4)
                            | (bit(10) << 3)
                            | (bit(6) << 7)
                            | (bit(5) << 6)
                            | (bit(4) << 2)
                            | (bit(3) << 1)
                            | (bit(2) << 5);
                        out.push((pc, offset(pc, sign_extend(imm, 9))));
                    }
                    _ => {}
                }
            }
            continue;
        }
        if at + 4 > bytes.len() {
            break;
        }
        let word = u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
        at += 4;
        let bits = |hi: u32, lo: u32| i64::from((word >> lo) & ((1 << (hi - lo + 1)) - 1));
        let rd = ((word >> 7) & 31) as usize;
        let rs1 = ((word >> 15) & 31) as usize;
        match word & 0x7f {
            // jal
            0x6f => {
                let imm = (bits(31, 31) << 20)
                    | (bits(19, 12) << 12)
                    | (bits(20, 20) << 11)
                    | (bits(30, 21) << 1);
                out.push((pc, offset(pc, sign_extend(imm, 21))));
            }
            // auipc
            0x17 => {
                auipc[rd] = Some(offset(pc, i64::from(word & 0xffff_f000) << 32 >> 32));
                continue;
            }
            // jalr
            0x67 => {
                if let Some(upper) = auipc[rs1] {
                    out.push((pc, offset(upper, sign_extend(bits(31, 20), 12))));
                }
            }
            // branches
            0x63 => {
                let imm = (bits(31, 31) << 12)
                    | (bits(7, 7) << 11)
                    | (bits(30, 25) << 5)
                    | (bits(11, 8) << 1);
                out.push((pc, offset(pc, sign_extend(imm, 13))));
            }
            _ => {}
        }
        if rd != 0 {
            auipc[rd] = None;
        }
    }
    out
}

fn sign_extend(value: i64, bits: u32) -> i64 {
    let shift = 64 - bits;
    (value << shift) >> shift
}

/// `base + delta` in the 32-bit address space.
fn offset(base: u64, delta: i64) -> u64 {
    (base as i64).wrapping_add(delta) as u64 & 0xffff_ffff
}

/// A readable path for legacy (`_ZN…E`) and v0 (`_R…`) Rust symbols: the identifiers joined
/// by `::` (v0 generic arguments and back-references are dropped); other names unchanged.
fn demangle(raw: &str) -> String {
    let (body, v0) = if let Some(rest) = raw.strip_prefix("_ZN") {
        (rest.strip_suffix('E').unwrap_or(rest), false)
    } else if let Some(rest) = raw.strip_prefix("_R") {
        (rest, true)
    } else {
        return raw.to_string();
    };
    let b = body.as_bytes();
    let mut idents: Vec<String> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let start = i;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
            let n: usize = body[start..i].parse().unwrap_or(0);
            if v0 && b.get(i) == Some(&b'_') {
                i += 1;
            }
            let end = (i + n).min(b.len());
            idents.push(body[i..end].to_string());
            i = end;
        } else if v0 && (b[i] == b's' || b[i] == b'B') {
            // disambiguator `s<base62>_` or back-reference `B<base62>_`
            let mut j = i + 1;
            while j < b.len() && b[j].is_ascii_alphanumeric() {
                j += 1;
            }
            i = if b.get(j) == Some(&b'_') {
                j + 1
            } else {
                i + 1
            };
        } else {
            i += 1;
        }
    }
    // Legacy hashes (`h` and 16 hex digits) and what follows the closing `E` (`.llvm.…`).
    idents.retain(|ident| {
        let hash = ident.len() == 17
            && ident.starts_with('h')
            && ident[1..].bytes().all(|c| c.is_ascii_hexdigit());
        !ident.is_empty() && !hash
    });
    let joined = idents.join("::");
    // Legacy mangling escapes a leading `<` as `_$LT$`.
    let joined = match joined.strip_prefix("_<") {
        Some(rest) => format!("<{rest}"),
        None => joined,
    };
    [
        ("$LT$", "<"),
        ("$GT$", ">"),
        ("$RF$", "&"),
        ("$BP$", "*"),
        ("$C$", ","),
        ("$u20$", " "),
        ("$u27$", "'"),
        ("$u5b$", "["),
        ("$u5d$", "]"),
        ("$u7b$", "{"),
        ("$u7d$", "}"),
        ("$u7e$", "~"),
        ("..", "::"),
    ]
    .iter()
    .fold(joined, |s, (from, to)| s.replace(from, to))
}
