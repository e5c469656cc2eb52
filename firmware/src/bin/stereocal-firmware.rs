//! The soft-core program (`riscv32imc-unknown-none-elf`, QEMU `virt` machine).
//!
//! 1. Boot: check the frame-grabber input region (`softcore::frame_input`), program each
//!    camera channel's WIDTH/HEIGHT from it.
//! 2. If the input asks to autostart, announce the device with `Hello` and start. Otherwise
//!    answer the host's packets (`Hello`, `RegisterRead`, `RegisterWrite`; writes go to every
//!    channel, reads are answered from the left one) until the host sets `CONTROL.ENABLE`.
//!    The host speaks first there, so it gets one `Hello`, the answer to its own, and the
//!    stream is byte for byte what the in-process device sends (apart from the `LOG`
//!    capability bit in that `Hello`).
//! 3. For every frame of the input, left then right image: the driver runs the image through
//!    the fabric's device model, on its registers and PIXEL_IN port, and the model's stream
//!    engine sends the frame's packets on the UART. Host packets waiting between frames are
//!    answered; clearing `CONTROL.ENABLE` pauses before the next frame. With
//!    `FLAG_COUNT_INSTRUCTIONS` each image's instruction counts follow as a log packet, and
//!    after the last frame the row kernels' counts on the first image
//!    (`softcore::instructions`), preceded by the main loop's stack high-water mark
//!    (`softcore::stack`: the free stack is painted as soon as the input says to count).
//! 4. Exit through the `sifive_test` finisher: 0 when every frame ran, 2 for a bad input
//!    region, 3 when a frame failed (an `ErrorReport` says why), 4 on a trap
//!    (`softcore::trap`), 101 on a panic.
//!
//! Build: `cargo build --release -p stereocal-firmware --target riscv32imc-unknown-none-elf`.
//! Run: see the `softcore` module of the library (QEMU command line, link protocol). On any other target this file builds a stub that says so,
//! so host builds of the whole workspace (build, clippy, tests) need no bare-metal runtime.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "stereocal-firmware is the soft-core program; build it for the soft-core with\n  \
         cargo build --release -p stereocal-firmware --target riscv32imc-unknown-none-elf\n\
         and run the ELF under qemu-system-riscv32 -machine virt (see the docs of\n\
         stereocal_firmware::softcore)."
    );
    std::process::exit(2);
}

#[cfg(target_os = "none")]
mod soft_core {
    use stereocal_firmware::driver::{Driver, DriverError};
    use stereocal_firmware::fabric::{FabricDevice, FabricModel};
    use stereocal_firmware::framing::PacketWriter;
    use stereocal_firmware::softcore::finisher::{self, ExitCode};
    use stereocal_firmware::softcore::frame_input::{
        FrameInput, InputHeader, FLAG_AUTOSTART, FLAG_COUNT_INSTRUCTIONS, FLAG_REGISTER_MODEL,
        FLAG_WIRED_CAMERAS, VIRT_FRAME_REGION, VIRT_FRAME_REGION_LEN,
    };
    use stereocal_firmware::softcore::instructions::{self, CountedFabric, InstructionReport};
    use stereocal_firmware::softcore::link::{Uart0, LINK};
    use stereocal_firmware::softcore::soc::ImageReport;
    use stereocal_firmware::softcore::stack::{self, StackReport};
    use stereocal_firmware::softcore::wired::{ChannelFabric, ModelFabric, WiredFabric};
    use stereocal_hdl::regs::{control, height, width};
    use stereocal_wire::{
        Accumulator, Camera, Capabilities, ErrorCode, ErrorReportRepr, FeedResult, HelloRepr,
        PacketRepr, PROTOCOL_VERSION,
    };

    /// One camera channel: the driver, on the registers and PIXEL_IN port of the fabric's
    /// device model (everything the model does counted in instructions), whose stream engine
    /// sends on the UART as the fabric's LINK_OUT would; or, on the SoC in the loop with
    /// wired cameras, on the real fabric's registers at MMIO. The driver reaches either only
    /// through the register bus.
    type Channel<F> = Driver<F>;

    /// Host packets are short (a RegisterWrite is 16 framed bytes); a longer frame is refused.
    type HostAccumulator = Accumulator<64>;

    /// Sends a packet through the shared link writer.
    fn send(packet: &PacketRepr<'_>) {
        with_link(|link| {
            // Every packet built here is within the wire limits; a failure would be a bug
            // that the host sees as a missing packet.
            let _ = link.send(packet);
        });
    }

    fn report(code: ErrorCode, detail: u32) {
        send(&PacketRepr::ErrorReport(ErrorReportRepr { code, detail }));
    }

    /// Runs `f` with the link writer borrowed.
    ///
    /// Only this main loop borrows [`LINK`] outright, never nested; the logger merely tries
    /// (and counts a log it could not send), so the borrow is never refused. Were it refused,
    /// the firmware stops with the status of a firmware bug instead of panicking.
    fn with_link<R>(f: impl FnOnce(&mut PacketWriter<Uart0>) -> R) -> R {
        critical_section::with(|cs| match LINK.borrow(cs).try_borrow_mut() {
            Ok(mut link) => f(&mut link),
            Err(_) => stop(ExitCode::Panic),
        })
    }

