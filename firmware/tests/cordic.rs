//! CORDIC against atan2/hypot: the stated bounds hold; golden vectors; the fast path's
//! branch-free version equals the register-level steps.

use proptest::prelude::*;
use stereocal_firmware::fabric::cordic::{
    cordic, magnitude_code, CordicPipeline, MAGNITUDE_BOUND, MAGNITUDE_GAIN, ORIENTATION_BOUND_DEG,
};
use stereocal_firmware::fabric::fast::cordic_row;

fn errors(sx: i32, sy: i32) -> (f64, f64) {
    let (mag, ori) = cordic(sx, sy);
    let truth = (sy as f64).atan2(sx as f64).to_degrees().rem_euclid(360.0);
    let d = (ori as f64 * 5.625 - truth).rem_euclid(360.0);
    let ang = d.min(360.0 - d);
    let h = (sx as f64).hypot(sy as f64);
    (ang, (mag as f64 / (MAGNITUDE_GAIN * h) - 1.0).abs())
}

#[test]
fn golden_vectors() {
    // Axis and diagonal directions land on their exact bins (bin = angle / 5.625 deg, y down).
    assert_eq!(cordic(256, 0).1, 0);
    assert_eq!(cordic(256, 256).1, 8);
    assert_eq!(cordic(0, 256).1, 16);
    assert_eq!(cordic(-256, 0).1, 32);
    assert_eq!(cordic(0, -256).1, 48);
    assert_eq!(cordic(0, 0), (0, 0));
    // |(3,4)| = 5 grey levels of Sobel response in Q8.8 = 1280: x_n·5/8 ≈ 1.0286·1280 = 1316.
    let (m, _) = cordic(3 * 256, 4 * 256);
    assert!((1310..=1320).contains(&m), "{m}");
    assert_eq!(magnitude_code(m), 1); // (1316 + 512) >> 10
    assert_eq!(magnitude_code(1 << 20), 255); // saturates
}

#[test]
fn bounds_hold_on_a_dense_grid() {
    let (mut worst_a, mut worst_m) = (0f64, 0f64);
    for sx in (-4000..=4000).step_by(37) {
        for sy in (-4000..=4000).step_by(41) {
            if (sx as f64).hypot(sy as f64) < 256.0 {
                continue;
            }
            let (a, m) = errors(sx, sy);
            worst_a = worst_a.max(a);
            worst_m = worst_m.max(m);
        }
    }
    eprintln!(
        "worst orientation error {worst_a:.3} deg, worst magnitude error {:.3} %",
        worst_m * 100.0
    );
    assert!(worst_a <= ORIENTATION_BOUND_DEG, "{worst_a}");
    assert!(worst_m <= MAGNITUDE_BOUND, "{worst_m}");
}

#[test]
fn pipeline_has_the_documented_latency_and_values() {
    let mut p = CordicPipeline::new();
    let mut outs = Vec::new();
    for t in 0..12 {
        let inp = (t == 0).then_some((5u16, 6u16, 1000, -700));
        if let Some(o) = p.clock(inp) {
            outs.push((t, o));
        }
    }
    let (mag, ori) = cordic(1000, -700);
    assert_eq!(outs, vec![(7, (5, 6, magnitude_code(mag), ori))]);
}

proptest! {
    #[test]
    fn bounds_hold_for_random_vectors(sx in -(1i32 << 18)..(1 << 18), sy in -(1i32 << 18)..(1 << 18)) {
        prop_assume!((sx as f64).hypot(sy as f64) >= 256.0);
        let (a, m) = errors(sx, sy);
        prop_assert!(a <= ORIENTATION_BOUND_DEG, "angle error {}", a);
        prop_assert!(m <= MAGNITUDE_BOUND, "magnitude error {}", m);
    }

    #[test]
    fn branch_free_row_equals_the_steps(v in prop::collection::vec((-(1i32 << 18)..(1 << 18), -(1i32 << 18)..(1 << 18)), 1..64)) {
        let sx: Vec<i32> = v.iter().map(|p| p.0).collect();
        let sy: Vec<i32> = v.iter().map(|p| p.1).collect();
        let (mut m, mut o) = (vec![0u8; v.len()], vec![0u8; v.len()]);
        cordic_row(&sx, &sy, &mut m, &mut o);
        for i in 0..v.len() {
            let (mag, ori) = cordic(sx[i], sy[i]);
            prop_assert_eq!((m[i], o[i]), (magnitude_code(mag), ori));
        }
    }
}
