//! One emitter per output language; each prints a checked [`crate::description::Description`].

pub mod c;
pub mod markdown;
pub mod rust;
pub mod rust_api;
pub mod verilog;
pub mod verilog_regs;

/// `0x4000_0000`-style hex with 16-bit groups, as Rust and the docs spell 32-bit words.
pub fn hex32_grouped(v: u32) -> String {
    format!("0x{:04X}_{:04X}", v >> 16, v & 0xFFFF)
}

/// `CONTROL` → `Control`, `SOBEL_OUTPUT` → `SobelOutput`.
pub fn camel_case(upper_snake: &str) -> String {
    upper_snake
        .split('_')
        .map(|word| {
            let mut chars = word.chars();
            match chars.next() {
                Some(first) => first.to_string() + &chars.as_str().to_ascii_lowercase(),
                None => String::new(),
            }
        })
        .collect()
}

/// Small values in decimal, large ones (codes, masks) in hex.
pub fn readable(v: u32) -> String {
    if v < 0x1000 {
        v.to_string()
    } else {
        format!("{v:#X}")
    }
}
