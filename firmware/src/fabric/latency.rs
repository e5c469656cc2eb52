//! Latency figures of the register-level model, in pixel clocks, derived from the per-stage
//! latencies each stage module declares. `tests/latency.rs` checks them against the clocks the
//! model actually takes.
//!
//! Octave 0 receives one pixel per clock (no horizontal blanking in the model), and after the
//! last pixel every clock is blanking. An octave is clock-enabled: octave `k ≥ 1` advances when
//! its input (the subsampled G3 of octave `k - 1`) is valid, and on every clock once that input
//! is complete until it has drained.

use crate::fabric::convolver::gaussian_latency;
use crate::fabric::cordic::CORDIC_LATENCY;
use crate::fabric::dog::DOG_LATENCY;
use crate::fabric::edge::EDGE_LATENCY;
use crate::fabric::extrema::EXTREMA_LATENCY;
use crate::fabric::geometry::octave_dims;
use crate::fabric::refine::REFINE_LATENCY;
use crate::fabric::sobel::SOBEL_LATENCY;
use crate::fabric::subsample::SUBSAMPLE_LATENCY;
use crate::fabric::window::window_latency;

/// Enabled clocks from an octave's input sample `p` to the subsampler emitting `G3(p)`.
pub const fn octave_to_next(width: u16, k: u8) -> u32 {
    filters(k) * gaussian_latency(width) + SUBSAMPLE_LATENCY
}

/// Convolvers in series in octave `k`: the input filter G0 runs in octave 0 only.
pub const fn filters(k: u8) -> u32 {
    if k == 0 {
        4
    } else {
        3
    }
}

/// Enabled clocks from input sample `p` to its extremum entering the point FIFO.
pub const fn octave_to_point(width: u16, k: u8) -> u32 {
    filters(k) * gaussian_latency(width)
        + DOG_LATENCY
        + window_latency(width)
        + EXTREMA_LATENCY
        + EDGE_LATENCY
        + REFINE_LATENCY
}

/// Enabled clocks from input sample `p` to its Sobel pixel entering the Sobel FIFO when the
/// Sobel stage reads scale `sobel_scale`.
pub const fn octave_to_sobel(width: u16, k: u8, sobel_scale: u8) -> u32 {
    (sobel_scale as u32 + filters(k) - 3) * gaussian_latency(width)
        + window_latency(width)
        + SOBEL_LATENCY
        + CORDIC_LATENCY
}

/// Clock at which octave `k` receives its input sample number `n` (raster index) for a
/// `width x height` frame whose first pixel enters at clock 0.
pub const fn sample_clock(width: u16, height: u16, k: u8, n: u32) -> u64 {
    enabled_clock(width, height, k, n as u64)
}

/// Clock (from the frame's first pixel at clock 0) of octave `k`'s enabled clock number `m`:
/// an octave takes its input sample `n` on its enabled clock `n` and hands out the item of
/// sample `n` on its enabled clock `n + latency`, so this is when that item leaves.
///
/// Octave 0 is enabled on every clock (a pixel a clock, then flushing), so its enabled clock
/// `m` is clock `m`. Octave `k >= 1` is enabled when the subsampler of octave `k - 1` hands it
/// sample `n = y·w + x`, which is that octave's sample `2y·w' + 2x` [`octave_to_next`] enabled
/// clocks on, and, once its `w x h` samples are in, on every clock until it has drained.
pub const fn enabled_clock(width: u16, height: u16, k: u8, m: u64) -> u64 {
    enabled_run(width, height, k, m).clock
}

/// Enabled clocks of one octave that follow one another at a fixed distance: from enabled
/// clock `m` on, `len` of them, the `j`-th at `clock + j·stride`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClockRun {
    /// Clock of the first.
    pub clock: u64,
    /// Clocks between two of them: a power of two.
    pub stride: u64,
    /// How many (at least 1; `u64::MAX` when they go on for ever, as a flushing octave's).
    pub len: u64,
}

/// The longest [`ClockRun`] of octave `k` from its enabled clock `m` ([`enabled_clock`]
/// explains the schedule). Within one row of its input an octave `k >= 1` is enabled every
/// other enabled clock of octave `k - 1`; a run ends at the end of that row, where octave
/// `k - 1`'s run under it ends, or where the octave's input ends and it flushes every clock.
pub const fn enabled_run(width: u16, height: u16, k: u8, m: u64) -> ClockRun {
    if k == 0 {
        return ClockRun {
            clock: m,
            stride: 1,
            len: u64::MAX,
        };
    }
    let (w, h) = octave_dims(width, height, k);
    let total = w as u64 * h as u64;
    // An empty octave (a zero-width frame, which no configuration allows) has no samples.
    if w == 0 || h == 0 {
        return ClockRun {
            clock: 0,
            stride: 1,
            len: u64::MAX,
        };
    }
    if m >= total {
        let last = enabled_clock(width, height, k, total - 1);
        return ClockRun {
            clock: last + (m - total + 1),
            stride: 1,
            len: u64::MAX,
        };
    }
    let (pw, _) = octave_dims(width, height, k - 1);
    let (y, x) = (m / w as u64, m % w as u64);
    let parent = enabled_run(
        width,
        height,
        k - 1,
        2 * y * pw as u64 + 2 * x + octave_to_next(pw, k - 1) as u64,
    );
    // Sample `m + j` is the parent's enabled clock `2j` further on, within this row.
    let under = parent.len / 2 + parent.len % 2;
    let row = w as u64 - x;
    ClockRun {
        clock: parent.clock,
        stride: 2 * parent.stride,
        len: if under < row { under } else { row },
    }
}

/// First pixel in to first pixel of the last of `octaves` octaves, in clocks.
pub const fn first_pixel_of_last_octave(width: u16, height: u16, octaves: u8) -> u64 {
    sample_clock(width, height, octaves.saturating_sub(1), 0)
}

/// The same in nanoseconds at `clock_hz`.
pub const fn clocks_to_ns(clocks: u64, clock_hz: u64) -> u64 {
    clocks * 1_000_000_000 / clock_hz
}
