//! The whole chain for one stereo sequence, frame pair by frame pair: pixels into the device
//! (fabric model and soft-core driver), wire bytes back through the host driver, then the
//! estimator and the Kalman filter, giving one [`FrameRecord`] per pair.
//!
//! `run`, `eval` and `demo` all go through here, so every number they print comes from the
//! same path the bytes take on a real head: nothing reaches the estimator except through the
//! wire format. The device is the in-process one unless [`Session::with_device`] is given
//! another (`stereocal hil` gives it the firmware under QEMU).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::FabricConfig;

use crate::calib::Calibration;
use crate::driver::{Driver, DriverError, FrameOutcome, PairOutcome, ReceivedFrame};
use crate::estimator::{EstimatorConfig, FrameEstimate, VergeEstimator};
use crate::kalman::{KalmanConfig, Measurement, TimeWentBackwards, VergeFilter};
use crate::link::{FrameInput, InProcessLink, Link, LinkError, LinkProtection, Threaded};
use crate::misalignment::{MisalignmentWindow, WindowConfig};
use crate::output::record::{FrameRecord, FrameStatus, LinkLoss};
use crate::output::summary::RunCost;

/// Settings of a session.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionConfig {
    /// The per-pair estimate.
    pub estimator: EstimatorConfig,
    /// The filter over the pairs' raw verges.
    pub kalman: KalmanConfig,
    /// Which Sobel output the fabric streams (full rows, as the thesis, or 16x16 patches).
    pub sobel_output: SobelOutput,
    /// Learn the head's fixed misalignments over a sliding window of frames and correct each
    /// frame's verge by what holding them moves its refit (constrained model only; the general
    /// model frees them in every frame); `None`: each frame alone. The default learns the roll
    /// ([`WindowConfig::roll`]).
    pub misalignment: Option<WindowConfig>,
    /// How the link is guarded against damage (packing, error correction, loss limit).
    pub link: LinkProtection,
    /// Keep each frame's consistent point pairs in its record (`matches.csv`); off by default,
    /// as a record then holds a few hundred pairs of 40 bytes.
    pub keep_pairs: bool,
}

impl Default for SessionConfig {
    fn default() -> Self {
        Self {
            estimator: EstimatorConfig::default(),
            kalman: KalmanConfig::default(),
            sobel_output: SobelOutput::Rows,
            misalignment: Some(WindowConfig::roll()),
            link: LinkProtection::clean(),
            keep_pairs: false,
        }
    }
}

impl SessionConfig {
    /// The defaults with each frame estimated alone (no misalignment window): a window's
    /// estimate of a pair depends on the frames before it, so only per-frame estimates let a
    /// run that lost or damaged some frames give every intact pair the clean run's verge to
    /// the bit.
    pub fn per_frame() -> Self {
        Self {
            misalignment: None,
            ..Self::default()
        }
    }
}

/// The fabric configuration a session writes for `width` x `height` frames: the register
/// defaults with the host's contrast threshold (the type, `FabricConfig`, is the map's).
///
/// The contrast threshold is 1 grey level (256 in the register's Q8.8) rather than the
/// register's reset value (8 grey levels, Lowe's 0.03 of full scale): the verge estimate gains
/// from every stable keypoint, and the ratio test and RANSAC reject the weak ones that do not
/// match.
pub fn tuned_fabric_config(width: u16, height: u16, sobel_output: SobelOutput) -> FabricConfig {
    FabricConfig {
        width,
        height,
        contrast_threshold: 1 << 8,
        sobel_output,
        ..FabricConfig::default()
    }
}

