//! Faults cost frames, never correctness: a rendered sequence through the in-process device
//! with a [`FaultLink`] between the device's bytes and the host driver, swept over fault
//! kinds and rates, each run compared frame by frame with a run without faults.
//!
//! A *wrong estimate* is measured, not assumed: the estimator is deterministic, so a frame
//! pair that arrives intact gives the bit-identical raw verge of the clean run, and any
//! estimate that differs (or belongs to a frame id the clean run never produced) came from
//! bytes the link damaged and the driver let through. A salvaged pair (one of its frames
//! lost packets) is estimated from part of the data, so its estimate is wrong when it is
//! further from the clean run's than its own sigma (or when the clean run had none). Faults
//! are on for a burst in the middle of the sequence; the frames after it show how fast the
//! driver is back in step. Each row runs on a link guard ([`Guard`]): the clean-link default,
//! or the noisy-link one with error correction and small packets.
//!
//! The runner drives the [`Driver`] directly rather than through a
//! [`Session`](stereocal::session::Session): it needs every outcome the driver hands out, by
//! frame id, including late damage reports that a session skips (a session's own behaviour
//! under faults is tested in `tests/faults.rs`).
//!
//! `stereocal reliability` writes the sweep to `docs/RELIABILITY.md` ([`markdown`]).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::ops::Range;
use std::time::{Duration, Instant};

use rayon::prelude::*;
use stereocal::output::summary::percentile;
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_wire::Camera;

use crate::workload::{Workload, WorkloadError};
use stereocal::driver::{
    Driver, DriverError, FrameOutcome, LinkStats, ReceivedFrame, MAX_LOST_FRACTION,
};
use stereocal::estimator::{EstimatorConfig, VergeEstimator};
use stereocal::link::{
    BadRate, FaultConfig, FaultCounts, FaultLink, FrameInput, InProcessLink, Link, LinkError,
    LinkProtection,
};
use stereocal::session::tuned_fabric_config;

