//! Kalman filtering of the verge angle and its rate (thesis 5.2.1 used a first-order filter).
//!
//! A verge head spends most of its time still and now and then turns fast, and one
//! constant-velocity filter cannot serve both: tuned still, it lags and overshoots every move;
//! tuned for moves, it passes the measurement noise of a still head straight through. So two
//! models run side by side in an interacting multiple model (IMM) filter, with Markov switching
//! between them: *still*, a constant verge (the rate held at zero, a slow random walk for
//! drift), and *turning*, constant velocity with large acceleration noise. Each frame the
//! models are mixed, predicted, updated, and weighted by how well each predicted the
//! measurement; the output is their mixture. State `[verge, rate]` in degrees and degrees per
//! second; prediction and uncertainty grow with the real time between frames (`dt` from the
//! timestamps, not a frame count).
//!
//! Why the still model has no rate: a still head's rate is zero, and a still model that keeps
//! one (constant velocity with small noise) fits a line through the last few measurements, so
//! it follows any error that persists for a few frames. On real frames the per-frame error is
//! such a slowly changing function of the view (a head on a moving vehicle sees the scene
//! drift); holding the rate at zero averages it over as many frames as the drift density
//! allows.
//!
//! Why the models are weighed by a Student-t likelihood rather than a Gaussian: the per-frame
//! errors have heavier tails than the estimator's σ says (a 3-4 σ frame every few dozen), and
//! under a Gaussian one such frame makes the turning model a hundred times likelier, so the
//! output jumps with it. A t-distribution with a few degrees of freedom takes several
//! consistent frames to switch, which a real move gives at once. The same t-distribution
//! updates the still model: written as a Gaussian whose variance is scaled by a hidden
//! gamma-distributed factor, a measurement `z` standard deviations off the prediction makes
//! that factor's posterior mean scale the measurement variance by `(ν + z²)/(ν + 1)`, so a
//! frame far off moves a still head less than a linear update would, and one near it slightly
//! more: a still head keeps its value through such a frame rather than averaging it in. The
//! turning model is updated linearly: a frame far off its prediction is what it is there for
//! (a move's rate not yet known), not a tail of the measurement noise.
//!
//! Heavy tails make the still model a likely explanation of frames far off it, so each model's
//! gate also bounds what it may explain: a measurement outside one model's gate gives that
//! model no weight. Without that, a move's first interval beyond the still gate but inside the
//! turning one would still be taken, in part, as a still head's outlier.
//!
//! A measurement outside the innovation gate of both models (`gate_sigmas` standard deviations
//! of each one's prediction) is either a bad frame or the first frame of a move faster than
//! either model foresees: a motor reaches its speed within milliseconds, so a move starts
//! between two frames with degrees to go. One frame cannot tell them apart, and holding the
//! old value until a second frame agrees leaves the output a whole frame's move behind. So the
//! filter restarts from such a measurement at once, its rate the jump over the interval, and
//! keeps the state it had (predicted on) as a fallback: the next measurement is weighed by
//! both, and the one that predicted it better goes on. A bad frame thus costs its own output
//! and nothing after it: the still head's averaged state comes back; a move is followed from
//! its first frame. Frames without a measurement are predicted and marked, never updated with
//! an invented value.
//!
//! Where the head reports its joint angles (encoders, or the angles it was commanded to), the
//! change of their verge between frames is the filter's control input: both models' verge is
//! moved by it in the prediction, so a move is predicted rather than detected, and a still
//! model stays right through it (the verge the images measure is the encoders' plus the
//! calibration's slowly drifting offset, which is what the still model then tracks).
//!
//! The estimator's σ counts only its matches' noise. On rendered frames that is the whole
//! error; on real ones the error also carries a part that follows the view (geometry beyond
//! the model, bent differently by each view's matches), which no number of matches lowers.
//! Trusting the matches' σ there makes every few-frame excursion of that part look like a
//! move, and the filter follows it. So the filter learns how far off its measurements really
//! are: the median of the still model's squared normalised innovations over the last still
//! frames, against the median a correct σ gives (χ² with one degree of freedom), scales the
//! measurement σ up (never down: where the σ is right, nothing changes).

use std::collections::VecDeque;

use nalgebra::{Matrix2, Vector2};

