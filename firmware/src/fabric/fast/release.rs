//! Moving what the fast-path octaves computed ahead ([`crate::fabric::fast::pending`]) into the
//! FIFOs in the order the register-level pipeline pushes it: by clock, and within one clock
//! octave 0 first, as `sc_out_fifo` takes the four octaves' items of a clock. With the same
//! pushes between the same pops, the FIFOs then hold, drop and count exactly what the
//! pipeline's FIFOs do.
//!
//! Octave 0 pushes a Sobel pixel on every clock of a row, octave `k` on every `2^k`-th clock
//! while its input comes in: the clocks of one octave's consecutive pixels form runs of a fixed
//! stride ([`ClockRun`]). Where several octaves push, their pixels therefore interleave in a
//! pattern that repeats every longest stride, so the merge works the pattern out once and
//! writes many periods of it straight into the FIFO's words, each octave's pixels to their
//! places; where one octave pushes alone, its pixels go in as one run. Pixel by pixel it
//! goes only where a run starts or ends.

use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::fifo_words::SobelRowWords;
use crate::fabric::latency::ClockRun;
use crate::fabric::output::OutputFifos;
use crate::fabric::sobel_fifo::{SobelAppend, SobelRun};

/// An octave's waiting items, oldest first ([`crate::fabric::fast::pending::Pending`]).
pub(crate) trait Waiting<const W0: usize> {
    /// The clocks of the oldest waiting Sobel pixel and the ones after it, and how many
    /// pixels of its row wait.
    fn sobel_run(&self) -> Option<(ClockRun, u32)>;
    /// The waiting Sobel pixels of the oldest one's row, oldest first: as many as
    /// [`Waiting::sobel_run`] counts.
    fn sobel_waiting(&self) -> SobelRun<'_>;
    /// The oldest `len` waiting Sobel pixels, all of one row, are in the FIFO.
    fn sobel_released(&mut self, len: u32);
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

/// One octave's waiting Sobel pixels of one clock run and one row: the `i`-th at clock
/// `clock + i << shift`.
#[derive(Clone, Copy)]
struct Head<'a> {
    clock: u64,
    shift: u32,
    /// The pixels, `len` of them before the run or the row ends (0: none waits).
    pixels: SobelRun<'a>,
    /// What their words share.
    words: SobelRowWords,
    len: u64,
}

impl Head<'_> {
    const NONE: Self = Self {
        clock: u64::MAX,
        shift: 0,
        pixels: SobelRun {
            octave: 0,
            y: 0,
            x: 0,
            magnitude: &[],
            orientation: &[],
        },
        words: SobelRowWords::new(0, 0),
        len: 0,
    };
}

/// Moves the waiting Sobel pixels pushed before `until` into `out`: a segment at a time, in
/// which every octave's pixels stay in one clock run and one row, then the octaves let go of
/// what the segment took.
fn release_sobel<const W0: usize>(
    octaves: &mut [&mut dyn Waiting<W0>],
    until: u64,
    out: &mut OutputFifos<W0>,
) {
    let mut out = out.append_sobel();
    loop {
        let mut heads = [Head::NONE; MAX_OCTAVES];
        for (head, octave) in heads.iter_mut().zip(octaves.iter()) {
            if let Some((run, left)) = octave.sobel_run() {
                let pixels = octave.sobel_waiting();
                *head = Head {
                    clock: run.clock,
                    shift: run.stride.trailing_zeros(),
                    pixels,
                    words: SobelRowWords::new(pixels.octave, pixels.y),
                    len: run.len.min(left.into()),
                };
            }
        }
        let (taken, more) = merge(&heads, until, &mut out);
        for (octave, &n) in octaves.iter_mut().zip(&taken) {
            if n > 0 {
                octave.sobel_released(n);
            }
        }
        if !more {
            return;
        }
    }
}

