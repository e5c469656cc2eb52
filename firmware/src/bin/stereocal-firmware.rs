//! The soft-core program (`riscv32imc-unknown-none-elf`, QEMU `virt` machine).
//!
//! Boot, say Hello on the UART, then run the frames of the frame-grabber input region through
//! the fabric and the driver; exit through the `sifive_test` finisher. Build it with
//! `cargo build --release -p stereocal-firmware --target riscv32imc-unknown-none-elf`.
//!
//! On any other target this file builds a stub that says so, so that host builds of the whole
//! workspace (`cargo build --workspace`, clippy, tests) work without the bare-metal runtime.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "stereocal-firmware is the soft-core program; build it for the soft-core with\n  \
         cargo build --release -p stereocal-firmware --target riscv32imc-unknown-none-elf\n\
         and run the ELF under qemu-system-riscv32 -machine virt (see firmware/README.md)."
    );
    std::process::exit(2);
}

#[cfg(target_os = "none")]
mod soft_core {
    use stereocal_firmware::driver::PacketWriter;
    use stereocal_firmware::softcore::finisher::{self, ExitCode};
    use stereocal_firmware::softcore::frame_input::{
        FrameInput, VIRT_FRAME_REGION, VIRT_FRAME_REGION_LEN,
    };
    use stereocal_firmware::softcore::link::{Uart0, LINK};
    use stereocal_wire::{Capabilities, HelloRepr, PacketRepr, PROTOCOL_VERSION};

    #[riscv_rt::entry]
    fn main() -> ! {
        Uart0::device().init();
        let hello = PacketRepr::Hello(HelloRepr {
            version: PROTOCOL_VERSION,
            capabilities: Capabilities::POINTS | Capabilities::LOG,
        });
        critical_section::with(|cs| {
            let _ = LINK.borrow_ref_mut(cs).send(&hello);
        });
        // SAFETY: the region is RAM that nothing else writes while the firmware runs.
        let region = unsafe {
            core::slice::from_raw_parts(VIRT_FRAME_REGION as *const u8, VIRT_FRAME_REGION_LEN)
        };
        match FrameInput::new(region) {
            Ok(input) => defmt::error!("frames: {=u32}", input.header().frame_count),
            Err(e) => {
                defmt::error!("{}", defmt::Display2Format(&e));
                unsafe { finisher::exit(ExitCode::BadInput) }
            }
        }
        let _ = PacketWriter::new(Uart0);
        unsafe { finisher::exit(ExitCode::Success) }
    }
}