/// Filter settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanConfig {
    /// Spectral density of the still model's verge random walk (slow drift), deg²/s.
    pub still_noise: f64,
    /// Spectral density of the verge acceleration noise of the turning model, deg²/s³.
    pub turning_noise: f64,
    /// Mean time the head stays in one mode (still or turning) before switching, seconds.
    pub mode_time_s: f64,
    /// Measurement σ used when the estimator gives none, and lower bound of given ones (deg).
    pub min_measurement_sigma_deg: f64,
    /// Innovation gate in standard deviations of each model's innovation.
    pub gate_sigmas: f64,
    /// Prior σ of the rate when the filter starts (deg/s).
    pub initial_rate_sigma: f64,
    /// 1-σ error of one encoder verge reading (deg); the change between two readings, the
    /// control input, has √2 times it.
    pub encoder_sigma_deg: f64,
    /// Degrees of freedom of the Student-t innovation likelihood that weighs the two models
    /// and updates the still one (`f64::INFINITY`: Gaussian, and a linear update).
    pub likelihood_dof: f64,
    /// Still frames whose innovations set the measurement-noise scale (module doc); 0 keeps
    /// the estimator's σ as it is.
    pub noise_scale_frames: usize,
}

impl Default for KalmanConfig {
    fn default() -> Self {
        Self {
            // 0.01° of drift in 10 s.
            still_noise: 1e-5,
            // Halving or doubling it moves the filtered median error of the rendered road by
            // < 0.0001° and the KITTI drive's by up to 0.0035° (README, "Sensitivity of the
            // constants").
            turning_noise: 100.0,
            // Halving or doubling it moves the filtered median error of the rendered road by
            // < 0.0001° and the KITTI drive's by < 0.002°.
            mode_time_s: 2.0,
            // The output's resolution (hundredths of a degree): the estimator's σ counts only
            // its matches' noise, and a frame is not trusted beyond what the output shows.
            // Halving it raises the rendered road's filtered median error from 0.0008° to
            // 0.0012°; doubling it lowers that to 0.0006° and the fixed KITTI head's from 0.024°
            // to 0.017°, but it would say no frame is ever worth more than 0.02°, twice the
            // resolution the output is asked for.
            min_measurement_sigma_deg: 0.01,
            // Above the 3-4 σ frames that the per-frame errors' heavy tails give every few
            // dozen frames (module doc): those are weighed by the models, not restarted from.
            gate_sigmas: 5.0,
            // Only the start: the first frames fix the rate, and 5 or 20 °/s moves the filtered
            // median error of the rendered road by < 0.0001° and the KITTI drive's by up to
            // 0.0011°.
            initial_rate_sigma: 10.0,
            // The output's resolution (hundredths of a degree): a head whose joint angles are
            // worse than that (backlash, a commanded angle not yet reached) still predicts a
            // move to within a few of its σ, and the measurements correct the rest.
            encoder_sigma_deg: 0.01,
            // The value Lange, Little and Taylor (1989, "Robust statistical modeling using the
            // t distribution") recommend where ν is not fitted: tails heavy enough that a 4 σ
            // frame inside the gate leaves a still head's turning probability below one half,
            // where a Gaussian makes it over 0.8
            // (`one_outlying_frame_does_not_switch_a_still_head_to_turning`). It sets how far
            // off a still head a frame may lie before the filter follows it: halved or doubled,
            // the KITTI drive's fixed head (`bench/drives.py --phase`, eight phases) spans up
            // to 0.040° or 0.089°, against 0.057°, and the rendered `demo` is followed 0.044°
            // or 0.023° late at worst, against 0.038° (README, "The filter takes the
            // t-distribution's tails into its updates").
            likelihood_dof: 4.0,
            // The misalignment window's 30 frames, for the same reasons: the scale's relative
            // noise (about 1.17/√n, see `NOISE_SCALE_MIN_FRAMES`) is about a fifth at 30, and
            // the part of the error that follows the view changes as a drive goes on. Halving
            // or doubling it moves the filtered median error of the rendered road and the KITTI
            // drive by < 0.0001°.
            noise_scale_frames: 30,
        }
    }
}

/// Median of χ² with one degree of freedom: the median squared normalised innovation when the
/// measurement σ is right.
const CHI2_1_MEDIAN: f64 = 0.454_936_423_119_572_8;

