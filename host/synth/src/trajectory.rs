//! How the head moves: the two camera yaws (hence the verge), the head tilt and the vehicle.
//!
//! The kinds reproduce the thesis experiments: [`TrajectoryKind::Manual`] is figure 5.1 (each
//! camera moved independently by hand over a ±15° verge range, smooth moves with pauses),
//! [`TrajectoryKind::Fixed`] is figure 5.2 (cameras fixed at a verge of about 1.6° while the car
//! drives), and [`TrajectoryKind::Steps`] holds a list of verge values for two seconds each,
//! switching instantaneously, which shows a filter's step response. [`TrajectoryKind::Motor`]
//! is figure 5.1 as a motorised head would make it: the same pauses and one-camera moves, but
//! each move at a constant speed from its first instant, as a servo reaches its speed within
//! milliseconds, far less than a frame interval, so a move starts between two frames with
//! several degrees to go.

use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::camera::{pitch_down, yaw, CameraPose, Intrinsics};
use crate::SynthError;

/// The kinds of head motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryKind {
    /// Thesis fig. 5.1: one camera at a time moved by hand, ±15° verge, with pauses.
    Manual,
    /// Thesis fig. 5.2: verge held (at 1.6° unless configured), vehicle moving (with a small
    /// pitch bounce).
    Fixed,
    /// A fixed list of verge values, two seconds each, instantaneous switches.
    Steps,
    /// Fig. 5.1's moves made by motors: constant speed from the first instant of a move.
    Motor,
}

impl TrajectoryKind {
    pub const ALL: [TrajectoryKind; 4] = [Self::Manual, Self::Fixed, Self::Steps, Self::Motor];

    pub fn name(self) -> &'static str {
        match self {
            Self::Manual => "manual",
            Self::Fixed => "fixed",
            Self::Steps => "steps",
            Self::Motor => "motor",
        }
    }
}

impl fmt::Display for TrajectoryKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for TrajectoryKind {
    type Err = SynthError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| SynthError::UnknownTrajectory(s.to_owned()))
    }
}

/// The state of the head at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadState {
    /// Left optical centre in world coordinates (metres).
    pub position: Vector3<f64>,
    /// Head pitch, positive looking down (radians).
    pub tilt_rad: f64,
    /// Left camera yaw, positive toward +x (radians).
    pub alpha_l_rad: f64,
    /// Right camera yaw, positive toward +x (radians).
    pub alpha_r_rad: f64,
}

impl HeadState {
    /// `alpha_l - alpha_r` in degrees (toe-in positive).
    pub fn verge_deg(&self) -> f64 {
        (self.alpha_l_rad - self.alpha_r_rad).to_degrees()
    }

    /// The two cameras: each yaws about its own vertical axis through its optical centre; the
    /// right one sits at `(+baseline, 0, 0)` in the head frame and carries the head's fixed
    /// pitch after its yaw (`Ry(alpha_r) Rx(pitch)`, `docs/ARCHITECTURE.md`, "Fixed
    /// misalignments").
    pub fn camera_poses(
        &self,
        geometry: HeadGeometry,
        left: Intrinsics,
        right: Intrinsics,
    ) -> [CameraPose; 2] {
        let head = pitch_down(self.tilt_rad);
        // `pitch_down(a)` is `Rx(-a)` of the library's convention.
        let misaligned = pitch_down(-geometry.right_pitch_rad);
        [
            CameraPose {
                intrinsics: left,
                center: self.position,
                rotation: head * yaw(self.alpha_l_rad),
            },
            CameraPose {
                intrinsics: right,
                center: self.position + head * Vector3::new(geometry.baseline_m, 0.0, 0.0),
                rotation: head * yaw(self.alpha_r_rad) * misaligned,
            },
        ]
    }
}

/// What of the head does not move: the baseline and the right camera's fixed pitch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadGeometry {
    pub baseline_m: f64,
    /// Positive as the calibration's `pitch_deg` (radians).
    pub right_pitch_rad: f64,
}

