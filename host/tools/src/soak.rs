//! The soak: many synthetic frames through a [`Session`] on the in-process device with a
//! [`FaultLink`] damaging its bytes the whole time. Faults must cost frames, never
//! correctness, and nothing may grow with the number of frames.
//!
//! The frames are **cycled**: a small set of rendered frame pairs is submitted over and over
//! with advancing timestamps (the road's head drives on, so a long sequence would leave the
//! furnished scene, and holding thousands of rendered pairs would hide a leak in the
//! noise). The truth of each soak frame is exactly that of the rendered pair it reuses.
//! Because the estimator is deterministic, an intact pair must give the bit-identical raw
//! verge of the same pair run once without faults: every delivered frame is compared with
//! that clean result, and any difference is a **wrong** estimate. The accuracy bar is
//! checked on the estimated frames against the truth.
//!
//! Memory is the process's resident set (`VmRSS` of `/proc/self/status`), sampled every
//! [`SoakConfig::sample_every`] frames; it is **flat** when the last sample is within
//! [`FLAT_KIB`] of the second one (the first is taken while allocators warm up).
//!
//! `stereocal reliability --soak N` writes the result as a section of `docs/RELIABILITY.md`
//! ([`markdown`], [`splice`]).

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use crate::reliability::{is_wrong_estimate, FaultKind};
use crate::workload::{Workload, WorkloadError};
use stereocal::link::{BadRate, FaultCounts, FaultLink, InProcessLink, LinkError, LinkProtection};
use stereocal::output::record::FrameStatus;
use stereocal::session::{Session, SessionConfig, SessionError};

/// The accuracy bar of the synthetic road: median raw error on estimated frames (degrees).
pub const MEDIAN_BAR_DEG: f64 = 0.01;

/// Most the resident set may grow between the second and the last sample (KiB).
pub const FLAT_KIB: u64 = 4 * 1024;

/// Marks the soak's section in `docs/RELIABILITY.md`, so the sweep and the soak can each
/// rewrite their own part.
pub const SECTION_BEGIN: &str = "<!-- soak: begin (written by stereocal reliability --soak) -->";
pub const SECTION_END: &str = "<!-- soak: end -->";

/// Why a soak stopped (a fault never is a reason: those cost frames).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SoakError {
    #[error(transparent)]
    Workload(#[from] WorkloadError),
    #[error("device link: {0}")]
    Link(#[from] LinkError),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error(transparent)]
    Rate(#[from] BadRate),
    #[error("the soak needs at least one frame, one rendered pair and a sampling interval")]
    Empty,
}

/// Settings of a soak.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoakConfig {
    /// Frame pairs submitted.
    pub frames: usize,
    /// Rendered pairs cycled through.
    pub cycle: usize,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    /// Faults, on for every frame.
    pub kind: FaultKind,
    pub rate: f64,
    /// Frames between two samples of the resident set.
    pub sample_every: usize,
}

/// The resident set after `frame` frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemorySample {
    pub frame: usize,
    pub rss_kib: u64,
}

/// What the clean run made of one rendered pair.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reference {
    /// Raw verge of the clean run (`None`: delivered without an estimate).
    raw_verge_deg: Option<f64>,
    truth_deg: f64,
}

/// The result of a soak.
#[derive(Debug, Clone, PartialEq)]
pub struct Soak {
    pub config: SoakConfig,
    /// Frames submitted.
    pub frames: usize,
    /// Frames delivered, intact or salvaged (estimated or not).
    pub delivered: usize,
    /// Delivered frames that had lost packets (salvaged).
    pub salvaged: usize,
    /// Frames damaged on the link and dropped.
    pub dropped: usize,
    /// Frames with an estimate.
    pub estimated: usize,
    /// Delivered frames whose result is wrong against the clean run's for the same rendered
    /// pair ([`is_wrong_estimate`]).
    pub wrong: usize,
    /// Rendered pairs the clean run estimated.
    pub clean_estimated: usize,
    /// Median and largest raw error of the clean run over the rendered pairs (degrees).
    pub clean_median_deg: Option<f64>,
    pub clean_max_deg: Option<f64>,
    /// Median and largest raw error over the soak's estimated frames (degrees).
    pub median_deg: Option<f64>,
    pub max_deg: Option<f64>,
    /// What the fault link did.
    pub faults: FaultCounts,
    /// Resident set every [`SoakConfig::sample_every`] frames (empty where `/proc` is not).
    pub memory: Vec<MemorySample>,
    pub elapsed: Duration,
}

