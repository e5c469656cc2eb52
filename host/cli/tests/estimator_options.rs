//! The estimator's optional modes reach it from the command line and each still measures the
//! verge: the reduced 16-element descriptor and dominant-orientation rotation (thesis 6.3),
//! matching without the left-right check or the vertical-disparity gate or with another ratio
//! or a best-N cut, the solve without RANSAC, with the general five-degree-of-freedom model,
//! with each frame alone or with more of the head's fixed misalignments learned over the
//! window (which reports them) than the default's roll, and Sobel
//! patches on the wire. Each must show its effect (so the flag took effect): a mode of the
//! matcher changes the matches, `--best N` keeps N of them, the solver's modes keep the
//! matches and change the estimates (or, where the rendered head gives a mode nothing to change,
//! report what it learns), patches cut the wire bytes and the noisy link's guard adds to them. None loses a frame, and
//! every mode keeps the maximum error under 0.05°, except Sobel patches (which leave the
//! sub-pixel refinement without its octave-0 Sobel plane) under 0.1°.

mod common;

use common::{stereocal, succeeded};
use serde_json::Value;

fn eval(extra: &[&str]) -> Value {
    let args = [
        "eval", "--scene", "road", "--frames", "8", "--seed", "1", "--json",
    ];
    let out = succeeded(stereocal(&[&args[..], extra].concat()));
    serde_json::from_slice(&out.stdout).expect("JSON summary")
}

fn number(j: &Value, key: &str) -> f64 {
    j[key]
        .as_f64()
        .unwrap_or_else(|| panic!("`{key}` is not a number in {j}"))
}