/// Why a session stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SessionError {
    /// Opening the device, or handing it a pair's pixels, failed.
    #[error("device link: {0}")]
    Link(#[from] LinkError),
    /// The host driver failed: Hello or the configuration went wrong, the link failed under
    /// it, or no pair came to [`Session::receive`] within the answer timeout.
    #[error("device: {0}")]
    Driver(#[from] DriverError),
    /// A pair's capture time is before the previous pair's.
    #[error("frame {frame}: {source}")]
    Time {
        /// The session frame index of the pair.
        frame: usize,
        /// The two timestamps.
        source: TimeWentBackwards,
    },
    /// The device delivered a newer frame id than any pair submitted: host and device
    /// disagree about which images they are.
    #[error("frame {frame}: the device answered with frame id {got}, expected {expected}")]
    OutOfStep {
        /// The session frame index of the pair.
        frame: usize,
        /// The device's frame id that arrived.
        got: u32,
        /// The device's frame id of the pair submitted.
        expected: u32,
    },
    /// A pair's size is not the size the fabric was configured for.
    #[error(
        "frame {frame}: image is {width}x{height}, the fabric was configured for {configured_w}x{configured_h}"
    )]
    SizeChanged {
        /// The session frame index of the pair.
        frame: usize,
        /// Its width in pixels.
        width: usize,
        /// Its height in pixels.
        height: usize,
        /// The fabric's configured width in pixels.
        configured_w: u16,
        /// The fabric's configured height in pixels.
        configured_h: u16,
    },
}

/// What was spent on the pairs processed so far.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SessionCost {
    /// Pairs recorded, dropped ones included.
    pub pairs: usize,
    /// Wall time inside [`Session::process`] (device, driver, estimator, filter).
    pub elapsed: Duration,
    /// The part of `elapsed` spent in the estimator (matching, RANSAC, refinement): the
    /// device model dominates `elapsed`, so host-side choices such as RANSAC only show here.
    pub estimating: Duration,
    /// Link bytes of the delivered pairs.
    pub wire_bytes: u64,
}

/// What the summary reports of a session's cost.
impl From<SessionCost> for RunCost {
    fn from(cost: SessionCost) -> Self {
        RunCost {
            ms_per_frame_pair: cost.ms_per_pair(),
            wire_bytes_per_pair: cost.wire_bytes_per_pair(),
        }
    }
}

impl SessionCost {
    /// Milliseconds of [`SessionCost::elapsed`] per pair; 0 before the first.
    pub fn ms_per_pair(&self) -> f64 {
        if self.pairs == 0 {
            0.0
        } else {
            self.elapsed.as_secs_f64() * 1e3 / self.pairs as f64
        }
    }

    /// Estimator milliseconds per pair (see [`SessionCost::estimating`]).
    pub fn estimator_ms_per_pair(&self) -> f64 {
        if self.pairs == 0 {
            0.0
        } else {
            self.estimating.as_secs_f64() * 1e3 / self.pairs as f64
        }
    }

    /// Link bytes per pair (see [`SessionCost::wire_bytes`]); 0 before the first.
    pub fn wire_bytes_per_pair(&self) -> f64 {
        if self.pairs == 0 {
            0.0
        } else {
            self.wire_bytes as f64 / self.pairs as f64
        }
    }
}

/// A pair handed to the device whose record is not out yet.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    frame: usize,
    /// Whether images went to the device (a pair the grabber lost did not).
    submitted: bool,
    timestamp_us: u64,
    truth_deg: Option<f64>,
    /// The head's own verge reading for the pair (encoders or commanded), if it sent one.
    encoder_verge_deg: Option<f64>,
}

/// One stereo head, from pixels to filtered verge angle, over link `L`.
///
/// Where the host provides the pixels (`L` has a [`FrameInput`]), pairs go in with
/// [`Session::submit`] and records come out in the same order. A device with a
/// [`lookahead`](FrameInput::lookahead) works on the next pairs while the host decodes and
/// estimates the oldest, so `submit` returns a record only once more pairs are in flight than
/// the device takes ahead, and [`Session::flush`] collects the rest; [`Session::process`] is
/// one pair in, its record out. A head with its own cameras sends pairs when it takes them:
/// [`Session::receive`] reads the next. Both match the device's frame ids by one rule: late
/// reports of older frames are skipped, and a newer id means the expected frame was lost.
pub struct Session<L: Link = Threaded> {
    driver: Driver<L>,
    fabric: FabricConfig,
    estimator: VergeEstimator,
    filter: VergeFilter,
    misalignment: Option<MisalignmentWindow>,
    /// The device's id of the next pair submitted: it numbers frames from 0 after it starts
    /// (the firmware driver's channel), one per pair.
    next_frame_id: u32,
    in_flight: VecDeque<InFlight>,
    /// A pair that came from a device with its own cameras before its session frame did
    /// (the device skipped ids): it waits for [`Session::receive`] to reach it. A session
    /// whose host provides the pixels never holds one: a skipped id stops it.
    early: Option<PairOutcome>,
    /// Capture time of the last pair filtered.
    last_timestamp_us: Option<u64>,
    /// The head's verge reading for the next pair submitted ([`Session::encoder_reading`]).
    next_encoder_deg: Option<f64>,
    /// [`SessionConfig::keep_pairs`].
    keep_pairs: bool,
    cost: SessionCost,
}