impl Soak {
    /// The sample the growth is measured from: the second one (or the only one).
    pub fn baseline(&self) -> Option<MemorySample> {
        self.memory.get(1).or(self.memory.first()).copied()
    }

    /// Growth of the resident set from [`Soak::baseline`] to the last sample (KiB; negative
    /// when it shrank).
    pub fn growth_kib(&self) -> Option<i64> {
        let base = self.baseline()?;
        let last = self.memory.last()?;
        Some(last.rss_kib as i64 - base.rss_kib as i64)
    }

    /// Whether memory stayed flat (within [`FLAT_KIB`]).
    pub fn memory_flat(&self) -> bool {
        self.growth_kib().is_some_and(|g| g <= FLAT_KIB as i64)
    }

    /// Whether the estimated frames meet the accuracy bar.
    pub fn accurate(&self) -> bool {
        self.median_deg.is_some_and(|m| m <= MEDIAN_BAR_DEG)
    }

    /// Zero wrong estimates, some frames estimated within the bar, memory flat.
    pub fn passed(&self) -> bool {
        self.wrong == 0 && self.estimated > 0 && self.accurate() && self.memory_flat()
    }
}

/// `VmRSS` of `/proc/self/status`: what the process has resident now.
pub fn rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Runs the soak; `progress` is called with the number of frames done.
pub fn soak(config: SoakConfig, progress: &dyn Fn(usize)) -> Result<Soak, SoakError> {
    if config.frames == 0 || config.cycle == 0 || config.sample_every == 0 {
        return Err(SoakError::Empty);
    }
    let start = Instant::now();
    // The cycled pairs, held once for the whole soak.
    let workload = Workload::road(config.cycle, config.seed, config.width, config.height)?;
    let (w, h, size, calib) = (
        workload.width,
        workload.height,
        workload.size(),
        workload.calib,
    );

    // The faults change which frames come before a pair.
    let per_frame = SessionConfig::per_frame();
    // The clean reference: each rendered pair once, without faults.
    let mut clean = Session::with_device(InProcessLink::new()?, calib, w, h, per_frame)?;
    let mut reference = Vec::with_capacity(workload.len());
    for (index, pair) in workload.pairs.iter().enumerate() {
        let record = clean.process(
            index,
            Some((&pair.left, &pair.right)),
            size,
            workload.timestamp_us(index),
            Some(pair.truth_deg),
        )?;
        reference.push(Reference {
            raw_verge_deg: record.raw_verge_deg,
            truth_deg: pair.truth_deg,
        });
    }
    drop(clean);
    let mut clean_errors: Vec<f64> = reference
        .iter()
        .filter_map(|r| r.raw_verge_deg.map(|v| (v - r.truth_deg).abs()))
        .collect();
    let clean_estimated = clean_errors.len();
    let (clean_median_deg, clean_max_deg) = median_max(&mut clean_errors);

    // The soak: faults on all the time.
    let mut link = FaultLink::new(
        InProcessLink::new()?,
        config.kind.config(config.rate, config.seed),
    )?;
    link.set_active(true);
    // Every frame goes over a damaging link, which is what the noisy-link guard is for.
    let noisy = SessionConfig {
        link: LinkProtection::noisy(),
        ..per_frame
    };
    let mut session = Session::with_device(link, calib, w, h, noisy)?;
    let (mut delivered, mut salvaged, mut dropped, mut wrong) = (0, 0, 0, 0);
    let mut errors = Vec::new();
    let mut memory = Vec::new();
    for frame in 0..config.frames {
        let slot = frame % workload.len();
        let (pair, clean) = (&workload.pairs[slot], &reference[slot]);
        let record = session.process(
            frame,
            Some((&pair.left, &pair.right)),
            size,
            workload.timestamp_us(frame),
            Some(pair.truth_deg),
        )?;
        if record.status == FrameStatus::Dropped {
            dropped += 1;
        } else {
            delivered += 1;
            let is_salvaged = record.link_loss.is_some();
            salvaged += usize::from(is_salvaged);
            let is_wrong = match (record.raw_verge_deg, clean.raw_verge_deg) {
                (Some(v), Some(c)) => {
                    let sigma = record.raw_sigma_deg.unwrap_or(f64::NAN);
                    is_wrong_estimate(v, sigma, is_salvaged, c)
                }
                // A salvaged pair may lack the estimate the whole pair had.
                (None, Some(_)) => !is_salvaged,
                (Some(_), None) => true,
                (None, None) => false,
            };
            wrong += usize::from(is_wrong);
            if let Some(v) = record.raw_verge_deg {
                errors.push((v - pair.truth_deg).abs());
            }
        }
        let done = frame + 1;
        if done % config.sample_every == 0 {
            if let Some(rss_kib) = rss_kib() {
                memory.push(MemorySample {
                    frame: done,
                    rss_kib,
                });
            }
        }
        progress(done);
    }
    let estimated = errors.len();
    let (median_deg, max_deg) = median_max(&mut errors);
    Ok(Soak {
        config,
        frames: config.frames,
        delivered,
        salvaged,
        dropped,
        estimated,
        wrong,
        clean_estimated,
        clean_median_deg,
        clean_max_deg,
        median_deg,
        max_deg,
        faults: session.device_mut().counts(),
        memory,
        elapsed: start.elapsed(),
    })
}