/// Why a reliability run failed (a fault never is a reason: those cost frames).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReliabilityError {
    #[error(transparent)]
    Workload(#[from] WorkloadError),
    #[error("device link: {0}")]
    Link(#[from] LinkError),
    #[error("device: {0}")]
    Driver(#[from] DriverError),
    #[error(transparent)]
    Rate(#[from] BadRate),
}

/// What the host made of one frame id.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PairResult {
    /// Both frames delivered and estimated.
    Estimated {
        /// The raw verge (an intact pair's is compared to the bit).
        verge_deg: f64,
        /// The estimate's own 1-sigma uncertainty.
        sigma_deg: f64,
        /// Whether either frame was salvaged.
        salvaged: bool,
    },
    /// Both frames delivered, no estimate (too few matches).
    NoEstimate {
        /// Whether either frame was salvaged.
        salvaged: bool,
    },
}

impl PairResult {
    /// Whether `self`, delivered for a frame id, is wrong when the clean run gave `clean`
    /// (`None`: the clean run never had the id). An intact pair must reproduce the clean
    /// result exactly; a salvaged pair may lack an estimate, and its estimate must lie within
    /// its own sigma of the clean one.
    pub fn is_wrong(&self, clean: Option<&PairResult>) -> bool {
        match (*self, clean) {
            (Self::NoEstimate { salvaged: true }, Some(_)) => false,
            (Self::NoEstimate { .. }, Some(Self::NoEstimate { .. })) => false,
            (
                Self::Estimated {
                    verge_deg,
                    sigma_deg,
                    salvaged,
                },
                Some(&Self::Estimated { verge_deg: c, .. }),
            ) => is_wrong_estimate(verge_deg, sigma_deg, salvaged, c),
            _ => true,
        }
    }
}

/// Whether an estimate `verge_deg` (own 1-σ `sigma_deg`) is wrong against the fault-free
/// run's `clean_deg` for the same pair: an intact pair must reproduce it to the bit, a
/// salvaged one (`salvaged`) lie within its own sigma of it. A NaN difference or sigma is
/// wrong too.
pub fn is_wrong_estimate(verge_deg: f64, sigma_deg: f64, salvaged: bool, clean_deg: f64) -> bool {
    if salvaged {
        !matches!(
            (verge_deg - clean_deg).abs().partial_cmp(&sigma_deg),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        )
    } else {
        verge_deg.to_bits() != clean_deg.to_bits()
    }
}

/// One run of the workload.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Every delivered pair, in the order the driver handed it out: frame id and result.
    /// A frame id may come twice (a duplicated frame) and need not be one that was sent.
    pub delivered: Vec<(u32, PairResult)>,
    /// The driver's counters.
    pub stats: LinkStats,
    /// What the fault link did.
    pub faults: FaultCounts,
    pub elapsed: Duration,
}

/// Runs the workload over a link guarded by `protection`, with `faults` on for the frames
/// in `burst` (off elsewhere).
pub fn run(
    workload: &Workload,
    faults: FaultConfig,
    burst: Range<usize>,
    protection: &LinkProtection,
) -> Result<Run, ReliabilityError> {
    let start = Instant::now();
    let link = FaultLink::new(InProcessLink::new()?, faults)?;
    let timeout = link.answer_timeout();
    let mut driver = Driver::new(link);
    driver.request_fec(protection.fec);
    driver.set_loss_limit(protection.loss_limit);
    let estimator_config = EstimatorConfig::default();
    driver.set_refinement_reach(estimator_config.subpixel.map(|s| s.reach_px()));
    driver.hello(timeout)?;
    driver.configure(
        &protection.pack(tuned_fabric_config(
            workload.width,
            workload.height,
            SobelOutput::Rows,
        )),
        timeout,
    )?;
    driver.enable()?;
    let estimator = VergeEstimator::new(workload.calib, estimator_config);
    let mut delivered = Vec::new();
    let mut lefts = HashMap::new();
    for (index, pair) in workload.pairs.iter().enumerate() {
        driver.link_mut().set_active(burst.contains(&index));
        driver
            .link_mut()
            .submit_pair(&pair.left, &pair.right, workload.timestamp_us(index))?;
        for (frame_id, l, r) in drain_pairs(&mut driver, &mut lefts, timeout)? {
            let salvaged = l.salvage.is_some() || r.salvage.is_some();
            let result = match estimator.estimate(&l.features, &r.features) {
                Ok(est) => PairResult::Estimated {
                    verge_deg: est.verge_deg,
                    sigma_deg: est.sigma_deg,
                    salvaged,
                },
                Err(_) => PairResult::NoEstimate { salvaged },
            };
            delivered.push((frame_id, result));
        }
    }
    Ok(Run {
        delivered,
        stats: *driver.stats(),
        faults: driver.link().counts(),
        elapsed: start.elapsed(),
    })
}

/// Takes every frame the driver can assemble from the bytes the device has sent, and pairs
/// the delivered ones by frame id. The in-process device answers synchronously, so its
/// receive times out at once when a pair's bytes are used up. A frame can come out of a
/// later pair's bytes (one that lost its `FrameEnd` is closed by the next frame's packets),
/// so the left frames waiting for their partner, `lefts`, outlive the call, as
/// [`Driver::next_pair`] keeps a frame for the next call; a right frame ends the wait of
/// every earlier left one, since the device sends each pair's left frame first.
fn drain_pairs<D: Link + FrameInput>(
    driver: &mut Driver<FaultLink<D>>,
    lefts: &mut HashMap<u32, ReceivedFrame>,
    timeout: Duration,
) -> Result<Vec<(u32, ReceivedFrame, ReceivedFrame)>, ReliabilityError> {
    let mut pairs = Vec::new();
    loop {
        let frame = match driver.next_frame(timeout) {
            Ok(FrameOutcome::Delivered(frame)) => *frame,
            Ok(FrameOutcome::Damaged(_)) => continue,
            Err(DriverError::Timeout { .. }) => return Ok(pairs),
            Err(e) => return Err(e.into()),
        };
        match frame.camera {
            Camera::Left => {
                lefts.insert(frame.frame_id, frame);
            }
            Camera::Right => {
                let id = frame.frame_id;
                if let Some(left) = lefts.remove(&id) {
                    pairs.push((id, left, frame));
                }
                lefts.retain(|&waiting, _| waiting > id);
            }
            Camera::Unknown(_) => {}
        }
    }
}

/// A faulted run judged against the clean one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Verdict {
    /// Pairs delivered (both frames intact or salvaged).
    pub delivered: usize,
    /// Delivered pairs with a salvaged frame.
    pub salvaged: usize,
    /// Frame ids delivered with an estimate that is not wrong.
    pub estimated: usize,
    /// Pairs sent that were not delivered.
    pub lost: usize,
    /// Camera frames the driver reported damaged (dropped, with a reason).
    pub reported_damaged: u64,
    /// Delivered pairs whose result is wrong ([`PairResult::is_wrong`]).
    pub wrong: usize,
    /// Frames after the burst until the first one delivered with the clean result (0: the
    /// first frame after the burst); `None` when none was.
    pub recovery: Option<usize>,
    /// Pairs after the burst that were not delivered with the clean result.
    pub bad_after_burst: usize,
}