/// Pushes the pixels of `heads` before `until` into `out` by clock, lowest octave first
/// within a clock, until a head runs out; returns how many of each it pushed, and whether a
/// head ran out (the octave may have more pixels, in its next run or row).
#[inline(always)]
fn merge(
    heads: &[Head<'_>; MAX_OCTAVES],
    until: u64,
    out: &mut SobelAppend<'_>,
) -> ([u32; MAX_OCTAVES], bool) {
    // The next clock of every octave with pixels.
    let mut clocks = heads.map(|h| if h.len > 0 { h.clock } else { u64::MAX });
    let mut taken = [0u32; MAX_OCTAVES];
    loop {
        // The oldest pixel, the lowest octave among equal clocks.
        let mut k = 0;
        let mut clock = u64::MAX;
        for (j, &c) in clocks.iter().enumerate() {
            if c < clock {
                (k, clock) = (j, c);
            }
        }
        if clock >= until {
            return (taken, false);
        }
        match periods(heads, &mut clocks, &mut taken, clock, until, out) {
            Periods::None => {}
            Periods::Pushed => continue,
            Periods::RanOut => return (taken, true),
        }
        let (Some(head), Some(t), Some(c)) = (heads.get(k), taken.get_mut(k), clocks.get_mut(k))
        else {
            return (taken, false);
        };
        push_pixel(&head.pixels, head.words, *t as usize, out);
        *t += 1;
        *c += 1 << head.shift;
        if u64::from(*t) == head.len {
            return (taken, true);
        }
    }
}

/// What [`periods`] did.
enum Periods {
    /// Nothing: not a whole period fits.
    None,
    /// Whole periods, every head has pixels left.
    Pushed,
    /// Whole periods, after which a head has no pixel left.
    RanOut,
}

/// Pushes whole periods of the octaves' pattern from `clock`, the oldest pixel's.
///
/// An octave whose next pixel comes within its stride of `clock` pushes, from `clock` on, on
/// the same clocks of every period of the longest such stride: the pixels of a period go in
/// the same octave order in every period, so the order is worked out once and repeated for as
/// many periods as every such octave has pixels for, that end before `until` and before the
/// first pixel of any other octave. One octave alone repeats a pattern of one pixel: a run.
#[inline(always)]
fn periods(
    heads: &[Head<'_>; MAX_OCTAVES],
    clocks: &mut [u64; MAX_OCTAVES],
    taken: &mut [u32; MAX_OCTAVES],
    clock: u64,
    until: u64,
    out: &mut SobelAppend<'_>,
) -> Periods {
    let mut in_step = [false; MAX_OCTAVES];
    let mut shift = 0;
    let mut bound = until;
    for ((step, head), &c) in in_step.iter_mut().zip(heads).zip(clocks.iter()) {
        if c == u64::MAX {
            continue;
        }
        if c < clock + (1 << head.shift) {
            *step = true;
            shift = shift.max(head.shift);
        } else {
            bound = bound.min(c);
        }
    }
    // `clock < until` and every octave out of step is after `clock`.
    let mut count = (bound - clock) >> shift;
    for ((&step, head), &t) in in_step.iter().zip(heads).zip(taken.iter()) {
        if step {
            count = count.min((head.len - u64::from(t)) >> (shift - head.shift));
        }
    }
    if count == 0 {
        return Periods::None;
    }
    let steps = in_step.iter().filter(|&&s| s).count();
    if steps == 1 {
        // One octave alone: `count` of its pixels in one run.
        if let Some(k) = in_step.iter().position(|&s| s) {
            if let (Some(head), Some(&t)) = (heads.get(k), taken.get(k)) {
                let (_, rest) = head.pixels.split_at(t as usize);
                out.push_run(rest.split_at(count as usize).0);
            }
        }
    } else {
        // The order of one period's pixels (at most 1 + 2 + 4 + 8), and per octave the
        // places of its pixels in it.
        let mut pattern = [0u8; 15];
        let mut places = [[0u8; 8]; MAX_OCTAVES];
        let mut per = [0usize; MAX_OCTAVES];
        let mut len = 0;
        for d in 0..1u64 << shift {
            let at = clock + d;
            for (j, ((&step, head), &c)) in in_step.iter().zip(heads).zip(clocks.iter()).enumerate()
            {
                if step && at >= c && (at - c) & ((1 << head.shift) - 1) == 0 {
                    let (Some(p), Some(n)) = (pattern.get_mut(len), per.get_mut(j)) else {
                        continue;
                    };
                    if let Some(place) = places.get_mut(j).and_then(|q| q.get_mut(*n)) {
                        *p = j as u8;
                        *place = len as u8;
                        *n += 1;
                        len += 1;
                    }
                }
            }
        }
        // Two octaves in step put at least two pixels into a period; the soft-core build
        // proves it has no panicking path, so the divisor says so in its type.
        let Some(period) = core::num::NonZeroUsize::new(len) else {
            return Periods::None;
        };
        let pattern = pattern.get(..len).unwrap_or_default();
        let mut next = taken.map(|t| t as usize);
        let mut left = count as usize;
        while left > 0 {
            // As many whole periods as fit before the end of the ring, written in place; a
            // period across the end, or into a full FIFO, pixel by pixel.
            let space = out.space();
            let fit = (space.len() / period).min(left);
            if fit == 0 {
                for &j in pattern {
                    let j = usize::from(j);
                    if let (Some(head), Some(i)) = (heads.get(j), next.get_mut(j)) {
                        push_pixel(&head.pixels, head.words, *i, out);
                        *i += 1;
                    }
                }
                left -= 1;
                continue;
            }
            // Octave by octave: its pixels go to the same places of every period's block.
            let blocks = space.get_mut(..fit * len).unwrap_or_default();
            for (j, (head, i)) in heads.iter().zip(next.iter_mut()).enumerate() {
                let (Some(places), Some(&per)) = (places.get(j), per.get(j)) else {
                    continue;
                };
                let (Some(places), Some(per)) =
                    (places.get(..per), core::num::NonZeroUsize::new(per))
                else {
                    continue;
                };
                let per = per.get();
                let span = *i..*i + fit * per;
                let (Some(magnitude), Some(orientation)) = (
                    head.pixels.magnitude.get(span.clone()),
                    head.pixels.orientation.get(span),
                ) else {
                    continue;
                };
                let mut x = head.pixels.x.wrapping_add(*i as u16);
                let pixels = magnitude
                    .chunks_exact(per)
                    .zip(orientation.chunks_exact(per));
                for (block, (magnitude, orientation)) in
                    blocks.chunks_exact_mut(period.get()).zip(pixels)
                {
                    for ((&at, &m), &o) in places.iter().zip(magnitude).zip(orientation) {
                        if let Some(slot) = block.get_mut(usize::from(at)) {
                            *slot = head.words.pixel(x, m, o);
                        }
                        x = x.wrapping_add(1);
                    }
                }
                *i += fit * per;
            }
            out.commit(fit * len);
            left -= fit;
        }
    }
    let mut ran_out = false;
    for (((&step, head), t), c) in in_step
        .iter()
        .zip(heads)
        .zip(taken.iter_mut())
        .zip(clocks.iter_mut())
    {
        if step {
            // At most a row's pixels.
            *t += (count << (shift - head.shift)) as u32;
            *c += count << shift;
            ran_out |= u64::from(*t) == head.len;
        }
    }
    if ran_out {
        Periods::RanOut
    } else {
        Periods::Pushed
    }
}

/// The words of pixel `i` of `pixels`, whose words share `words`.
#[inline(always)]
fn pixel_words(pixels: &SobelRun<'_>, words: SobelRowWords, i: usize) -> Option<[u32; 2]> {
    let (Some(&m), Some(&o)) = (pixels.magnitude.get(i), pixels.orientation.get(i)) else {
        return None;
    };
    Some(words.pixel(pixels.x.wrapping_add(i as u16), m, o))
}

/// Pushes pixel `i` of `pixels`, whose words share `words`.
#[inline(always)]
fn push_pixel(pixels: &SobelRun<'_>, words: SobelRowWords, i: usize, out: &mut SobelAppend<'_>) {
    if let Some(words) = pixel_words(pixels, words, i) {
        out.push(words);
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