    fn stop(code: ExitCode) -> ! {
        // SAFETY: this program only runs on QEMU `virt`, which has the finisher.
        unsafe { finisher::exit(code) }
    }

    /// A channel for `camera` on the device model.
    fn model_channel(header: &InputHeader, camera: Camera) -> Channel<ModelFabric> {
        let model = if header.has_flag(FLAG_REGISTER_MODEL) {
            FabricModel::register_level()
        } else {
            FabricModel::fast()
        };
        let fabric = CountedFabric::new(FabricDevice::with_link(model, Uart0::new()));
        configured(header, Driver::new(fabric, camera))
    }

    /// A channel for `camera` on the real fabric of the SoC in the loop.
    fn wired_channel(header: &InputHeader, camera: Camera) -> Channel<WiredFabric> {
        // SAFETY: the input says the board is the SoC in the loop, whose bus has each
        // camera's fabric where `WiredFabric` looks.
        let fabric = unsafe { WiredFabric::new(u8::from(camera).into()) };
        configured(header, Driver::new(fabric, camera))
    }

    /// `channel` with the soft-core's capabilities, WIDTH/HEIGHT matching the input frames and,
    /// when the input asks to autostart, CONTROL.ENABLE set.
    fn configured<F: ChannelFabric>(header: &InputHeader, channel: Channel<F>) -> Channel<F> {
        let mut channel = channel.with_capabilities(Capabilities::LOG);
        let bus = channel.bus_mut();
        let geometry = bus
            .write_field(&width::VALUE, header.width.into())
            .and_then(|()| bus.write_field(&height::VALUE, header.height.into()));
        if let Err(e) = geometry {
            defmt::error!("input frames: {}", defmt::Display2Format(&e));
            report(ErrorCode::InvalidConfig, width::OFFSET.into());
            stop(ExitCode::BadInput);
        }
        if header.has_flag(FLAG_AUTOSTART) {
            channel.write_register(control::OFFSET, control::ENABLE.mask());
        }
        channel
    }

    /// Answers every host packet received so far; with `wait`, also waits for more packets
    /// while CONTROL.ENABLE is 0.
    fn serve_host<F: ChannelFabric>(
        acc: &mut HostAccumulator,
        channels: &mut [Channel<F>],
        last_good_seq: &mut u16,
        wait: bool,
    ) {
        // `FrameInput::new` checked that there are 1 or 2 cameras.
        let Some((first, others)) = channels.split_first_mut() else {
            return;
        };
        loop {
            let byte = match Uart0::device().try_read_byte() {
                Some(byte) => byte,
                None if wait && first.bus_mut().read_field(&control::ENABLE) == 0 => {
                    core::hint::spin_loop();
                    continue;
                }
                None => return,
            };
            match acc.feed(&[byte]) {
                FeedResult::Consumed => {}
                FeedResult::OverFull(_) => report(ErrorCode::BadPacket, (*last_good_seq).into()),
                FeedResult::DecodeError { .. } => {
                    report(ErrorCode::BadPacket, (*last_good_seq).into())
                }
                FeedResult::Success { header, packet, .. } => {
                    *last_good_seq = header.seq;
                    if let PacketRepr::RegisterWrite(w) = packet {
                        for other in others.iter_mut() {
                            other.write_register(w.addr, w.value);
                        }
                    }
                    let answered = with_link(|link| first.handle_host_packet(&packet, link));
                    if let Err(e) = answered {
                        let (code, detail) = e.report();
                        report(code, detail);
                    }
                    if let PacketRepr::Hello(_) = packet {
                        // Every channel's frames share the link the Hello set up.
                        let fec = with_link(|link| link.fec());
                        for other in others.iter_mut() {
                            if let Err(e) = other.set_fec(fec) {
                                let (code, detail) = e.report();
                                report(code, detail);
                            }
                        }
                    }
                }
            }
        }
    }

    #[riscv_rt::entry]
    fn main() -> ! {
        Uart0::device().init();
        // SAFETY: the region is RAM above the program (memory.x) that nothing writes while the
        // firmware runs; QEMU's loader filled it before the hart started.
        let region = unsafe {
            core::slice::from_raw_parts(VIRT_FRAME_REGION as *const u8, VIRT_FRAME_REGION_LEN)
        };
        let input = match FrameInput::new(region) {
            Ok(input) => input,
            Err(e) => {
                send(&hello());
                defmt::error!("{}", defmt::Display2Format(&e));
                stop(ExitCode::BadInput);
            }
        };
        let header = *input.header();
        // The stack is measured only for the instruction-count report: painting megabytes of
        // free stack costs a slow core (the SoC in the loop) millions of clocks.
        let measure_stack = header.has_flag(FLAG_COUNT_INSTRUCTIONS);
        if measure_stack {
            stack::paint();
        }
        if header.has_flag(FLAG_WIRED_CAMERAS) {
            let channels = [
                wired_channel(&header, Camera::Left),
                wired_channel(&header, Camera::Right),
            ];
            run(&input, channels)
        } else {
            let channels = [
                model_channel(&header, Camera::Left),
                model_channel(&header, Camera::Right),
            ];
            run(&input, channels)
        }
    }