/// Compares `faulted` with `clean` (same workload, no faults); `burst` as given to [`run`].
pub fn judge(clean: &Run, faulted: &Run, frames: usize, burst: &Range<usize>) -> Verdict {
    let expected: HashMap<u32, PairResult> = clean.delivered.iter().copied().collect();
    let is_wrong = |(id, result): &&(u32, PairResult)| result.is_wrong(expected.get(id));
    let wrong = faulted.delivered.iter().filter(is_wrong).count();
    let good: HashMap<u32, PairResult> = faulted
        .delivered
        .iter()
        .filter(|pair| !is_wrong(pair))
        .copied()
        .collect();
    let estimated = good
        .values()
        .filter(|r| matches!(r, PairResult::Estimated { .. }))
        .count();
    let salvaged = faulted
        .delivered
        .iter()
        .filter(|(_, r)| {
            matches!(
                r,
                PairResult::Estimated { salvaged: true, .. }
                    | PairResult::NoEstimate { salvaged: true }
            )
        })
        .count();
    let is_good = |frame: usize| u32::try_from(frame).is_ok_and(|id| good.contains_key(&id));
    let after = burst.end..frames;
    let mut distinct: Vec<u32> = faulted.delivered.iter().map(|&(id, _)| id).collect();
    distinct.sort_unstable();
    distinct.dedup();
    Verdict {
        delivered: faulted.delivered.len(),
        salvaged,
        estimated,
        lost: frames.saturating_sub(distinct.len()),
        reported_damaged: faulted.stats.frames_damaged,
        wrong,
        recovery: after.clone().position(is_good),
        bad_after_burst: after.filter(|&f| !is_good(f)).count(),
    }
}

/// How far salvage moved one salvaged estimate from the clean run's estimate of its pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SalvageMove {
    /// `|salvaged - clean| / σ`, σ the salvaged estimate's own.
    pub ratio: f64,
    /// The move's standard deviation, in the same unit, were the salvaged frame's matches a
    /// subset of the intact frame's (the argument of `host/src/driver/salvage.rs`): the subset
    /// estimate is the whole's plus an independent part of variance `σ² - σ_clean²`.
    pub subset_std: f64,
}

/// The moves of `faulted`'s salvaged estimates against `clean` (same workload, no faults),
/// for the pairs both estimated.
pub fn salvage_moves(clean: &Run, faulted: &Run) -> Vec<SalvageMove> {
    let expected: HashMap<u32, PairResult> = clean.delivered.iter().copied().collect();
    faulted
        .delivered
        .iter()
        .filter_map(|(id, result)| match (*result, expected.get(id)) {
            (
                PairResult::Estimated {
                    verge_deg,
                    sigma_deg,
                    salvaged: true,
                },
                Some(&PairResult::Estimated {
                    verge_deg: clean_deg,
                    sigma_deg: clean_sigma,
                    ..
                }),
            ) => Some(SalvageMove {
                ratio: (verge_deg - clean_deg).abs() / sigma_deg,
                subset_std: (1.0 - (clean_sigma / sigma_deg).powi(2)).max(0.0).sqrt(),
            }),
            _ => None,
        })
        .collect()
}

/// One kind of fault, alone, at `rate`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultKind {
    BitFlip,
    ByteDrop,
    Truncate,
    Duplicate,
    Reorder,
    Stall,
    /// Every kind at once.
    All,
}

impl FaultKind {
    /// The table's name and the unit of its rate.
    pub fn label(self) -> (&'static str, &'static str) {
        match self {
            Self::BitFlip => ("bit flips", "per bit"),
            Self::ByteDrop => ("dropped bytes", "per byte"),
            Self::Truncate => ("truncated packets", "per packet"),
            Self::Duplicate => ("duplicated packets", "per packet"),
            Self::Reorder => ("reordered packets", "per packet"),
            Self::Stall => ("stalls", "per packet"),
            Self::All => ("all of the above", "each, per its unit"),
        }
    }