/// A keyframe of the camera yaws (degrees); consecutive keys are joined by a cosine ease, so a
/// key that repeats the previous values is a pause.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Key {
    t_s: f64,
    alpha_l_deg: f64,
    alpha_r_deg: f64,
}

/// How the yaws go from one key to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Between {
    /// A cosine ease: a hand starts and stops a move gently (`Manual`).
    Ease,
    /// Linear, at constant speed: a motor's move (`Motor`).
    Linear,
    /// Held until the next key (`Steps`, `Fixed`).
    Hold,
}

/// Where the head and the vehicle go over time. Deterministic for a seed.
#[derive(Debug, Clone)]
pub struct Trajectory {
    kind: TrajectoryKind,
    keys: Vec<Key>,
    between: Between,
    start: Vector3<f64>,
    speed_mps: f64,
    tilt_deg: f64,
}

/// The verge range of the manual moves (fig. 5.1 stays within about ±15°).
const MANUAL_VERGE_LIMIT_DEG: f64 = 15.0;
/// How far a single camera is turned at most in the manual moves.
const MANUAL_ALPHA_LIMIT_DEG: f64 = 10.0;
/// The verge of the fixed-camera experiment (fig. 5.2 varies between 1.43° and 1.86°).
pub const FIXED_VERGE_DEG: f64 = 1.6;
/// The verge values of the `steps` trajectory and how long each is held.
const STEPS_DEG: [f64; 10] = [0.0, 2.0, 5.0, 10.0, -3.0, -8.0, 1.6, 15.0, -15.0, 0.5];
const STEP_HOLD_S: f64 = 2.0;

impl Trajectory {
    /// A trajectory of `kind` covering at least `duration_s` seconds, starting with the left
    /// optical centre at `start` and moving along +z at `speed_mps`, the head tilted down by
    /// `tilt_deg`; `fixed_verge_deg` is the verge `Fixed` holds.
    pub fn new(
        kind: TrajectoryKind,
        seed: u64,
        duration_s: f64,
        start: Vector3<f64>,
        speed_mps: f64,
        tilt_deg: f64,
        fixed_verge_deg: f64,
    ) -> Self {
        let (keys, between) = match kind {
            TrajectoryKind::Manual => (manual_keys(seed, duration_s, hand_speed), Between::Ease),
            TrajectoryKind::Motor => (manual_keys(seed, duration_s, motor_speed), Between::Linear),
            TrajectoryKind::Fixed => (
                vec![Key {
                    t_s: 0.0,
                    alpha_l_deg: fixed_verge_deg / 2.0,
                    alpha_r_deg: -fixed_verge_deg / 2.0,
                }],
                Between::Hold,
            ),
            TrajectoryKind::Steps => (step_keys(duration_s), Between::Hold),
        };
        Trajectory {
            kind,
            keys,
            between,
            start,
            speed_mps,
            tilt_deg,
        }
    }

    pub fn kind(&self) -> TrajectoryKind {
        self.kind
    }

    /// The head at time `t_s` (seconds from the start).
    pub fn state(&self, t_s: f64) -> HeadState {
        let (alpha_l_deg, alpha_r_deg) = self.angles_deg(t_s);
        let moving = self.speed_mps != 0.0;
        // A vehicle on a real road pitches a little; it moves both cameras alike, so the verge
        // is untouched, but it keeps the estimator from seeing a perfectly static head.
        let bounce_deg = if moving {
            0.15 * (2.0 * PI * 1.3 * t_s).sin() + 0.05 * (2.0 * PI * 3.1 * t_s + 1.0).sin()
        } else {
            0.0
        };
        HeadState {
            position: self.start + Vector3::new(0.0, 0.0, self.speed_mps * t_s),
            tilt_rad: (self.tilt_deg + bounce_deg).to_radians(),
            alpha_l_rad: alpha_l_deg.to_radians(),
            alpha_r_rad: alpha_r_deg.to_radians(),
        }
    }

