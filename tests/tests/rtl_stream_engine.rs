//! The stream engine in RTL against its Rust model: random frames and configurations through
//! the Verilated `sc_fabric` (its `sc_stream` and `sc_framer`) and through the device model,
//! every LINK_OUT byte and the engine's registers compared after each frame
//! (`stereocal_hil::stream_cosim`). Run with
//! `cargo test --release -p stereocal-hil --test rtl_stream_engine`.
//!
//! Without Verilator every test prints a loud SKIPPED line and passes, except under `CI=true`
//! (where the build already fails).

// Without the RTL model only the skip path is compiled.
#![cfg_attr(
    not(rtl_sim),
    allow(dead_code, unused_imports, clippy::needless_return)
)]

use stereocal_hdl::regs::stream_fault;
use stereocal_hil::rng::Rng;
use stereocal_hil::stream_cosim::{Clocking, Frame};

/// Frames per seed.
const FRAMES: usize = 12;

fn skipped(name: &str) -> bool {
    if let Some(why) = stereocal_hil::rtl::SKIP {
        stereocal_hil::skip(name, &format!("RTL co-simulation not built: {why}"));
        return true;
    }
    false
}

/// A camera at a thirty-second of the fabric's clock with a quarter line of blanking: the
/// engine keeps up, and every byte is the model's.
#[test]
fn the_rtl_engine_sends_the_models_bytes() {
    if skipped("stream engine co-simulation") {
        return;
    }
    #[cfg(rtl_sim)]
    {
        use stereocal_hil::rtl_fabric::RtlFabric;
        use stereocal_hil::stream_cosim::{model_frame, rtl_frame, stream_model};
        let (mut packets, mut patches, mut rows) = (0, 0, 0);
        for seed in 1..=3u64 {
            let mut r = Rng::new(seed);
            let mut model = stream_model();
            let mut rtl = RtlFabric::new(seed as u32);
            let clocking = Clocking {
                ratio: 32,
                line_blank: 16,
                link_stalls: 100,
            };
            for n in 0..FRAMES {
                let frame = Frame::random(&mut r);
                let (want, counters) = model_frame(&mut model, &frame);
                let got = rtl_frame(&mut rtl, &frame, clocking, &mut r);
                let at = want.iter().zip(&got.bytes).position(|(a, b)| a != b);
                assert!(
                    want == got.bytes,
                    "seed {seed} frame {n} ({:?}): model {} bytes, RTL {} bytes, first \
                     difference at {at:?}; registers model {counters:?}, RTL {:?}",
                    frame.config,
                    want.len(),
                    got.bytes.len(),
                    got.counters
                );
                assert_eq!(counters, got.counters, "seed {seed} frame {n}");
                packets += want.iter().filter(|&&b| b == 0).count();
                match frame.config.sobel_output {
                    stereocal_hdl::regs::output_mode::SobelOutput::Patches => {
                        patches += counters.sobel_packets
                    }
                    stereocal_hdl::regs::output_mode::SobelOutput::Rows => {
                        rows += counters.sobel_packets
                    }
                }
                eprintln!(
                    "seed {seed} frame {n}: {} bytes, {counters:?}, {} clocks",
                    want.len(),
                    got.clocks
                );
            }
        }
        // The frames went where they should: patches and rows sent, many link frames.
        assert!(
            patches >= 50 && rows >= 50,
            "{patches} patches, {rows} rows"
        );
        assert!(packets >= 500, "{packets} link frames");
    }
}

/// A camera at the fabric's full clock with a busy link: the engine falls behind on most
/// frames. It must say so: STREAM_FAULT.OVERRUN set, and what it sent of the frame a prefix
/// of the model's bytes ending at a link frame; otherwise every byte is the model's.
#[test]
fn an_rtl_engine_that_falls_behind_says_so() {
    if skipped("stream engine overrun") {
        return;
    }
    #[cfg(rtl_sim)]
    {
        use stereocal_hil::rtl_fabric::RtlFabric;
        use stereocal_hil::stream_cosim::{model_frame, rtl_frame, stream_model};
        let mut overruns = 0;
        let mut r = Rng::new(7);
        let clocking = Clocking {
            ratio: 1,
            line_blank: 0,
            link_stalls: 500,
        };
        for n in 0..FRAMES {
            // A fresh pair for every frame: after an overrun the RTL has sent fewer packets,
            // so its sequence numbers are behind the model's.
            let (mut model, mut rtl) = (stream_model(), RtlFabric::new(n as u32));
            let frame = Frame::random(&mut r);
            let (want, counters) = model_frame(&mut model, &frame);
            let got = rtl_frame(&mut rtl, &frame, clocking, &mut r);
            if stream_fault::OVERRUN.extract(got.counters.fault) != 0 {
                overruns += 1;
                assert!(
                    want.starts_with(&got.bytes) && got.bytes.last().is_none_or(|&b| b == 0),
                    "frame {n}: the RTL's {} bytes are not a prefix of the model's {} ending \
                     at a link frame: first difference at {:?}, fault {:#x}",
                    got.bytes.len(),
                    want.len(),
                    want.iter().zip(&got.bytes).position(|(a, b)| a != b),
                    got.counters.fault
                );
            } else {
                assert!(want == got.bytes, "frame {n}: no overrun, other bytes");
                assert_eq!(counters, got.counters, "frame {n}");
            }
        }
        assert!(overruns >= 3, "{overruns} overruns in {FRAMES} frames");
    }
}