impl Session {
    /// Opens the in-process device in a thread of its own (it works on the next pair while
    /// the host estimates the last), says Hello, configures the fabric for `width` x `height`
    /// and reads the registers back.
    pub fn new(
        calib: Calibration,
        width: u16,
        height: u16,
        config: SessionConfig,
    ) -> Result<Self, SessionError> {
        let device = Threaded::new(InProcessLink::new()?, "in-process")?;
        Self::with_device(device, calib, width, height, config)
    }
}

impl<L: Link> Session<L> {
    /// [`Session::new`] on `device`: says Hello, configures the fabric for `width` x
    /// `height`, reads the registers back and enables the device.
    pub fn with_device(
        device: L,
        calib: Calibration,
        width: u16,
        height: u16,
        config: SessionConfig,
    ) -> Result<Self, SessionError> {
        let timeout = device.answer_timeout();
        let mut driver = Driver::new(device);
        driver.request_fec(config.link.fec);
        driver.set_loss_limit(config.link.loss_limit);
        driver.set_refinement_reach(config.estimator.subpixel.map(|s| s.reach_px()));
        driver.hello(timeout)?;
        let fabric = config
            .link
            .pack(tuned_fabric_config(width, height, config.sobel_output));
        driver.configure(&fabric, timeout)?;
        driver.enable()?;
        Ok(Self {
            driver,
            fabric,
            estimator: VergeEstimator::new(calib, config.estimator),
            misalignment: config
                .misalignment
                .map(|w| MisalignmentWindow::new(&calib.extrinsics, w, config.estimator.refine)),
            filter: VergeFilter::new(config.kalman),
            next_frame_id: 0,
            in_flight: VecDeque::new(),
            early: None,
            last_timestamp_us: None,
            next_encoder_deg: None,
            keep_pairs: config.keep_pairs,
            cost: SessionCost::default(),
        })
    }

    /// The fabric configuration in force.
    pub fn fabric(&self) -> &FabricConfig {
        &self.fabric
    }

    /// The device, e.g. to switch a fault injector or read an emulator's state.
    pub fn device_mut(&mut self) -> &mut L {
        self.driver.link_mut()
    }

    /// The head's own verge (deg, from its encoders or the angles it was commanded to) at the
    /// capture of the next pair submitted: the filter predicts the change since the last
    /// reading instead of detecting it (see [`crate::kalman`]).
    pub fn encoder_reading(&mut self, verge_deg: f64) {
        self.next_encoder_deg = Some(verge_deg);
    }

    /// Cost so far.
    pub fn cost(&self) -> SessionCost {
        self.cost
    }

    /// The record of the next pair from a device that captures with its own cameras
    /// ([`OwnCameras`](crate::link::OwnCameras)): session frame `frame`, the device's next
    /// frame id. The filter runs on the capture time the device stamped; a pair that arrived
    /// damaged, or whose id the device skipped (its frames were lost on the link), is recorded
    /// as dropped, its time unknown: the filter carries its state on to the next pair that
    /// has one. Waiting longer than the device's answer timeout is an error, as is a closed
    /// link: the caller decides whether that ends the stream.
    ///
    /// A head may have been streaming before this host connected: the first pair's id, not
    /// 0, is where the session's numbering starts. A head that sends an `Encoders` reading
    /// for the capture gives the filter its verge change as control input.
    pub fn receive(&mut self, frame: usize) -> Result<FrameRecord, SessionError> {
        let mut expected = self.next_frame_id;
        // No record yet: the device's numbering is adopted.
        let outcome = match self.next_arrival(&mut expected, self.cost.pairs == 0)? {
            Arrival::Expected(outcome) => Some(outcome),
            // A newer pair waits for its own frame.
            Arrival::Ahead(outcome) => {
                self.early = Some(outcome);
                None
            }
        };
        self.next_frame_id = expected.wrapping_add(1);
        let encoder_verge_deg = self
            .driver
            .take_encoders(expected)
            .map(|e| e.verge_udeg() as f64 * 1e-6);
        let start = Instant::now();
        let captured = match &outcome {
            Some(PairOutcome::Pair {
                left: FrameOutcome::Delivered(left),
                right: FrameOutcome::Delivered(_),
            }) => left.features.timestamp_us,
            _ => self.last_timestamp_us.unwrap_or(0),
        };
        let record = self.conclude(
            frame,
            outcome,
            "the device skipped its frame id (its packets were lost on the link)",
            captured,
            encoder_verge_deg,
            None,
        )?;
        self.cost.elapsed += start.elapsed();
        Ok(record)
    }

