//! Moving what the fast-path octaves computed ahead ([`crate::fabric::fast::pending`]) into the
//! FIFOs in the order the register-level pipeline pushes it: by clock, and within one clock
//! octave 0 first, as `sc_out_fifo` takes the four octaves' items of a clock. With the same
//! pushes between the same pops, the FIFOs then hold, drop and count exactly what the
//! pipeline's FIFOs do.
//!
//! Octave 0 pushes a Sobel pixel on every clock of a row, octave `k` on every `2^k`-th clock
//! while its input comes in: the clocks of one octave's consecutive pixels form runs of a fixed
//! stride ([`ClockRun`]), so the merge moves a whole stretch of one octave per step, however
//! short the stretches between another octave's pixels are.

use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::latency::ClockRun;
use crate::fabric::output::OutputFifos;

/// An octave's waiting items, oldest first ([`crate::fabric::fast::pending::Pending`]).
pub(crate) trait Waiting<const W0: usize> {
    /// The clocks of the oldest waiting Sobel pixel and the ones after it, and how many
    /// pixels of its row wait.
    fn sobel_run(&self) -> Option<(ClockRun, u32)>;
    /// Pushes the oldest `len` waiting Sobel pixels, all of one row.
    fn release_sobel(&mut self, len: u32, out: &mut OutputFifos<W0>);
    /// Clock of the oldest waiting point.
    fn point_clock(&self) -> Option<u64>;
    /// Pushes the oldest waiting point.
    fn release_point(&mut self, out: &mut OutputFifos<W0>);
}

/// Pushes every waiting item the pipeline pushes before clock `until` into `out`, in the
/// pipeline's order; `octaves[k]` is octave `k`.
pub(crate) fn release<const W0: usize>(
    octaves: &mut [&mut dyn Waiting<W0>],
    until: u64,
    out: &mut OutputFifos<W0>,
) {
    release_sobel(octaves, until, out);
    release_points(octaves, until, out);
}

/// The position of the oldest of `clocks` before `until`: the lowest clock, the lowest
/// octave among equal clocks.
#[inline(always)]
fn oldest(clocks: impl Iterator<Item = Option<u64>>, until: u64) -> Option<(usize, u64)> {
    let mut first: Option<(usize, u64)> = None;
    for (k, clock) in clocks.enumerate() {
        if let Some(c) = clock.filter(|&c| c < until) {
            if first.is_none_or(|(_, f)| c < f) {
                first = Some((k, c));
            }
        }
    }
    first
}

fn release_sobel<const W0: usize>(
    octaves: &mut [&mut dyn Waiting<W0>],
    until: u64,
    out: &mut OutputFifos<W0>,
) {
    let mut heads: [Option<(ClockRun, u32)>; MAX_OCTAVES] = [None; MAX_OCTAVES];
    for (head, octave) in heads.iter_mut().zip(octaves.iter()) {
        *head = octave.sobel_run();
    }
    let clocks =
        |heads: &[Option<(ClockRun, u32)>; MAX_OCTAVES]| heads.map(|h| h.map(|(run, _)| run.clock));
    while let Some((k, _)) = oldest(clocks(&heads).into_iter(), until) {
        let Some((run, left)) = heads.get(k).copied().flatten() else {
            return;
        };
        let shift = run.stride.trailing_zeros();
        // Pixels `i` of the run, at `run.clock + i·stride`, that come before `until` and
        // before every other octave's oldest pixel (after it on a tie when that octave is
        // lower, before it when higher).
        let mut take = ((until - run.clock - 1) >> shift) + 1;
        take = take.min(run.len).min(left.into());
        for (j, other) in heads.iter().enumerate() {
            let Some((other, _)) = other.filter(|_| j != k) else {
                continue;
            };
            let d = other.clock.saturating_sub(run.clock);
            let before = if j > k {
                (d >> shift) + 1
            } else {
                (d + run.stride - 1) >> shift
            };
            take = take.min(before);
        }
        // `k` is the oldest: every bound is at least 1, and `take <= left`, a u32.
        let take = take.max(1) as u32;
        let Some(octave) = octaves.get_mut(k) else {
            return;
        };
        octave.release_sobel(take, out);
        let next = if take == left || u64::from(take) == run.len {
            octave.sobel_run()
        } else {
            let ahead = u64::from(take);
            Some((
                ClockRun {
                    clock: run.clock + ahead * run.stride,
                    len: run.len - ahead,
                    ..run
                },
                left - take,
            ))
        };
        if let Some(head) = heads.get_mut(k) {
            *head = next;
        }
    }
}

fn release_points<const W0: usize>(
    octaves: &mut [&mut dyn Waiting<W0>],
    until: u64,
    out: &mut OutputFifos<W0>,
) {
    let mut heads: [Option<u64>; MAX_OCTAVES] = [None; MAX_OCTAVES];
    for (head, octave) in heads.iter_mut().zip(octaves.iter()) {
        *head = octave.point_clock();
    }
    while let Some((k, _)) = oldest(heads.into_iter(), until) {
        let (Some(octave), Some(head)) = (octaves.get_mut(k), heads.get_mut(k)) else {
            return;
        };
        octave.release_point(out);
        *head = octave.point_clock();
    }
}