/// Innovations the noise scale needs before it is used. A scale from the median of n squared
/// innovations has a relative noise of about 1.17/√n (as a MAD has), over a third below 12:
/// the bar the estimator's `min_matches` sets for its own σ. Six or 24 leave the rendered
/// road's filtered median error as it is and move the KITTI drive's by 0.006° either way: down
/// at 6, up at 24 to what it is without the scale, which then starts late in the 51 frames.
const NOISE_SCALE_MIN_FRAMES: usize = 12;

/// One per-frame verge measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// The frame's raw verge in degrees, toe-in positive.
    pub verge_deg: f64,
    /// The estimator's own 1-σ uncertainty (deg).
    pub sigma_deg: f64,
}

/// What happened to a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilterStatus {
    /// The measurement was fused.
    Updated,
    /// The measurement was fused into the state from before the last restart, which predicted
    /// it better than the restart did: the restart's frame was a bad one.
    Resumed,
    /// No measurement: the output is the prediction.
    Predicted,
    /// The filter restarted from this measurement (the first, or one outside both models'
    /// gates).
    Restarted,
}

/// The filter's output for one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterOutput {
    /// Filtered verge in degrees, toe-in positive (`filtered_verge_deg` in the CSV).
    pub verge_deg: f64,
    /// Filtered verge rate in degrees per second, of the models' mixture.
    pub rate_deg_s: f64,
    /// 1-σ of the filtered verge (`filtered_sigma_deg` in the CSV).
    pub sigma_deg: f64,
    /// Probability that the head is turning (the turning model's weight).
    pub turning_probability: f64,
    /// What the filter did with the frame.
    pub status: FilterStatus,
}

/// Timestamps must not run backwards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("frame timestamp {now_us} µs is before the previous one ({previous_us} µs)")]
pub struct TimeWentBackwards {
    /// The previous frame's timestamp in microseconds.
    pub previous_us: u64,
    /// The offending frame's timestamp in microseconds.
    pub now_us: u64,
}

/// One model's estimate.
#[derive(Debug, Clone, Copy)]
struct Gaussian {
    x: Vector2<f64>,
    p: Matrix2<f64>,
}

/// Index of the models in the arrays below.
const STILL: usize = 0;
const TURNING: usize = 1;

#[derive(Debug, Clone, Copy)]
struct State {
    models: [Gaussian; 2],
    /// Model probabilities (sum 1).
    mu: [f64; 2],
    t_us: u64,
}

impl State {
    /// The mixture's mean and covariance.
    fn combined(&self) -> Gaussian {
        let x = self.models[STILL].x * self.mu[STILL] + self.models[TURNING].x * self.mu[TURNING];
        let mut p = Matrix2::zeros();
        for (m, mu) in self.models.iter().zip(self.mu) {
            let d = m.x - x;
            p += (m.p + d * d.transpose()) * mu;
        }
        Gaussian { x, p }
    }
}

/// The verge filter.
#[derive(Debug, Clone)]
pub struct VergeFilter {
    config: KalmanConfig,
    state: Option<State>,
    /// The state from before a restart, until the next measurement says which of the two goes
    /// on.
    fallback: Option<State>,
    /// The last encoder verge reading (deg), whose change the next reading's frame predicts.
    encoder_deg: Option<f64>,
    /// The still model's squared innovations over the last still frames, each normalised by
    /// its variance under the estimator's own σ.
    still_innovations: VecDeque<f64>,
    /// The factor the estimator's σ is multiplied by (≥ 1).
    noise_scale: f64,
}

impl VergeFilter {
    /// A filter that has seen no measurement yet.
    pub fn new(config: KalmanConfig) -> Self {
        Self {
            config,
            state: None,
            fallback: None,
            encoder_deg: None,
            still_innovations: VecDeque::new(),
            noise_scale: 1.0,
        }
    }

    /// The factor the filter has learned to multiply the estimator's σ by (1 until the still
    /// frames' innovations show the σ too small; module doc).
    pub fn noise_scale(&self) -> f64 {
        self.noise_scale
    }

