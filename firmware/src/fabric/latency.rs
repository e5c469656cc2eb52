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
    if k == 0 {
        return n as u64;
    }
    let (w, _) = octave_dims(width, height, k);
    let (pw, ph) = octave_dims(width, height, k - 1);
    // An empty octave (a zero-width frame, which no configuration allows) has no samples.
    let (Some(x), Some(y)) = (n.checked_rem(w as u32), n.checked_div(w as u32)) else {
        return 0;
    };
    let parent = 2 * y * pw as u32 + 2 * x;
    let e = parent + octave_to_next(pw, k - 1);
    let parent_total = pw as u32 * ph as u32;
    if e < parent_total {
        sample_clock(width, height, k - 1, e)
    } else {
        sample_clock(width, height, k - 1, parent_total - 1) + (e - parent_total + 1) as u64
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
