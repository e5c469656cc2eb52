//! The estimator's optional modes reach it from the command line and each still measures the
//! verge: the reduced 16-element descriptor and dominant-orientation rotation (thesis 6.3),
//! matching without the left-right check or the vertical-disparity gate. Each changes which
//! matches are made (so the flag took effect) and none loses a frame or the accuracy.

use std::process::Command;

fn eval(extra: &[&str]) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_stereocal"))
        .args([
            "eval", "--scene", "road", "--frames", "8", "--seed", "1", "--json",
        ])
        .args(extra)
        .output()
        .expect("stereocal runs");
    assert!(
        out.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON summary")
}

#[test]
fn every_optional_mode_estimates_the_verge() {
    let default = eval(&[]);
    for extra in [
        &["--descriptor", "reduced16"][..],
        &["--rotate"],
        &["--no-cross-check"],
        &["--no-vertical-gate"],
        &["--max-vertical-px", "4"],
    ] {
        let j = eval(extra);
        assert_eq!(j["estimated_frames"], 8, "{extra:?}: {j}");
        let max = j["max_abs_err_deg"].as_f64().unwrap();
        assert!(max < 0.05, "{extra:?}: max error {max}");
        assert_ne!(
            j["median_matches"], default["median_matches"],
            "{extra:?} changed no match"
        );
    }
}