    /// Advances to `timestamp_us` and fuses `measurement` if any. Returns `None` while no
    /// measurement has ever arrived (nothing to predict from).
    pub fn step(
        &mut self,
        timestamp_us: u64,
        measurement: Option<Measurement>,
    ) -> Result<Option<FilterOutput>, TimeWentBackwards> {
        self.step_with_encoders(timestamp_us, measurement, None)
    }

    /// [`VergeFilter::step`] with the head's own verge reading at `timestamp_us` (encoders or
    /// commanded angles, deg), if it has one: its change since the previous reading moves
    /// the prediction. Only changes count, so a constant offset between the encoders' verge
    /// and the optical one does no harm; a frame without a reading predicts without control,
    /// and the next reading carries the change of both frames.
    pub fn step_with_encoders(
        &mut self,
        timestamp_us: u64,
        measurement: Option<Measurement>,
        encoder_verge_deg: Option<f64>,
    ) -> Result<Option<FilterOutput>, TimeWentBackwards> {
        let control = match (encoder_verge_deg, self.encoder_deg) {
            (Some(now), Some(before)) => Some(now - before),
            _ => None,
        };
        if encoder_verge_deg.is_some() {
            self.encoder_deg = encoder_verge_deg;
        }
        let Some(s) = self.state else {
            return Ok(measurement.map(|m| self.restart(timestamp_us, m, None)));
        };
        if timestamp_us < s.t_us {
            return Err(TimeWentBackwards {
                previous_us: s.t_us,
                now_us: timestamp_us,
            });
        }
        let dt = (timestamp_us - s.t_us) as f64 * 1e-6;
        let mut predicted = self.predict(&s, timestamp_us, control);
        let fallback = self
            .fallback
            .map(|f| self.predict(&f, timestamp_us, control));
        let Some(m) = measurement else {
            self.state = Some(predicted);
            self.fallback = fallback;
            return Ok(Some(output(&predicted, FilterStatus::Predicted)));
        };
        let r = self.measurement_sigma(m).powi(2);
        let mut status = FilterStatus::Updated;
        self.fallback = None;
        if let Some(f) = fallback {
            let dof = self.config.likelihood_dof;
            if density(&f, m.verge_deg, r, dof) > density(&predicted, m.verge_deg, r, dof) {
                predicted = f;
                status = FilterStatus::Resumed;
            }
        }
        let gate = self.config.gate_sigmas.powi(2);
        let inside = predicted.models.iter().any(|model| {
            let innovation = m.verge_deg - model.x[0];
            innovation * innovation <= gate * (model.p[(0, 0)] + r)
        });
        if !inside {
            self.fallback = Some(predicted);
            let jump = m.verge_deg - predicted.combined().x[0];
            return Ok(Some(self.restart(timestamp_us, m, Some((jump, dt)))));
        }
        let next = update(&predicted, m.verge_deg, r, self.config.likelihood_dof, gate);
        self.state = Some(next);
        if predicted.mu[STILL] >= 0.5 {
            self.learn_noise_scale(&predicted.models[STILL], m);
        }
        Ok(Some(output(&next, status)))
    }

    /// Adds a still frame's innovation under `still`'s prediction and updates the noise scale.
    fn learn_noise_scale(&mut self, still: &Gaussian, m: Measurement) {
        let n = self.config.noise_scale_frames;
        if n == 0 {
            return;
        }
        let own = self.own_sigma(m);
        let innovation = m.verge_deg - still.x[0];
        let window = &mut self.still_innovations;
        window.push_back(innovation * innovation / (still.p[(0, 0)] + own * own));
        while window.len() > n {
            window.pop_front();
        }
        if window.len() >= NOISE_SCALE_MIN_FRAMES {
            let mut sorted: Vec<f64> = window.iter().copied().collect();
            sorted.sort_by(f64::total_cmp);
            let median = sorted[sorted.len() / 2];
            self.noise_scale = (median / CHI2_1_MEDIAN).sqrt().max(1.0);
        }
    }

