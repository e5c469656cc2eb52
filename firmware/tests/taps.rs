//! The quantized kernels: unity DC gain, the documented deviations, exact cascade variance,
//! and the LUT distributed arithmetic equal to the dot product.

use proptest::prelude::*;
use stereocal_firmware::fabric::convolver::{da_column, da_row};
use stereocal_firmware::fabric::taps::{
    da_lut, discrete_sigma, GAUSS_LUTS, GAUSS_TAPS, TABLE_4_2_DISCRETE_TAPS, TAP_BITS,
};

#[test]
fn taps_have_unity_dc_gain_and_are_symmetric_unimodal() {
    for t in &GAUSS_TAPS {
        assert_eq!(
            t.iter().map(|&v| v as u32).sum::<u32>(),
            1 << TAP_BITS,
            "{t:?}"
        );
        assert_eq!((t[0], t[1]), (t[4], t[3]), "{t:?} symmetric");
        assert!(t[0] <= t[1] && t[1] <= t[2], "{t:?} unimodal");
        assert!(t.iter().all(|&v| v < 1024), "{t:?} fits 10 bits");
    }
}

#[test]
fn deviations_match_the_design_column_of_table_4_2() {
    // G0: sqrt(1 - 0.5^2) (camera blur 0.5 to a base of 1); G1..G3: thesis design sigmas.
    let design = [0.75f64.sqrt(), 0.7664, 0.9656, 1.2166];
    for (t, d) in GAUSS_TAPS.iter().zip(design) {
        let s = discrete_sigma(t);
        assert!((s - d).abs() < 5e-4, "{t:?}: sigma {s} vs design {d}");
    }
}

#[test]
fn the_discrete_set_matches_the_discrete_column_of_table_4_2() {
    let column = [1.1592f64, 0.8292, 0.9354, 1.1040];
    for (t, d) in TABLE_4_2_DISCRETE_TAPS.iter().zip(column) {
        assert_eq!(t.iter().map(|&v| v as u32).sum::<u32>(), 1 << TAP_BITS);
        assert!(t[0] <= t[1] && t[1] <= t[2] && (t[0], t[1]) == (t[4], t[3]));
        let s = discrete_sigma(t);
        assert!((s - d).abs() < 5e-4, "{t:?}: sigma {s} vs table 4.2 {d}");
    }
}

#[test]
fn cascade_variance_is_exactly_three_so_g3_is_twice_the_base() {
    let var = |t: &[u16; 5]| 8 * t[0] as u32 + 2 * t[1] as u32;
    let sum: u32 = GAUSS_TAPS[1..].iter().map(var).sum();
    assert_eq!(
        sum,
        3 << TAP_BITS,
        "G1..G3 variances must add to 3 (base 1 -> 4 = 2^2)"
    );
}

#[test]
fn lut_golden_entries() {
    // Entry m sums the taps whose bit is set: 0b00001 = tap 0, 0b10001 = taps 0 and 4, 31 = all.
    let l = da_lut(&GAUSS_TAPS[0]);
    assert_eq!(l[0], 0);
    assert_eq!(l[1], GAUSS_TAPS[0][0]);
    assert_eq!(l[0b10001], 2 * GAUSS_TAPS[0][0]);
    assert_eq!(l[31], 1024);
    assert_eq!(GAUSS_LUTS[3], da_lut(&GAUSS_TAPS[3]));
}

proptest! {
    #[test]
    fn row_distributed_arithmetic_is_the_exact_dot_product(s in prop::array::uniform5(any::<u16>()), k in 0usize..4) {
        let t = GAUSS_TAPS[k];
        let dot: u32 = t.iter().zip(s).map(|(&t, s)| t as u32 * s as u32).sum();
        prop_assert_eq!(da_row(&GAUSS_LUTS[k], s), dot);
        prop_assert!(dot < 1 << 26);
    }

    #[test]
    fn column_distributed_arithmetic_rounds_the_dot_product_once(s in prop::array::uniform5(0u32..=1024 * 0xFFFF), k in 0usize..4) {
        let t = GAUSS_TAPS[k];
        let dot: u64 = t.iter().zip(s).map(|(&t, s)| t as u64 * s as u64).sum();
        let expect = (dot + (1 << 19)) >> 20;
        prop_assert_eq!(u64::from(da_column(&GAUSS_LUTS[k], s)), expect);
        // Unity DC gain: never above the largest input, so Q8.8 inputs give a Q8.8 output.
        prop_assert!(expect <= (*s.iter().max().unwrap() as u64 + 512) >> 10);
    }
}
