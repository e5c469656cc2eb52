//! One contract for the device model and the RTL: seeded random schedules of bus accesses
//! and pixels, clock by clock, into `FabricDevice::clock` (the register-level datapath
//! behind it) and into the Verilated `sc_fabric`, comparing PIXEL_IN's ready and every word
//! read (`stereocal_hil::fabric_contract`). Run with
//! `cargo test --release -p stereocal-hil --test rtl_fabric_contract`.
//!
//! Without Verilator every test prints a loud SKIPPED line and passes, except under `CI=true`
//! (where the build already fails).

// Without the RTL model only the skip path is compiled.
#![cfg_attr(
    not(rtl_sim),
    allow(dead_code, unused_imports, clippy::needless_return)
)]

/// Clocks per seed: about 80 frames each.
const CLOCKS: u64 = 500_000;

fn contract(seed: u64) {
    if let Some(why) = stereocal_hil::rtl::SKIP {
        stereocal_hil::skip(
            &format!("contract seed {seed}"),
            &format!("RTL co-simulation not built: {why}"),
        );
        return;
    }
    #[cfg(rtl_sim)]
    {
        let stats = stereocal_hil::fabric_contract::run(seed, CLOCKS)
            .unwrap_or_else(|m| panic!("seed {seed}: model and RTL differ at {m}"));
        eprintln!("seed {seed}: {stats:?}");
        // The schedule went where it should: frames done and aborted, FIFO words compared,
        // both FIFOs overflowed.
        assert!(stats.frames_done >= 10, "{stats:?}");
        assert!(stats.soft_resets >= 1, "{stats:?}");
        assert!(
            stats.points_read >= 100 && stats.sobel_read >= 10_000,
            "{stats:?}"
        );
        assert!(
            stats.point_overflows >= 1 && stats.sobel_overflows >= 1,
            "{stats:?}"
        );
    }
}

#[test]
fn seed_1() {
    contract(1);
}

#[test]
fn seed_2() {
    contract(2);
}

#[test]
fn seed_3() {
    contract(3);
}

#[test]
fn seed_4() {
    contract(4);
}