    /// The z the left optical centre reaches at `t_s`.
    pub fn z_at(&self, t_s: f64) -> f64 {
        self.start.z + self.speed_mps * t_s
    }

    fn angles_deg(&self, t_s: f64) -> (f64, f64) {
        let next = self.keys.partition_point(|k| k.t_s <= t_s);
        let Some(prev) = next.checked_sub(1).map(|i| self.keys[i]) else {
            let first = self.keys[0];
            return (first.alpha_l_deg, first.alpha_r_deg);
        };
        match (self.keys.get(next), self.between) {
            (Some(to), Between::Ease | Between::Linear) => {
                let s = (t_s - prev.t_s) / (to.t_s - prev.t_s);
                let w = if self.between == Between::Ease {
                    0.5 - 0.5 * (PI * s).cos()
                } else {
                    s
                };
                (
                    prev.alpha_l_deg + (to.alpha_l_deg - prev.alpha_l_deg) * w,
                    prev.alpha_r_deg + (to.alpha_r_deg - prev.alpha_r_deg) * w,
                )
            }
            _ => (prev.alpha_l_deg, prev.alpha_r_deg),
        }
    }
}

/// A hand's speed, 6-20 °/s (fig. 5.1's moves); a move lasts at least 0.3 s, as a hand does.
fn hand_speed(rng: &mut ChaCha8Rng, degrees: f64) -> f64 {
    (degrees / rng.random_range(6.0..20.0)).max(0.3)
}

/// A verge motor's speed, 30-150 °/s: from a slow pursuit to a fast but ordinary turn of a head
/// like the thesis' CeDAR (chapter 4: "motions that exceed human performance"), so a move
/// covers 1-5° per frame interval at 30 fps; it lasts as long as the distance takes.
fn motor_speed(rng: &mut ChaCha8Rng, degrees: f64) -> f64 {
    degrees / rng.random_range(30.0..150.0)
}

/// Fig. 5.1 style: alternate pauses and moves of one camera (chosen at random) to a new verge
/// drawn uniformly in ±15°; `duration` draws how long a move of so many degrees takes.
fn manual_keys(seed: u64, duration_s: f64, duration: fn(&mut ChaCha8Rng, f64) -> f64) -> Vec<Key> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6d61_6e75_616c);
    let mut key = Key {
        t_s: 0.0,
        alpha_l_deg: FIXED_VERGE_DEG / 2.0,
        alpha_r_deg: -FIXED_VERGE_DEG / 2.0,
    };
    let mut keys = vec![key];
    while key.t_s <= duration_s {
        key.t_s += rng.random_range(0.3..1.5);
        keys.push(key);
        let target = rng.random_range(-MANUAL_VERGE_LIMIT_DEG..MANUAL_VERGE_LIMIT_DEG);
        let moved = if rng.random_bool(0.5) {
            let a =
                (target + key.alpha_r_deg).clamp(-MANUAL_ALPHA_LIMIT_DEG, MANUAL_ALPHA_LIMIT_DEG);
            let delta = (a - key.alpha_l_deg).abs();
            key.alpha_l_deg = a;
            delta
        } else {
            let a =
                (key.alpha_l_deg - target).clamp(-MANUAL_ALPHA_LIMIT_DEG, MANUAL_ALPHA_LIMIT_DEG);
            let delta = (a - key.alpha_r_deg).abs();
            key.alpha_r_deg = a;
            delta
        };
        key.t_s += duration(&mut rng, moved);
        keys.push(key);
    }
    keys
}

/// The `steps` list, repeated to cover the duration. Every other step also turns both cameras
/// by the same 2° (the verge is unchanged), so only a true verge estimate follows the truth.
fn step_keys(duration_s: f64) -> Vec<Key> {
    let mut keys = Vec::new();
    let mut t_s = 0.0;
    let mut i = 0usize;
    while t_s <= duration_s {
        let verge = STEPS_DEG[i % STEPS_DEG.len()];
        let common = if i % 2 == 1 { 2.0 } else { 0.0 };
        keys.push(Key {
            t_s,
            alpha_l_deg: verge / 2.0 + common,
            alpha_r_deg: -verge / 2.0 + common,
        });
        t_s += STEP_HOLD_S;
        i += 1;
    }
    keys
}