/// Median and maximum of `values` (sorted in place); `None` when empty.
fn median_max(values: &mut [f64]) -> (Option<f64>, Option<f64>) {
    if values.is_empty() {
        return (None, None);
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let median = if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    };
    (Some(median), values.last().copied())
}

fn deg(v: Option<f64>) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.4}"))
}

/// The soak's section of `docs/RELIABILITY.md` (with its markers); `command` is the command
/// line that produced it.
pub fn markdown(soak: &Soak, command: &str) -> String {
    let c = soak.config;
    let (name, unit) = c.kind.label();
    let f = soak.faults;
    let injected = f.bits_flipped
        + f.bytes_dropped
        + f.packets_truncated
        + f.packets_duplicated
        + f.packets_reordered
        + f.stalls;
    let mut md = String::new();
    let _ = writeln!(md, "{SECTION_BEGIN}");
    let _ = writeln!(md, "## Soak\n");
    let _ = writeln!(
        md,
        "Generated by `{command}` ({:.0} s on this machine); do not edit by hand.\n",
        soak.elapsed.as_secs_f64()
    );
    let _ = writeln!(
        md,
        "{} frame pairs of the road scene at {}x{} (seed {}) go through a session \
         (`host/src/session.rs`: device, driver, estimator, filter) on the in-process device, \
         with the fault link damaging the device's bytes **on every frame**: {name} at {:.0e} \
         {unit}, on the noisy-link guard (`--noisy-link`: error correction, 64-pixel row \
         segments, 8-point batches). The frames are **cycled**: {} rendered pairs are submitted over and over \
         with advancing timestamps (the road's head would otherwise drive out of the \
         furnished scene), and each soak frame's truth is exactly that of the rendered pair it \
         reuses. Each rendered pair also goes once through a session without faults: an \
         intact pair gives that clean run's raw verge to the bit, and a salvaged one (it lost \
         packets) must lie within its own sigma of it; a delivered frame that does not is a \
         **wrong** estimate. The accuracy bar of the synthetic road \
         (median raw error ≤ {MEDIAN_BAR_DEG}°) is checked on the soak's estimated frames.\n",
        soak.frames, c.width, c.height, c.seed, c.rate, c.cycle,
    );
    let _ = writeln!(md, "| quantity | value |\n|---|---|");
    let _ = writeln!(md, "| frame pairs submitted | {} |", soak.frames);
    let _ = writeln!(md, "| faults injected | {injected} |");
    let _ = writeln!(
        md,
        "| pairs delivered intact | {} |",
        soak.delivered - soak.salvaged
    );
    let _ = writeln!(md, "| pairs delivered salvaged | {} |", soak.salvaged);
    let _ = writeln!(md, "| pairs damaged and dropped | {} |", soak.dropped);
    let _ = writeln!(md, "| pairs estimated | {} |", soak.estimated);
    let _ = writeln!(md, "| **wrong estimates** | **{}** |", soak.wrong);
    let _ = writeln!(
        md,
        "| raw error median / max, estimated frames (deg) | {} / {} |",
        deg(soak.median_deg),
        deg(soak.max_deg)
    );
    let _ = writeln!(
        md,
        "| clean run: rendered pairs estimated, raw error median / max (deg) | {} of {}, {} / {} |",
        soak.clean_estimated,
        c.cycle,
        deg(soak.clean_median_deg),
        deg(soak.clean_max_deg)
    );
    let _ = writeln!(
        md,
        "| peak bytes held by the fault link | {} |",
        f.peak_buffered
    );
    match (soak.baseline(), soak.memory.last(), soak.growth_kib()) {
        (Some(base), Some(last), Some(growth)) => {
            let _ = writeln!(
                md,
                "| resident set at frame {} / at frame {} (MiB) | {:.1} / {:.1} |",
                base.frame,
                last.frame,
                base.rss_kib as f64 / 1024.0,
                last.rss_kib as f64 / 1024.0
            );
            let _ = writeln!(
                md,
                "| growth over those frames (MiB; flat: ≤ {:.0}) | {:+.2} |",
                FLAT_KIB as f64 / 1024.0,
                growth as f64 / 1024.0
            );
        }
        _ => {
            let _ = writeln!(
                md,
                "| resident set | not measured (fewer frames than one sampling interval, or no `/proc/self/status`) |"
            );
        }
    }
    if !soak.memory.is_empty() {
        let _ = writeln!(
            md,
            "\nResident set (`VmRSS`) every {} frames, MiB: {}.",
            c.sample_every,
            soak.memory
                .iter()
                .map(|s| format!("{} → {:.1}", s.frame, s.rss_kib as f64 / 1024.0))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let verdict = if soak.passed() {
        "**Zero wrong estimates, the estimated frames within the accuracy bar, memory flat.**"
    } else {
        "**REQUIREMENT NOT MET**: see the wrong estimates, the accuracy or the memory above."
    };
    let _ = writeln!(md, "\n{verdict}");
    let _ = writeln!(md, "{SECTION_END}");
    md
}

/// The soak's section of `doc`, markers included, if it has one.
pub fn section(doc: &str) -> Option<&str> {
    let begin = doc.find(SECTION_BEGIN)?;
    let end = doc[begin..].find(SECTION_END)? + begin + SECTION_END.len();
    let end = if doc[end..].starts_with('\n') {
        end + 1
    } else {
        end
    };
    Some(&doc[begin..end])
}

/// `doc` with its soak section replaced by `section` (appended when it had none).
pub fn splice(doc: &str, new_section: &str) -> String {
    match section(doc) {
        Some(old) => doc.replacen(old, new_section, 1),
        None => {
            let mut out = doc.trim_end().to_string();
            out.push_str("\n\n");
            out.push_str(new_section);
            out
        }
    }
}