    /// IMM mixing and the prediction of both models over `dt` seconds: constant verge for the
    /// still model, constant rate for the turning one, both moved by the encoders' verge change
    /// `control` when there is one.
    fn predict(&self, s: &State, t_us: u64, control: Option<f64>) -> State {
        let dt = t_us.saturating_sub(s.t_us) as f64 * 1e-6;
        // Probability of switching mode within dt, from the mean time in a mode.
        let switch = if self.config.mode_time_s > 0.0 {
            1.0 - (-dt / self.config.mode_time_s).exp()
        } else {
            // A mode that lasts no time says nothing of the next: either is equally likely.
            0.5
        };
        let stay = 1.0 - switch;
        let transition = [[stay, switch], [switch, stay]];
        let mut mu = [0.0; 2];
        for (j, mu_j) in mu.iter_mut().enumerate() {
            *mu_j = (0..2).map(|i| transition[i][j] * s.mu[i]).sum();
        }
        let mut models = s.models;
        for (j, model) in models.iter_mut().enumerate() {
            // Mixed prior of model j: the models' estimates weighted by P(was i | is j).
            let w: [f64; 2] = std::array::from_fn(|i| {
                if mu[j] > 0.0 {
                    transition[i][j] * s.mu[i] / mu[j]
                } else {
                    f64::from(u8::from(i == j))
                }
            });
            let x0 = s.models[STILL].x * w[STILL] + s.models[TURNING].x * w[TURNING];
            let mut p0 = Matrix2::zeros();
            for (m, wi) in s.models.iter().zip(w) {
                let d = m.x - x0;
                p0 += (m.p + d * d.transpose()) * wi;
            }
            let (f, qm) = if j == STILL {
                // The rate is zero, not merely unknown: its variance is zero too.
                let q = self.config.still_noise;
                (
                    Matrix2::new(1.0, 0.0, 0.0, 0.0),
                    Matrix2::new(q * dt, 0.0, 0.0, 0.0),
                )
            } else {
                let q = self.config.turning_noise;
                let qm = Matrix2::new(
                    q * dt.powi(3) / 3.0,
                    q * dt * dt / 2.0,
                    q * dt * dt / 2.0,
                    q * dt,
                );
                (Matrix2::new(1.0, dt, 0.0, 1.0), qm)
            };
            let (shift, shift_var) = match control {
                Some(delta) => (delta, 2.0 * self.config.encoder_sigma_deg.powi(2)),
                None => (0.0, 0.0),
            };
            *model = Gaussian {
                x: f * x0 + Vector2::new(shift, 0.0),
                p: f * p0 * f.transpose() + qm + Matrix2::new(shift_var, 0.0, 0.0, 0.0),
            };
        }
        State { models, mu, t_us }
    }

    /// The σ the filter weighs `m` by: the estimator's own, scaled by what the innovations
    /// have shown.
    fn measurement_sigma(&self, m: Measurement) -> f64 {
        self.noise_scale * self.own_sigma(m)
    }

    /// `m`'s σ as the estimator gives it, within the configured floor.
    fn own_sigma(&self, m: Measurement) -> f64 {
        if m.sigma_deg.is_finite() {
            m.sigma_deg.max(self.config.min_measurement_sigma_deg)
        } else {
            self.config.min_measurement_sigma_deg
        }
    }

    /// Starts over from `m`. After a `jump` (deg) away from the prediction over `dt` seconds
    /// the rate is the jump over the interval, with a σ as large (a move may have begun anywhere in the interval, so its
    /// speed is at least that); at the first measurement it is unknown (zero, with the
    /// configured prior). Either way both models are equally likely: one jump does not tell a
    /// move from a step, the next measurement does.
    fn restart(&mut self, t_us: u64, m: Measurement, jump: Option<(f64, f64)>) -> FilterOutput {
        let sigma = self.measurement_sigma(m);
        let prior = self.config.initial_rate_sigma.powi(2);
        let (rate, rate_var) = match jump {
            Some((jump, dt)) if dt > 0.0 => (jump / dt, (jump / dt).powi(2) + prior),
            _ => (0.0, prior),
        };
        let g = Gaussian {
            x: Vector2::new(m.verge_deg, rate),
            p: Matrix2::new(sigma * sigma, 0.0, 0.0, rate_var),
        };
        let s = State {
            models: [g, g],
            mu: [0.5, 0.5],
            t_us,
        };
        self.state = Some(s);
        output(&s, FilterStatus::Restarted)
    }
}