    /// The next pair the driver delivers for device frame id `expected`, or the first with a
    /// newer id. With `adopt`, the first pair's id becomes `expected` (a head that streamed
    /// before this host connected).
    ///
    /// Ids wrap: "older" is within half the id space behind. A link that loses bytes can lose
    /// a frame's end: the driver then times out on the pair, and reports the frame as damaged
    /// only later, when the next frame's packets show the old one will never finish. Such
    /// late reports carry an older id than the one expected and are skipped (that frame was
    /// already recorded as dropped), so a fault costs the frames it hit and never shifts a
    /// later estimate onto the wrong frame.
    fn next_arrival(&mut self, expected: &mut u32, adopt: bool) -> Result<Arrival, DriverError> {
        let timeout = self.driver.link().answer_timeout();
        loop {
            let outcome = match self.early.take() {
                Some(outcome) => outcome,
                None => self.driver.next_pair(timeout)?,
            };
            let got = outcome.frame_id();
            if adopt {
                *expected = got;
            }
            if got == *expected {
                self.cost.wire_bytes += outcome.wire_bytes();
                return Ok(Arrival::Expected(outcome));
            }
            if expected.wrapping_sub(got) > u32::MAX / 2 {
                return Ok(Arrival::Ahead(outcome));
            }
        }
    }

    /// Estimates and filters one pair's outcome into its record; `missing` says why there is
    /// none when `outcome` is `None`.
    fn conclude(
        &mut self,
        frame: usize,
        outcome: Option<PairOutcome>,
        missing: &str,
        timestamp_us: u64,
        encoder_verge_deg: Option<f64>,
        truth_deg: Option<f64>,
    ) -> Result<FrameRecord, SessionError> {
        let mut record = FrameRecord::dropped(frame, truth_deg);
        record.dropped_because = match &outcome {
            Some(outcome) => damage_of(outcome),
            None => Some(missing.to_owned()),
        };
        // What the device said on its own since the last pair (a frame it could not run)
        // explains a drop better than the host's view of the bytes.
        let reports = self.driver.take_device_errors();
        if let (Some(why), false) = (&mut record.dropped_because, reports.is_empty()) {
            for r in reports {
                why.push_str(&format!(
                    "; the device reported {:?} (detail {:#x}) in packet seq {}",
                    r.report.code, r.report.detail, r.seq
                ));
            }
        }
        let measurement = match outcome {
            Some(PairOutcome::Pair {
                left: FrameOutcome::Delivered(left),
                right: FrameOutcome::Delivered(right),
            }) => {
                record.status = FrameStatus::NoEstimate;
                record.link_loss = link_loss(&left, &right);
                let estimating = Instant::now();
                let estimate = self.estimator.estimate(&left.features, &right.features);
                let estimate = estimate.map(|est| self.refit_misaligned(est, &mut record));
                self.cost.estimating += estimating.elapsed();
                match estimate {
                    Ok(est) => {
                        record.raw_verge_deg = Some(est.verge_deg);
                        record.raw_sigma_deg = Some(est.sigma_deg);
                        record.matches = est.matches;
                        record.inliers = est.inliers;
                        record.keypoints_per_octave = est.keypoints_per_octave;
                        record.matches_per_octave = est.matches_per_octave;
                        if self.keep_pairs {
                            record.consistent_pairs = est.consistent_pairs;
                        }
                        record.status = match record.link_loss {
                            Some(_) => FrameStatus::Salvaged,
                            None => FrameStatus::Ok,
                        };
                        Some(Measurement {
                            verge_deg: est.verge_deg,
                            sigma_deg: est.sigma_deg,
                        })
                    }
                    Err(_) => None,
                }
            }
            Some(_) | None => None,
        };
        let filtered = self
            .filter
            .step_with_encoders(timestamp_us, measurement, encoder_verge_deg)
            .map_err(|source| SessionError::Time { frame, source })?;
        self.last_timestamp_us = Some(timestamp_us);
        if record.status.has_estimate() {
            if let Some(f) = filtered {
                record.filtered_verge_deg = Some(f.verge_deg);
                record.filtered_sigma_deg = Some(f.sigma_deg);
            }
        }
        self.cost.pairs += 1;
        Ok(record)
    }

