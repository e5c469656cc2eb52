//! Kalman filter of the verge angle and its rate (thesis 5.2.1 used a first-order filter).
//!
//! State `[verge, rate]` in degrees and degrees per second; constant-velocity model driven by
//! white acceleration noise, so the prediction and its uncertainty grow with the real time
//! between frames (`dt` from the timestamps, not a frame count). A measurement whose
//! innovation exceeds `gate_sigmas` standard deviations is rejected (a bad frame must not pull
//! the estimate); after `reset_after_rejections` consecutive rejections the filter restarts
//! from the measurement (the head really moved faster than the model allows). A restart takes
//! its rate from the previous rejected measurement: the rejections that end in a restart are
//! the start or the end of a move, and starting at rate 0 in the middle of a move (or at the
//! old rate after it stopped) would lag or overshoot it for several frames. Frames without
//! a measurement are predicted and marked, never updated with an invented value.

use nalgebra::{Matrix2, Vector2};

/// Filter settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanConfig {
    /// Spectral density of the verge acceleration noise, deg²/s³.
    pub process_noise: f64,
    /// Measurement σ used when the estimator gives none, and lower bound of given ones (deg).
    pub min_measurement_sigma_deg: f64,
    /// Innovation gate in standard deviations of the innovation.
    pub gate_sigmas: f64,
    /// Prior σ of the rate when the filter (re)starts (deg/s).
    pub initial_rate_sigma: f64,
    /// Consecutive rejected measurements after which the filter restarts.
    pub reset_after_rejections: usize,
}

impl Default for KalmanConfig {
    fn default() -> Self {
        Self {
            process_noise: 0.1,
            min_measurement_sigma_deg: 0.01,
            gate_sigmas: 4.0,
            initial_rate_sigma: 10.0,
            reset_after_rejections: 2,
        }
    }
}

/// One per-frame verge measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    pub verge_deg: f64,
    /// The estimator's own 1-σ uncertainty (deg).
    pub sigma_deg: f64,
}

/// What happened to a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FilterStatus {
    /// The measurement was fused.
    Updated,
    /// The measurement failed the innovation gate; the output is the prediction.
    Rejected,
    /// No measurement: the output is the prediction.
    Predicted,
    /// The filter restarted from this measurement.
    Restarted,
}

/// The filter's output for one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterOutput {
    pub verge_deg: f64,
    pub rate_deg_s: f64,
    /// 1-σ of the filtered verge (`filtered_sigma_deg` in the CSV).
    pub sigma_deg: f64,
    pub status: FilterStatus,
}

/// Timestamps must not run backwards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("frame timestamp {now_us} µs is before the previous one ({previous_us} µs)")]
pub struct TimeWentBackwards {
    pub previous_us: u64,
    pub now_us: u64,
}

#[derive(Debug, Clone, Copy)]
struct State {
    x: Vector2<f64>,
    p: Matrix2<f64>,
    t_us: u64,
}

/// The verge Kalman filter.
#[derive(Debug, Clone)]
pub struct VergeFilter {
    config: KalmanConfig,
    state: Option<State>,
    rejections: usize,
    /// The last rejected measurement and its time, while rejections are consecutive.
    last_rejected: Option<(u64, Measurement)>,
}

impl VergeFilter {
    pub fn new(config: KalmanConfig) -> Self {
        Self {
            config,
            state: None,
            rejections: 0,
            last_rejected: None,
        }
    }