/// Kalman update of both models with the verge measurement `z` (variance `r`, t-distributed
/// with `dof` degrees of freedom: module doc), and the new model probabilities from each
/// model's innovation likelihood, none for a model whose gate (`gate`, squared standard
/// deviations of its innovation) the measurement lies outside.
fn update(s: &State, z: f64, r: f64, dof: f64, gate: f64) -> State {
    let mut out = *s;
    let mut weights = [0.0; 2];
    for (j, model) in out.models.iter_mut().enumerate() {
        let innovation = z - model.x[0];
        let var = model.p[(0, 0)] + r;
        let z2 = innovation * innovation / var;
        let r_t = if j == STILL && dof.is_finite() {
            r * (dof + z2) / (dof + 1.0)
        } else {
            r
        };
        let k = Vector2::new(model.p[(0, 0)], model.p[(1, 0)]) / (model.p[(0, 0)] + r_t);
        model.x += k * innovation;
        let kh = Matrix2::new(k[0], 0.0, k[1], 0.0);
        model.p = (Matrix2::identity() - kh) * model.p;
        model.p = 0.5 * (model.p + model.p.transpose());
        weights[j] = if z2 <= gate {
            likelihood(z2, dof) / var.sqrt() * s.mu[j]
        } else {
            0.0
        };
    }
    let total = weights[STILL] + weights[TURNING];
    // Both weights vanish only for a measurement outside both gates, which the caller has
    // already restarted from, or far enough inside one for its likelihood to underflow; keep
    // the prior weights rather than divide by zero.
    if total.is_finite() && total > 0.0 {
        out.mu = [weights[STILL] / total, weights[TURNING] / total];
    }
    out
}

/// The mixture's density of a measurement `z` (variance `r`) under the prediction `s`, up to a
/// factor common to all predictions.
fn density(s: &State, z: f64, r: f64, dof: f64) -> f64 {
    s.models
        .iter()
        .zip(s.mu)
        .map(|(model, mu)| {
            let var = model.p[(0, 0)] + r;
            let innovation = z - model.x[0];
            mu * likelihood(innovation * innovation / var, dof) / var.sqrt()
        })
        .sum()
}

/// The density of a standardised innovation whose square is `z2`, up to a factor common to
/// both models: Student-t with `dof` degrees of freedom, Gaussian when `dof` is infinite.
fn likelihood(z2: f64, dof: f64) -> f64 {
    if dof.is_finite() {
        (1.0 + z2 / dof).powf(-0.5 * (dof + 1.0))
    } else {
        (-0.5 * z2).exp()
    }
}