    /// With a misalignment window: hands the frame's consistent matches to it and takes the
    /// frame's yaws corrected for the learned misalignments ([`MisalignmentWindow::update`]),
    /// recording the window's misalignment estimate. The frame's σ stays its own: the learned
    /// angles' uncertainty, which falls with every frame the window sees, adds little to it.
    /// A frame the window cannot refit keeps its own estimate.
    fn refit_misaligned(
        &mut self,
        mut est: FrameEstimate,
        record: &mut FrameRecord,
    ) -> FrameEstimate {
        let (Some(window), Some(angles)) = (&mut self.misalignment, est.angles) else {
            return est;
        };
        if let Ok(corrected) = window.update(std::mem::take(&mut est.consistent), angles) {
            est.verge_deg = corrected.verge_deg();
            est.angles = Some(corrected);
        }
        record.misalignment = Some(window.estimate());
        est
    }

    fn check_size(
        &self,
        frame: usize,
        (width, height): (usize, usize),
    ) -> Result<(), SessionError> {
        if (width, height)
            == (
                usize::from(self.fabric.width),
                usize::from(self.fabric.height),
            )
        {
            Ok(())
        } else {
            Err(SessionError::SizeChanged {
                frame,
                width,
                height,
                configured_w: self.fabric.width,
                configured_h: self.fabric.height,
            })
        }
    }
}

/// A pair the driver delivered, against the device frame id the session expects.
enum Arrival {
    Expected(PairOutcome),
    /// A newer id: the expected frame never came whole.
    Ahead(PairOutcome),
}

impl<L: Link + FrameInput> Session<L> {
    /// Processes frame pair `frame` captured at `timestamp_us` and returns the oldest record
    /// in flight: this pair's own when it is the only one (the caller did not
    /// [`submit`](Session::submit) ahead). `images` is `None` for a pair the grabber lost: the
    /// filter predicts across it and the record says `dropped`. A pair damaged on the link is
    /// dropped the same way, never estimated.
    pub fn process(
        &mut self,
        frame: usize,
        images: Option<(&[u8], &[u8])>,
        image_size: (usize, usize),
        timestamp_us: u64,
        truth_deg: Option<f64>,
    ) -> Result<FrameRecord, SessionError> {
        let pair = self.start(frame, images, image_size, timestamp_us, truth_deg)?;
        self.in_flight.push_back(pair);
        let oldest = self.in_flight.pop_front().unwrap_or(pair);
        self.finish(oldest)
    }

    /// Hands pair `frame` to the device (see [`Session::process`] for the arguments) and
    /// returns the oldest record once more pairs are in flight than the device works ahead.
    pub fn submit(
        &mut self,
        frame: usize,
        images: Option<(&[u8], &[u8])>,
        image_size: (usize, usize),
        timestamp_us: u64,
        truth_deg: Option<f64>,
    ) -> Result<Option<FrameRecord>, SessionError> {
        let pair = self.start(frame, images, image_size, timestamp_us, truth_deg)?;
        self.in_flight.push_back(pair);
        if self.in_flight.len() > self.driver.link().lookahead() {
            self.flush()
        } else {
            Ok(None)
        }
    }