    /// The fault configuration of this kind at `rate`.
    pub fn config(self, rate: f64, seed: u64) -> FaultConfig {
        let mut c = FaultConfig::none(seed);
        c.stall = STALL;
        match self {
            Self::BitFlip => c.bit_flip_rate = rate,
            Self::ByteDrop => c.byte_drop_rate = rate,
            Self::Truncate => c.truncate_rate = rate,
            Self::Duplicate => c.duplicate_rate = rate,
            Self::Reorder => c.reorder_rate = rate,
            Self::Stall => c.stall_rate = rate,
            Self::All => {
                c.bit_flip_rate = rate;
                c.byte_drop_rate = rate;
                c.truncate_rate = rate;
                c.duplicate_rate = rate;
                c.reorder_rate = rate;
                c.stall_rate = rate;
            }
        }
        c
    }
}

/// A stall: far below the in-process device's 5 s answer timeout, long enough to be a
/// real pause on a 2-core machine.
const STALL: Duration = Duration::from_millis(5);

/// The link guard of a sweep row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Guard {
    /// [`LinkProtection::clean`]: whole rows, no parity; salvage alone.
    Clean,
    /// [`LinkProtection::noisy`]: error correction and small packets (`--noisy-link`).
    Noisy,
}

impl Guard {
    /// The protection it stands for.
    pub fn protection(self) -> LinkProtection {
        match self {
            Self::Clean => LinkProtection::clean(),
            Self::Noisy => LinkProtection::noisy(),
        }
    }

    /// The table's name.
    pub fn label(self) -> &'static str {
        match self {
            Self::Clean => "clean",
            Self::Noisy => "noisy",
        }
    }
}

/// The sweep: every kind alone over its range of rates, then all kinds together, on the
/// noisy-link guard; and bit flips on the clean-link guard, which is salvage alone.
pub const PLAN: &[(FaultKind, Guard, &[f64])] = &[
    (FaultKind::BitFlip, Guard::Clean, &[1e-7, 1e-6, 1e-5]),
    (
        FaultKind::BitFlip,
        Guard::Noisy,
        &[1e-7, 1e-6, 1e-5, 1e-4, 1e-3],
    ),
    (
        FaultKind::ByteDrop,
        Guard::Noisy,
        &[1e-7, 1e-6, 1e-5, 1e-4, 1e-3],
    ),
    (FaultKind::Truncate, Guard::Noisy, &[1e-4, 1e-3, 1e-2, 1e-1]),
    (
        FaultKind::Duplicate,
        Guard::Noisy,
        &[1e-4, 1e-3, 1e-2, 1e-1],
    ),
    (FaultKind::Reorder, Guard::Noisy, &[1e-4, 1e-3, 1e-2, 1e-1]),
    (FaultKind::Stall, Guard::Noisy, &[1e-3, 1e-2]),
    (FaultKind::All, Guard::Noisy, &[1e-6, 1e-4, 1e-3]),
];

/// The share of all pairs a noisy-link sweep must estimate under bit flips, by rate (the
/// issue's availability targets; the clean-link rows show what salvage alone gives).
pub const AVAILABILITY: &[(f64, f64)] = &[(1e-6, 0.95), (1e-5, 0.80)];

/// Settings of a sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepConfig {
    pub frames: usize,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
}

impl SweepConfig {
    /// Faults are on for the middle two thirds of the sequence: frames before the burst
    /// show the faulted run starts like the clean one, frames after it show recovery.
    pub fn burst(&self) -> Range<usize> {
        self.frames / 6..self.frames - self.frames / 6
    }
}

/// One row of the sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    pub kind: FaultKind,
    pub guard: Guard,
    pub rate: f64,
    pub verdict: Verdict,
    /// How far salvage moved each salvaged estimate from the clean run of its guard.
    pub moves: Vec<SalvageMove>,
    pub run: Run,
}