    /// Advances to `timestamp_us` and fuses `measurement` if any. Returns `None` while no
    /// measurement has ever arrived (nothing to predict from).
    pub fn step(
        &mut self,
        timestamp_us: u64,
        measurement: Option<Measurement>,
    ) -> Result<Option<FilterOutput>, TimeWentBackwards> {
        let Some(mut s) = self.state else {
            return Ok(measurement.map(|m| self.restart(timestamp_us, m)));
        };
        if timestamp_us < s.t_us {
            return Err(TimeWentBackwards {
                previous_us: s.t_us,
                now_us: timestamp_us,
            });
        }
        let dt = (timestamp_us - s.t_us) as f64 * 1e-6;
        let f = Matrix2::new(1.0, dt, 0.0, 1.0);
        let q = self.config.process_noise;
        let qm = Matrix2::new(
            q * dt.powi(3) / 3.0,
            q * dt * dt / 2.0,
            q * dt * dt / 2.0,
            q * dt,
        );
        s.x = f * s.x;
        s.p = f * s.p * f.transpose() + qm;
        s.t_us = timestamp_us;
        let mut status = FilterStatus::Predicted;
        if let Some(m) = measurement {
            let r = self.measurement_sigma(m).powi(2);
            let innovation = m.verge_deg - s.x[0];
            let var = s.p[(0, 0)] + r;
            if innovation * innovation <= self.config.gate_sigmas.powi(2) * var {
                let k = Vector2::new(s.p[(0, 0)], s.p[(1, 0)]) / var;
                s.x += k * innovation;
                let kh = Matrix2::new(k[0], 0.0, k[1], 0.0);
                s.p = (Matrix2::identity() - kh) * s.p;
                s.p = 0.5 * (s.p + s.p.transpose());
                self.rejections = 0;
                self.last_rejected = None;
                status = FilterStatus::Updated;
            } else {
                self.rejections += 1;
                if self.rejections >= self.config.reset_after_rejections {
                    return Ok(Some(self.restart(timestamp_us, m)));
                }
                self.last_rejected = Some((timestamp_us, m));
                status = FilterStatus::Rejected;
            }
        }
        self.state = Some(s);
        Ok(Some(FilterOutput {
            verge_deg: s.x[0],
            rate_deg_s: s.x[1],
            sigma_deg: s.p[(0, 0)].max(0.0).sqrt(),
            status,
        }))
    }

    fn measurement_sigma(&self, m: Measurement) -> f64 {
        if m.sigma_deg.is_finite() {
            m.sigma_deg.max(self.config.min_measurement_sigma_deg)
        } else {
            self.config.min_measurement_sigma_deg
        }
    }

    /// Starts over from `m`; the rate comes from the previous rejected measurement when there
    /// is one (a move under way), else it is unknown (zero, with the configured prior).
    fn restart(&mut self, t_us: u64, m: Measurement) -> FilterOutput {
        let sigma = self.measurement_sigma(m);
        // With a previous rejected measurement m0 at dt before: verge = m, rate = (m - m0)/dt,
        // so var(rate) = (σ² + σ0²)/dt² and cov(verge, rate) = σ²/dt.
        let (rate, rate_var, cov) = match self.last_rejected.take() {
            Some((t0, m0)) if t_us > t0 => {
                let dt = (t_us - t0) as f64 * 1e-6;
                let sigma0 = self.measurement_sigma(m0);
                (
                    (m.verge_deg - m0.verge_deg) / dt,
                    (sigma * sigma + sigma0 * sigma0) / (dt * dt),
                    sigma * sigma / dt,
                )
            }
            _ => (0.0, self.config.initial_rate_sigma.powi(2), 0.0),
        };
        let s = State {
            x: Vector2::new(m.verge_deg, rate),
            p: Matrix2::new(sigma * sigma, cov, cov, rate_var),
            t_us,
        };
        self.state = Some(s);
        self.rejections = 0;
        FilterOutput {
            verge_deg: m.verge_deg,
            rate_deg_s: rate,
            sigma_deg: sigma,
            status: FilterStatus::Restarted,
        }
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
        let truth = 1.0 + 2.0 * t as f64 * 1e-6;
        assert!((p.verge_deg - truth).abs() < 0.1, "{p:?} vs {truth}");
        assert!(p.sigma_deg > o.sigma_deg);
    }

    #[test]
    fn gates_outliers_and_restarts_after_a_real_jump() {
        let mut f = VergeFilter::new(KalmanConfig::default());
        for i in 0..30u64 {
            f.step(i * 33_333, meas(1.5)).unwrap();
        }
        let o = f.step(30 * 33_333, meas(4.0)).unwrap().unwrap();
        assert_eq!(o.status, FilterStatus::Rejected);
        assert!((o.verge_deg - 1.5).abs() < 0.01);
        let mut status = o.status;
        for i in 31..40u64 {
            status = f.step(i * 33_333, meas(4.0)).unwrap().unwrap().status;
            if status == FilterStatus::Restarted {
                break;
            }
        }
        assert_eq!(status, FilterStatus::Restarted);
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