    /// Runs every frame of `input` through `channels`, then stops the machine.
    fn run<F: ChannelFabric>(input: &FrameInput<'_>, mut channels: [Channel<F>; 2]) -> ! {
        let header = *input.header();
        let measure_stack = header.has_flag(FLAG_COUNT_INSTRUCTIONS);
        let wired = header.has_flag(FLAG_WIRED_CAMERAS);
        // Boot is the deepest the stack goes (the channels are built by value); paint again
        // so that the mark after the frames is the main loop's own.
        let (boot_stack, _) = stack::high_water();
        if measure_stack {
            stack::paint();
        }
        // `FrameInput::new` checked that there are 1 or 2 cameras.
        let Some(channels) = channels.get_mut(..usize::from(header.cameras)) else {
            stop(ExitCode::BadInput);
        };
        if header.has_flag(FLAG_AUTOSTART) {
            send(&hello());
        }

        let mut acc = HostAccumulator::new();
        let mut last_good_seq = 0;
        let mut failed = false;
        for frame in 0..header.frame_count {
            serve_host(&mut acc, channels, &mut last_good_seq, true);
            for (camera, channel) in channels.iter_mut().enumerate() {
                let Some(image) = input.image(frame, camera as u8) else {
                    // `FrameInput::new` checked that every image is in the region.
                    stop(ExitCode::BadInput);
                };
                channel.bus().take_counted();
                channel.bus_mut().take_link_waited();
                with_link(|link| link.sink_mut().take_waited());
                channel.bus_mut().take_wait_cycles();
                let start = instructions::instret();
                let start_cycle = riscv::register::mcycle::read64();
                let result = channel.process_frame(image.pixels, image.timestamp_us);
                let spent = instructions::instret().wrapping_sub(start);
                let cycles = riscv::register::mcycle::read64().wrapping_sub(start_cycle);
                if let (Ok(summary), true) = (&result, wired) {
                    let waited = channel.bus_mut().take_wait_cycles();
                    let report = ImageReport {
                        frame: summary.frame_id,
                        camera: camera as u8,
                        softcore_cycles: u32::try_from(cycles.wrapping_sub(waited))
                            .unwrap_or(u32::MAX),
                        busy_wait_cycles: u32::try_from(waited).unwrap_or(u32::MAX),
                        point_overflows: summary.overflow.points,
                        sobel_overflows: summary.overflow.sobel,
                    };
                    // SAFETY: `wired`: the board is the SoC in the loop, which has the port.
                    unsafe { report.write() };
                }
                // The stream engine's waits for the transmitter are inside the fabric's count.
                let link_wait = channel.bus_mut().take_link_waited();
                match result {
                    Ok(summary) if header.has_flag(FLAG_COUNT_INSTRUCTIONS) => {
                        let front_end = channel.bus().take_counted().wrapping_sub(link_wait);
                        let uart_wait =
                            with_link(|link| link.sink_mut().take_waited()).wrapping_add(link_wait);
                        instructions::log(&InstructionReport {
                            frame: summary.frame_id,
                            camera: camera as u8,
                            pixels: image.pixels.len() as u32,
                            front_end,
                            driver: spent.wrapping_sub(front_end).wrapping_sub(uart_wait),
                            uart_wait,
                        })
                    }
                    Ok(_) => {}
                    Err(e) => {
                        failed = true;
                        report_frame_error(&e);
                    }
                }
            }
        }
        if header.has_flag(FLAG_COUNT_INSTRUCTIONS) {
            // Before the row-kernel measurement, whose buffers are not the main loop's.
            let (main_loop, region) = stack::high_water();
            stack::log(&StackReport {
                boot: boot_stack,
                main_loop,
                region,
            });
            let kernels = input
                .image(0, 0)
                .and_then(|image| instructions::measure_kernels(image.pixels, header.width.into()));
            if let Some(report) = kernels {
                instructions::log_kernels(&report);
            }
        }
        let dropped_logs = stereocal_firmware::softcore::dropped_logs();
        if dropped_logs > 0 {
            defmt::error!(
                "{=u32} log frames were too long or hit a busy link",
                dropped_logs
            );
        }
        stop(if failed {
            ExitCode::FrameFailed
        } else {
            ExitCode::Success
        })
    }

    fn report_frame_error(e: &DriverError) {
        let (code, detail) = e.report();
        report(code, detail);
        defmt::error!("frame failed: {}", defmt::Display2Format(e));
    }

    fn hello() -> PacketRepr<'static> {
        PacketRepr::Hello(HelloRepr {
            version: PROTOCOL_VERSION,
            capabilities: stereocal_firmware::driver::CHANNEL_CAPABILITIES | Capabilities::LOG,
        })
    }
}