fn output(s: &State, status: FilterStatus) -> FilterOutput {
    let c = s.combined();
    FilterOutput {
        verge_deg: c.x[0],
        rate_deg_s: c.x[1],
        sigma_deg: c.p[(0, 0)].max(0.0).sqrt(),
        turning_probability: s.mu[TURNING],
        status,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meas(v: f64) -> Option<Measurement> {
        Some(Measurement {
            verge_deg: v,
            sigma_deg: 0.02,
        })
    }

    #[test]
    fn tracks_a_ramp_and_predicts_over_gaps_with_growing_sigma() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        let mut last = None;
        for i in 0..60u64 {
            let t = i * 33_333;
            let truth = 1.0 + 2.0 * t as f64 * 1e-6; // 2°/s
            last = f.step(t, meas(truth)).unwrap();
        }
        let o = last.unwrap();
        assert!((o.rate_deg_s - 2.0).abs() < 0.2, "{o:?}");
        // A 0.5 s gap: predicted along the ramp, sigma grows, status says so.
        let t = 59 * 33_333 + 500_000;
        let p = f.step(t, None).unwrap().unwrap();
        assert_eq!(p.status, FilterStatus::Predicted);
        // The head may have stopped in the gap: the prediction mixes the still model's
        // (where the ramp was) with the turning model's (along it), and its σ covers both.
        let truth = 1.0 + 2.0 * t as f64 * 1e-6;
        assert!(p.verge_deg > o.verge_deg + 0.5, "{p:?} after {o:?}");
        assert!(
            (p.verge_deg - truth).abs() < p.sigma_deg,
            "{p:?} vs {truth}"
        );
        assert!(p.sigma_deg > o.sigma_deg);
    }

    #[test]
    fn a_bad_frame_costs_its_own_output_and_nothing_after_it() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        let mut settled = None;
        for i in 0..30u64 {
            settled = f.step(i * 33_333, meas(1.5)).unwrap();
        }
        let settled = settled.unwrap();
        let o = f.step(30 * 33_333, meas(4.0)).unwrap().unwrap();
        assert_eq!(o.status, FilterStatus::Restarted);
        assert!((o.verge_deg - 4.0).abs() < 0.01, "{o:?}");
        let back = f.step(31 * 33_333, meas(1.5)).unwrap().unwrap();
        assert_eq!(back.status, FilterStatus::Resumed);
        assert!((back.verge_deg - 1.5).abs() < 1e-3, "{back:?}");
        // The averaged state came back: its σ is the settled one, not a fresh start's.
        assert!(
            back.sigma_deg < 1.1 * settled.sigma_deg,
            "{back:?} {settled:?}"
        );
    }

    #[test]
    fn a_step_is_followed_from_its_first_frame() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        for i in 0..30u64 {
            f.step(i * 33_333, meas(1.5)).unwrap();
        }
        for i in 30..40u64 {
            let o = f.step(i * 33_333, meas(4.0)).unwrap().unwrap();
            assert!((o.verge_deg - 4.0).abs() < 0.01, "frame {i}: {o:?}");
        }
    }

    #[test]
    fn a_move_that_starts_abruptly_is_followed_within_two_frames() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        let truth = |i: u64| {
            if i < 30 {
                1.0
            } else {
                1.0 + 10.0 * (i - 30) as f64 / 30.0 // 10°/s from frame 30
            }
        };
        let mut worst_after = 0f64;
        for i in 0..60u64 {
            let o = f.step(i * 33_333, meas(truth(i))).unwrap().unwrap();
            if i >= 32 {
                worst_after = worst_after.max((o.verge_deg - truth(i)).abs());
            }
            if i == 59 {
                assert!((o.rate_deg_s - 10.0).abs() < 0.5, "{o:?}");
            }
        }
        assert!(worst_after < 0.05, "error after the restart {worst_after}");
    }

    #[test]
    fn a_smoothly_turning_head_is_followed_without_lag() {
        // ±3° at 0.5 Hz (up to 9.4°/s and 30°/s²), ±0.01° deterministic measurement noise:
        // a single still-tuned filter lags such a move by a tenth of a degree.
        let mut f = VergeFilter::new(KalmanConfig::default());
        let mut worst = 0f64;
        for i in 0..150u64 {
            let t = i as f64 / 30.0;
            let truth = 3.0 * (std::f64::consts::PI * t).sin();
            let noise = 0.01 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
            let o = f.step(i * 33_333, meas(truth + noise)).unwrap().unwrap();
            if i >= 10 {
                worst = worst.max((o.verge_deg - truth).abs());
            }
        }
        assert!(worst < 0.03, "worst filtered error {worst}");
    }

    #[test]
    fn fixed_cameras_stay_within_a_small_span() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        let mut lo = f64::MAX;
        let mut hi = f64::MIN;
        for i in 0..300u64 {
            // Deterministic ±0.03° measurement noise.
            let noise = 0.03 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
            let o = f.step(i * 33_333, meas(1.6 + noise)).unwrap().unwrap();
            if i >= 30 {
                lo = lo.min(o.verge_deg);
                hi = hi.max(o.verge_deg);
            }
        }
        assert!(hi - lo < 0.03, "span {}", hi - lo);
    }

    #[test]
    fn fixed_cameras_average_out_an_error_that_persists_for_frames() {
        // The per-frame error of real frames changes with the view: here ±0.02° that holds
        // for a dozen frames at a time. A still model with a rate follows each plateau.
        let mut f = VergeFilter::new(KalmanConfig::default());
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for i in 0..240u64 {
            let plateau = if (i / 12) % 2 == 0 { 0.02 } else { -0.02 };
            let o = f.step(i * 33_333, meas(1.6 + plateau)).unwrap().unwrap();
            if i >= 60 {
                lo = lo.min(o.verge_deg);
                hi = hi.max(o.verge_deg);
            }
        }
        assert!(hi - lo < 0.015, "span {}", hi - lo);
    }

    /// The default filter but for its noise-scale window (0: the estimator's σ as it is).
    fn with_noise_scale_frames(noise_scale_frames: usize) -> VergeFilter {
        VergeFilter::new(KalmanConfig {
            noise_scale_frames,
            ..KalmanConfig::default()
        })
    }

    #[test]
    fn measurements_that_scatter_beyond_their_sigma_are_weighed_by_their_scatter() {
        // A still head whose measurements claim 0.01° but scatter ±0.05° (uniform, 0.029° σ),
        // and after 100 frames three that sit 0.1° off, as a view can hold a real rig's error
        // for a few frames: weighed by the σ they claim they look like a move.
        let run = |noise_scale_frames| {
            let mut f = with_noise_scale_frames(noise_scale_frames);
            let (mut lo, mut hi) = (f64::MAX, f64::MIN);
            for i in 0..160u64 {
                let noise = 0.05 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
                let excursion = if (100..103).contains(&i) { 0.1 } else { 0.0 };
                let m = Measurement {
                    verge_deg: 1.6 + noise + excursion,
                    sigma_deg: 0.01,
                };
                let o = f.step(i * 100_000, Some(m)).unwrap().unwrap();
                if i >= 30 {
                    lo = lo.min(o.verge_deg);
                    hi = hi.max(o.verge_deg);
                }
            }
            (f.noise_scale(), hi - lo)
        };
        let (scale, span) = run(KalmanConfig::default().noise_scale_frames);
        let (fixed_scale, fixed_span) = run(0);
        // The noise's median |z| against the claimed σ alone is 0.025° / 0.01° (a scale of
        // 2.5 / 0.674 = 3.7); the still model's own spread takes a little of it.
        assert!((2.5..4.0).contains(&scale), "{scale}");
        assert_eq!(fixed_scale, 1.0);
        assert!(span < 0.5 * fixed_span, "span {span} against {fixed_span}");
    }

    #[test]
    fn a_right_sigma_is_left_as_it_is() {
        // Measurements within their σ: the learned scale stays 1 and nothing changes.
        let run = |noise_scale_frames| {
            let mut f = with_noise_scale_frames(noise_scale_frames);
            let out: Vec<FilterOutput> = (0..100u64)
                .map(|i| {
                    let noise = 0.01 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
                    f.step(i * 33_333, meas(1.6 + noise)).unwrap().unwrap()
                })
                .collect();
            (f.noise_scale(), out)
        };
        let (scale, learned) = run(KalmanConfig::default().noise_scale_frames);
        assert_eq!(scale, 1.0);
        assert_eq!(learned, run(0).1);
    }

    #[test]
    fn one_outlying_frame_does_not_switch_a_still_head_to_turning() {
        let after_outlier = |likelihood_dof| {
            let mut f = VergeFilter::new(KalmanConfig {
                likelihood_dof,
                ..KalmanConfig::default()
            });
            for i in 0..60u64 {
                f.step(i * 33_333, meas(1.6)).unwrap();
            }
            // 4 σ of the measurement: inside the gate, more than a still head explains.
            f.step(60 * 33_333, meas(1.68)).unwrap().unwrap()
        };
        let (t, gaussian) = (after_outlier(8.0), after_outlier(f64::INFINITY));
        assert_eq!(t.status, FilterStatus::Updated);
        assert!(t.turning_probability < 0.5, "{t:?}");
        assert!(gaussian.turning_probability > 0.8, "{gaussian:?}");
        assert!((t.verge_deg - 1.6).abs() < 0.5 * (gaussian.verge_deg - 1.6).abs());
    }

    #[test]
    fn a_frame_beyond_the_still_gate_is_the_turning_models_alone() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        for i in 0..60u64 {
            f.step(i * 33_333, meas(1.6)).unwrap();
        }
        // 7 σ of the measurement: outside the still model's gate, inside the turning one's.
        let o = f.step(60 * 33_333, meas(1.74)).unwrap().unwrap();
        assert_eq!(o.status, FilterStatus::Updated);
        assert_eq!(o.turning_probability, 1.0);
        assert!((o.verge_deg - 1.74).abs() < 0.05, "{o:?}");
    }

    #[test]
    fn no_output_before_the_first_measurement_and_time_must_advance() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        assert_eq!(f.step(0, None).unwrap(), None);
        f.step(100, meas(1.0)).unwrap();
        assert_eq!(
            f.step(50, None),
            Err(TimeWentBackwards {
                previous_us: 100,
                now_us: 50
            })
        );
    }
}