#[cfg(test)]
mod tests {
    use super::*;

    fn make(kind: TrajectoryKind, seed: u64) -> Trajectory {
        Trajectory::new(
            kind,
            seed,
            60.0,
            Vector3::zeros(),
            0.0,
            0.0,
            FIXED_VERGE_DEG,
        )
    }

    #[test]
    fn manual_stays_in_range_and_is_smooth() {
        let t = make(TrajectoryKind::Manual, 3);
        let mut prev = t.state(0.0).verge_deg();
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for i in 1..=6000 {
            let v = t.state(f64::from(i) * 0.01).verge_deg();
            assert!(v.abs() <= 15.0 + 1e-9, "verge {v} out of range");
            // Hand speed ≤ 20 °/s with a cosine ease: ≤ 20·π/2 °/s peak, i.e. < 0.32° per 10 ms.
            assert!((v - prev).abs() < 0.32, "jump at step {i}");
            prev = v;
            lo = lo.min(v);
            hi = hi.max(v);
        }
        assert!(
            hi - lo > 15.0,
            "manual moves should sweep most of the range"
        );
    }

    #[test]
    fn motor_moves_start_at_full_speed_within_range() {
        let t = make(TrajectoryKind::Motor, 3);
        let frame = 1.0 / 30.0;
        let (mut onsets, mut fastest) = (0, 0f64);
        let mut prev_step = 0.0;
        for i in 1..1800 {
            let at = |k: i32| t.state(f64::from(k) * frame).verge_deg();
            let step = at(i) - at(i - 1);
            assert!(at(i).abs() <= 15.0 + 1e-9, "verge {} out of range", at(i));
            // An onset: still over one frame interval, a degree or more over the next.
            if prev_step == 0.0 && step.abs() >= 1.0 {
                onsets += 1;
            }
            fastest = fastest.max(step.abs());
            prev_step = step;
        }
        assert!(onsets >= 10, "{onsets} abrupt onsets in 60 s");
        assert!(
            (4.0..=5.0).contains(&fastest),
            "fastest {fastest}° per frame"
        );
    }

    #[test]
    fn deterministic_for_a_seed() {
        let a = make(TrajectoryKind::Manual, 9);
        let b = make(TrajectoryKind::Manual, 9);
        let c = make(TrajectoryKind::Manual, 10);
        assert_eq!(a.state(12.3), b.state(12.3));
        assert_ne!(a.state(12.3), c.state(12.3));
    }

    #[test]
    fn fixed_and_steps() {
        let f = Trajectory::new(
            TrajectoryKind::Fixed,
            0,
            10.0,
            Vector3::zeros(),
            10.0,
            2.0,
            FIXED_VERGE_DEG,
        );
        assert!((f.state(3.7).verge_deg() - FIXED_VERGE_DEG).abs() < 1e-12);
        let wide = Trajectory::new(
            TrajectoryKind::Fixed,
            0,
            1.0,
            Vector3::zeros(),
            0.0,
            0.0,
            17.5,
        );
        assert!((wide.state(0.4).verge_deg() - 17.5).abs() < 1e-12);
        assert!((f.state(2.0).position.z - 20.0).abs() < 1e-12);
        let s = make(TrajectoryKind::Steps, 0);
        assert!((s.state(2.5).verge_deg() - 2.0).abs() < 1e-12);
        assert!((s.state(6.1).verge_deg() - 10.0).abs() < 1e-12);
        assert!("steps".parse::<TrajectoryKind>().is_ok());
        assert!("wobble".parse::<TrajectoryKind>().is_err());
    }
}