/// The whole sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    pub config: SweepConfig,
    /// The run without faults on the clean-link guard.
    pub clean: Run,
    /// The run without faults on the noisy-link guard: the packing and the parity change the
    /// bytes, not what arrives, so its results equal `clean`'s to the bit.
    pub clean_noisy: Run,
    pub rows: Vec<SweepRow>,
    pub elapsed: Duration,
    /// The process's peak resident set when the sweep ended (Linux; `None` elsewhere).
    pub peak_rss_kib: Option<u64>,
}

/// Renders the workload, runs it clean on each guard, then every fault of [`PLAN`] (runs in
/// parallel), each judged against the clean run of its guard; `progress` is called after each
/// run.
pub fn sweep(config: SweepConfig, progress: &(dyn Fn() + Sync)) -> Result<Sweep, ReliabilityError> {
    let start = Instant::now();
    let workload = Workload::road(config.frames, config.seed, config.width, config.height)?;
    let burst = config.burst();
    let none = FaultConfig::none(config.seed);
    let clean = run(&workload, none, burst.clone(), &Guard::Clean.protection())?;
    progress();
    let clean_noisy = run(&workload, none, burst.clone(), &Guard::Noisy.protection())?;
    progress();
    let cases: Vec<(FaultKind, Guard, f64)> = PLAN
        .iter()
        .flat_map(|&(kind, guard, rates)| rates.iter().map(move |&rate| (kind, guard, rate)))
        .collect();
    let rows = cases
        .into_par_iter()
        .map(|(kind, guard, rate)| {
            let faults = kind.config(rate, config.seed);
            let faulted = run(&workload, faults, burst.clone(), &guard.protection())?;
            progress();
            let reference = match guard {
                Guard::Clean => &clean,
                Guard::Noisy => &clean_noisy,
            };
            Ok(SweepRow {
                kind,
                guard,
                rate,
                verdict: judge(reference, &faulted, workload.len(), &burst),
                moves: salvage_moves(reference, &faulted),
                run: faulted,
            })
        })
        .collect::<Result<Vec<_>, ReliabilityError>>()?;
    Ok(Sweep {
        config,
        clean,
        clean_noisy,
        rows,
        elapsed: start.elapsed(),
        peak_rss_kib: peak_rss_kib(),
    })
}

/// `VmHWM` of `/proc/self/status`: the most memory the process ever had resident.
fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Runs in the sweep, the clean one included (for a progress bar).
pub fn sweep_runs() -> usize {
    2 + PLAN.iter().map(|(_, _, rates)| rates.len()).sum::<usize>()
}

/// The share of all pairs of `row`'s run that were estimated and not wrong.
pub fn estimated_share(row: &SweepRow, frames: usize) -> f64 {
    row.verdict.estimated as f64 / frames.max(1) as f64
}

/// Whether every faulted run met the requirement: no wrong estimate, every frame after the
/// burst delivered with a result that is not wrong, the noisy-link guard's bit-flip rows at
/// their [`AVAILABILITY`], and both clean runs alike to the bit.
pub fn passed(sweep: &Sweep) -> bool {
    let frames = sweep.config.frames;
    let available = sweep.rows.iter().all(|r| {
        let target = AVAILABILITY
            .iter()
            .find(|&&(rate, _)| rate == r.rate)
            .map(|&(_, share)| share);
        match (r.kind, r.guard, target) {
            (FaultKind::BitFlip, Guard::Noisy, Some(share)) => estimated_share(r, frames) >= share,
            _ => true,
        }
    });
    available
        && sweep.clean.delivered == sweep.clean_noisy.delivered
        && sweep
            .rows
            .iter()
            .all(|r| r.verdict.wrong == 0 && r.verdict.bad_after_burst == 0)
}