    /// The record of the oldest pair in flight; `None` when there is none.
    pub fn flush(&mut self) -> Result<Option<FrameRecord>, SessionError> {
        match self.in_flight.pop_front() {
            Some(pair) => self.finish(pair).map(Some),
            None => Ok(None),
        }
    }

    /// Hands the images, if any, to the device.
    fn start(
        &mut self,
        frame: usize,
        images: Option<(&[u8], &[u8])>,
        image_size: (usize, usize),
        timestamp_us: u64,
        truth_deg: Option<f64>,
    ) -> Result<InFlight, SessionError> {
        let start = Instant::now();
        if let Some((left, right)) = images {
            self.check_size(frame, image_size)?;
            self.driver
                .link_mut()
                .submit_pair(left, right, timestamp_us)?;
        }
        self.cost.elapsed += start.elapsed();
        Ok(InFlight {
            frame,
            submitted: images.is_some(),
            timestamp_us,
            truth_deg,
            encoder_verge_deg: self.next_encoder_deg.take(),
        })
    }

    /// Reads the pair back, estimates and filters it.
    fn finish(&mut self, pair: InFlight) -> Result<FrameRecord, SessionError> {
        let start = Instant::now();
        let (outcome, missing) = if pair.submitted {
            (
                self.receive_pair(pair.frame)?,
                "no complete pair arrived before the answer timeout",
            )
        } else {
            (None, "the grabber lost the pair")
        };
        let record = self.conclude(
            pair.frame,
            outcome,
            missing,
            pair.timestamp_us,
            pair.encoder_verge_deg,
            pair.truth_deg,
        )?;
        self.cost.elapsed += start.elapsed();
        Ok(record)
    }

    /// The outcome of the pair just submitted; `None` when it never arrived complete (see
    /// [`Session::next_arrival`] for late reports of older frames). A pair with a newer id
    /// than any submitted means host and device disagree about which images they are: that
    /// stops the session.
    fn receive_pair(&mut self, frame: usize) -> Result<Option<PairOutcome>, SessionError> {
        let mut expected = self.next_frame_id;
        self.next_frame_id = expected.wrapping_add(1);
        match self.next_arrival(&mut expected, false) {
            Ok(Arrival::Expected(outcome)) => Ok(Some(outcome)),
            Ok(Arrival::Ahead(outcome)) => Err(SessionError::OutOfStep {
                frame,
                got: outcome.frame_id(),
                expected,
            }),
            Err(DriverError::Timeout { .. }) => Ok(None),
            Err(e) => Err(e.into()),
        }
    }
}

/// What the driver found wrong with a pair, `None` when both camera frames arrived whole.
/// What the link cost a delivered pair, `None` when both frames arrived whole.
fn link_loss(left: &ReceivedFrame, right: &ReceivedFrame) -> Option<LinkLoss> {
    let lost = [&left.salvage, &right.salvage].map(|s| {
        s.as_ref().map(|s| LinkLoss {
            packets_lost: s.packets_lost,
            keypoints_lost: s.keypoints_lost,
        })
    });
    match lost {
        [None, None] => None,
        [l, r] => {
            let (l, r) = (l.unwrap_or_default(), r.unwrap_or_default());
            Some(LinkLoss {
                packets_lost: l.packets_lost + r.packets_lost,
                keypoints_lost: l.keypoints_lost + r.keypoints_lost,
            })
        }
    }
}

fn damage_of(outcome: &PairOutcome) -> Option<String> {
    let damaged = |f: &FrameOutcome| match f {
        FrameOutcome::Delivered(_) => None,
        FrameOutcome::Damaged(d) => Some(format!(
            "{:?} camera frame {} damaged: {}",
            d.camera, d.frame_id, d.damage
        )),
    };
    match outcome {
        PairOutcome::Pair { left, right } => {
            let found: Vec<String> = [left, right].into_iter().filter_map(damaged).collect();
            (!found.is_empty()).then(|| found.join("; "))
        }
        PairOutcome::Single(f) => Some(format!(
            "only the {:?} camera's frame {} arrived{}",
            f.camera(),
            f.frame_id(),
            damaged(f).map_or(String::new(), |d| format!(" ({d})"))
        )),
    }
}