/// The effect that shows a mode took effect, against the default run.
#[derive(Debug, Clone, Copy)]
enum Effect {
    /// Other matches than the default's.
    OtherMatches,
    /// More matches than the default's.
    MoreMatches,
    /// Fewer matches than the default's.
    FewerMatches,
    /// Exactly this many matches per pair.
    Matches(f64),
    /// The default's matches, and estimates that differ from the default's.
    SameMatchesOtherEstimates,
    /// At most this fraction of the default's wire bytes per pair.
    WireBytesAtMost(f64),
    /// The default's estimates to the bit, on at least this multiple of its wire bytes.
    SameEstimatesWireBytesAtLeast(f64),
    /// The default's estimates to the bit, and a misalignment the default does not learn
    /// (zero in its JSON) reported learned: this field of `misalignment` is not zero.
    SameEstimatesLearns(&'static str),
}

/// Whether `j` has the default's matches and errors to the bit.
fn same_estimates(j: &Value, default: &Value) -> bool {
    ["median_matches", "median_abs_err_deg", "max_abs_err_deg"]
        .iter()
        .all(|key| number(j, key) == number(default, key))
}

impl Effect {
    fn holds(self, j: &Value, default: &Value) -> bool {
        let matches = number(j, "median_matches");
        let default_matches = number(default, "median_matches");
        match self {
            Effect::OtherMatches => matches != default_matches,
            Effect::MoreMatches => matches > default_matches,
            Effect::FewerMatches => matches < default_matches,
            Effect::Matches(n) => matches == n,
            // The chain is deterministic, so an ignored flag would give the default's bits.
            Effect::SameMatchesOtherEstimates => {
                matches == default_matches
                    && number(j, "median_abs_err_deg") != number(default, "median_abs_err_deg")
            }
            Effect::WireBytesAtMost(fraction) => {
                number(j, "wire_bytes_per_pair")
                    <= fraction * number(default, "wire_bytes_per_pair")
            }
            Effect::SameEstimatesWireBytesAtLeast(multiple) => {
                same_estimates(j, default)
                    && number(j, "wire_bytes_per_pair")
                        >= multiple * number(default, "wire_bytes_per_pair")
            }
            Effect::SameEstimatesLearns(field) => {
                same_estimates(j, default)
                    && number(&default["misalignment"], field) == 0.0
                    && number(&j["misalignment"], field) != 0.0
            }
        }
    }
}

#[test]
fn every_optional_mode_estimates_the_verge() {
    let default = eval(&[]);
    let modes: [(&[&str], Effect, f64); 18] = [
        (&["--descriptor", "reduced16"], Effect::OtherMatches, 0.05),
        (&["--rotate"], Effect::OtherMatches, 0.05),
        (&["--no-cross-check"], Effect::OtherMatches, 0.05),
        (&["--no-vertical-gate"], Effect::OtherMatches, 0.05),
        (&["--max-vertical-px", "4"], Effect::OtherMatches, 0.05),
        (&["--ratio", "0.8"], Effect::MoreMatches, 0.05),
        (&["--ratio", "0.4"], Effect::FewerMatches, 0.05),
        (&["--best", "100"], Effect::Matches(100.0), 0.05),
        (&["--no-ransac"], Effect::SameMatchesOtherEstimates, 0.05),
        // The general model fits a relative pitch and roll, so its matching band lets more of
        // them through: other matches.
        (&["--model", "general"], Effect::OtherMatches, 0.05),
        (
            &["--misalignment", "window"],
            Effect::SameMatchesOtherEstimates,
            0.05,
        ),
        (
            &["--misalignment", "window-tilt"],
            Effect::SameMatchesOtherEstimates,
            0.05,
        ),
        // The rendered head's frames do not pitch apart: the prior holds each frame's own
        // pitch at their mean, and the estimates are the default's to the bit; the mode shows
        // in the frames' mean pitch it reports, with its standard error.
        (
            &["--misalignment", "window-frame-pitch"],
            Effect::SameEstimatesLearns("pitch_sigma_deg"),
            0.05,
        ),
        // The default learns the roll over a window; `off` takes each frame alone.
        (
            &["--misalignment", "off"],
            Effect::SameMatchesOtherEstimates,
            0.05,
        ),
        // Grid points add guided matches, not descriptor matches.
        (&["--grid", "12"], Effect::SameMatchesOtherEstimates, 0.05),
        // The disparity gradient moves refined points, not the descriptor matches.
        (
            &["--disparity-gradient"],
            Effect::SameMatchesOtherEstimates,
            0.05,
        ),
        (&["--sobel", "patches"], Effect::WireBytesAtMost(0.6), 0.1),
        // Parity and smaller packets change the bytes on the link, not what arrives.
        (
            &["--noisy-link"],
            Effect::SameEstimatesWireBytesAtLeast(1.2),
            0.05,
        ),
    ];
    for (extra, effect, max_err) in modes {
        let j = eval(extra);
        assert_eq!(j["estimated_frames"], 8, "{extra:?}: {j}");
        let max = number(&j, "max_abs_err_deg");
        assert!(max < max_err, "{extra:?}: max error {max}°");
        assert!(
            effect.holds(&j, &default),
            "{extra:?}: no {effect:?} in {j} against the default {default}"
        );
        // The window reports its estimate; the rendered head has no misalignment, the
        // pitch is estimated unless only the roll is (the default), and the baseline's tilt
        // only when asked. Each frame alone, and the general model, which frees the
        // misalignments in every frame, report none.
        let m = &j["misalignment"];
        let window = match extra {
            ["--misalignment", "off"] | ["--model", "general"] => None,
            ["--misalignment", mode] => Some(*mode),
            _ => Some("window-roll"),
        };
        match window {
            Some(mode) => {
                assert_eq!(m["frames"], 8, "{extra:?}: {j}");
                assert!(number(m, "pitch_deg").abs() < 0.05, "{extra:?}: {m}");
                assert!(number(m, "roll_deg").abs() < 0.05, "{extra:?}: {m}");
                let tilt_sigma = number(m, "baseline_tilt_sigma_deg");
                assert_eq!(tilt_sigma > 0.0, mode == "window-tilt", "{extra:?}: {m}");
                let pitch_sigma = number(m, "pitch_sigma_deg");
                assert_eq!(pitch_sigma > 0.0, mode != "window-roll", "{extra:?}: {m}");
            }
            None => assert!(m.is_null(), "{extra:?}: {j}"),
        }
    }
}