/// `docs/RELIABILITY.md` for `sweep`; `command` is the command line that produced it.
pub fn markdown(sweep: &Sweep, command: &str) -> String {
    let c = sweep.config;
    let burst = c.burst();
    let clean_estimated = sweep
        .clean
        .delivered
        .iter()
        .filter(|(_, r)| matches!(r, PairResult::Estimated { .. }))
        .count();
    let mut md = String::new();
    let _ = writeln!(md, "# Reliability under link faults\n");
    let _ = writeln!(
        md,
        "Generated by `{command}` ({:.0} s on this machine); do not edit by hand.\n",
        sweep.elapsed.as_secs_f64()
    );
    let per_pair = |run: &Run| run.stats.bytes_received as f64 / c.frames.max(1) as f64;
    let _ = writeln!(
        md,
        "The road scene at {}x{}, {} frame pairs (seed {}), runs through the in-process device \
         (fabric model and soft-core firmware) with a fault-injecting link \
         (`host/src/link/fault.rs`) between the device's bytes and the host driver. Faults are \
         on for frames {}..{} (the burst) and off before and after it. The clean run (no \
         faults) delivered {} pairs, {} with an estimate.\n",
        c.width,
        c.height,
        c.frames,
        c.seed,
        burst.start,
        burst.end,
        sweep.clean.delivered.len(),
        clean_estimated,
    );
    let _ = writeln!(
        md,
        "Each row runs on one of two **link guards** (`host/src/link/protection.rs`). *clean* \
         is the default for a clean link: whole Sobel rows, {}-point batches, no parity, and \
         a frame that lost any keypoint or Sobel pixel dropped (a whole lost row costs too \
         many keypoints at once for salvage to stay exact); {:.0} KiB per pair. *noisy* \
         (`--noisy-link`) asks the device for forward error correction in `Hello` (RS(255, \
         239) over each link frame, `shared/src/fec.rs`: up to 8 damaged bytes in 255 \
         repaired), sets 64-pixel row segments and 8-point batches, so that a packet lost all \
         the same costs little, and salvages frames; {:.0} KiB per pair. Without faults both \
         guards give the same results to the bit: {}.\n",
        LinkProtection::clean().points_per_batch,
        per_pair(&sweep.clean) / 1024.0,
        per_pair(&sweep.clean_noisy) / 1024.0,
        if sweep.clean.delivered == sweep.clean_noisy.delivered {
            "yes"
        } else {
            "**no**"
        },
    );
    let _ = writeln!(
        md,
        "A **wrong estimate** is measured: the estimator is deterministic, so a pair that \
         arrives intact gives the clean run's raw verge to the bit, and an intact pair whose \
         result differs from the clean run's for its frame id (or whose id the clean run never \
         had) is wrong. A **salvaged** pair (a camera frame of it lost packets and was \
         delivered with what arrived intact, `host/src/driver/salvage.rs`) is estimated from \
         part of the data: its estimate is wrong when it differs from the clean run's by more \
         than its own sigma, or when the clean run had none. **Pairs estimated** counts frame \
         ids with an estimate that is not wrong, of all {} pairs (the {} outside the burst \
         included). **Recovery** is the number of frames after the burst before the first one \
         delivered with a result that is not wrong (0: the first frame after the burst already \
         is); *bad after* counts frames after the burst that were not.\n",
        c.frames,
        c.frames - burst.len(),
    );
    let pair_bits = per_pair(&sweep.clean) * 8.0;
    let _ = writeln!(
        md,
        "A fault costs the packet it lands in, not the camera frame. A packet lost costs the \
         points it carried, or the Sobel pixels, and with them every keypoint whose 16x16 \
         window touches one (at full resolution also every keypoint within {} px of one: \
         the sub-pixel refinement of its match reads them); a frame that lost more than {:.0} % of its keypoints, or of an \
         octave's Sobel pixels, or its `FrameStart`, is dropped and reported damaged (the \
         limit keeps a salvaged estimate within its own sigma of the intact one, \
         `salvage.rs`; on the clean guard the limit is 0). On the clean guard a pair is \
         {:.1} Mbit, so bit flips at 1e-6 expect {:.1} per pair, each costing a whole Sobel \
         row and the pair with it. A \
         repeated or overtaken packet is dropped (the overtaken one counts as lost). A stall \
         pauses the link for {} ms, far inside the driver's timeout, and costs time only.\n",
        EstimatorConfig::default()
            .subpixel
            .map_or(0, |s| s.reach_px()),
        MAX_LOST_FRACTION * 100.0,
        pair_bits / 1e6,
        pair_bits * 1e-6,
        STALL.as_millis(),
    );
    let _ = writeln!(
        md,
        "Targets (issue: a noisy link costs only what it damaged): on the noisy guard, bit \
         flips at {} estimate at least {} of all pairs; zero wrong estimates in every row.\n",
        AVAILABILITY
            .iter()
            .map(|(rate, _)| format!("{rate:.0e}"))
            .collect::<Vec<_>>()
            .join(" and "),
        AVAILABILITY
            .iter()
            .map(|(_, share)| format!("{:.0} %", share * 100.0))
            .collect::<Vec<_>>()
            .join(" and "),
    );
    let _ = writeln!(
        md,
        "| fault | rate | guard | faults injected | blocks repaired | pairs delivered | pairs salvaged | pairs estimated | pairs lost | camera frames reported damaged | wrong estimates | recovery (frames) | bad after | peak bytes held by the link |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for row in &sweep.rows {
        let (name, unit) = row.kind.label();
        let v = row.verdict;
        let f = row.run.faults;
        let injected = f.bits_flipped
            + f.bytes_dropped
            + f.packets_truncated
            + f.packets_duplicated
            + f.packets_reordered
            + f.stalls;
        let recovery = v
            .recovery
            .map_or_else(|| "never".to_string(), |r| r.to_string());
        let _ = writeln!(
            md,
            "| {name} | {:.0e} {unit} | {} | {injected} | {} | {} | {} | {} ({:.0} %) | {} | {} | {} | {recovery} | {} | {} |",
            row.rate,
            row.guard.label(),
            row.run.stats.fec_blocks_repaired,
            v.delivered,
            v.salvaged,
            v.estimated,
            estimated_share(row, c.frames) * 100.0,
            v.lost,
            v.reported_damaged,
            v.wrong,
            v.bad_after_burst,
            f.peak_buffered,
        );
    }
    let moves: Vec<&SalvageMove> = sweep.rows.iter().flat_map(|row| &row.moves).collect();
    let ratios: Vec<f64> = moves.iter().map(|m| m.ratio).collect();
    let subset: Vec<f64> = moves.iter().map(|m| m.subset_std).collect();
    if let (Some(median), Some(p95), Some(max), Some(subset_median)) = (
        percentile(&ratios, 0.5),
        percentile(&ratios, 0.95),
        percentile(&ratios, 1.0),
        percentile(&subset, 0.5),
    ) {
        let _ = writeln!(
            md,
            "\n**How far salvage moves an estimate.** Over the sweep's {} salvaged estimates \
             whose pair the clean run estimated, |salvaged - clean| in units of the salvaged \
             estimate's own sigma has median {median:.2}, 95th percentile {p95:.2} and maximum \
             {max:.2} ({} beyond 1). Were a salvaged frame's matches a subset of the intact \
             frame's (the argument of the loss limit in `salvage.rs`), the move's standard \
             deviation in the same unit would be sqrt(1 - sigma_clean² / sigma²), median \
             {subset_median:.2} over the same estimates, and its median |move| two thirds of \
             that.",
            moves.len(),
            ratios.iter().filter(|&&r| r > 1.0).count(),
        );
    }
    let verdict = if passed(sweep) {
        "**Zero wrong estimates at every rate, every frame after every burst delivered, and \
         the noisy guard at its targets.**"
    } else {
        "**REQUIREMENT NOT MET**: see the rows with wrong estimates, bad frames after the burst, \
         or the noisy guard's bit flips below their target."
    };
    let _ = writeln!(md, "\n{verdict} No run panicked or stopped.\n");
    let _ = writeln!(
        md,
        "## Memory\n\n\
         Nothing on the receiving side grows with the faults. The fault link holds at most \
         one receive of the wrapped link (64 KiB), a partial packet, a duplicate and one \
         held-back packet: the column above, about the same at every rate. The driver's accumulator is a fixed \
         `MAX_PROTECTED_LEN` buffer that skips an over-long frame rather than growing, its receive \
         buffer is a fixed 64 KiB, the assembler holds one frame in progress (its Sobel planes \
         sized by the `FrameStart` geometry, which is checked against the fabric's maximum \
         before anything is allocated; a damaged frame stops collecting points and rows at its \
         first problem, and a salvaged one holds no more than an intact one) and reports and frees it at its end or at the next `FrameStart`. The runner takes every frame the driver \
         has after each pair, so its frame queue is empty between pairs; the log queue is \
         capped at 65,536 entries."
    );
    if let Some(kib) = sweep.peak_rss_kib {
        let _ = writeln!(
            md,
            "\nPeak resident set of the whole sweep (rendering and the parallel runs included, \
             `VmHWM`): {:.0} MiB.",
            kib as f64 / 1024.0
        );
    }
    md
}
