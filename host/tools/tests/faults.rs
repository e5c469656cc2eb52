//! Faults on the link cost frames, never correctness: a short rendered sequence through the
//! in-process device with heavy damage between its bytes and the host driver.

use std::time::{Duration, Instant};

use stereocal::link::{FaultConfig, FaultLink, Link, LinkError, LinkProtection, ReplayLink};
use stereocal_tools::reliability::{
    is_wrong_estimate, judge, run, salvage_moves, FaultKind, PairResult,
};
use stereocal_tools::workload::Workload;

const FRAMES: usize = 10;
/// Faults on for frames 2..7; frames 7..10 show recovery.
const BURST: std::ops::Range<usize> = 2..7;

#[test]
fn heavy_faults_cost_frames_never_estimates_and_the_link_recovers() {
    let workload = Workload::road(FRAMES, 3, 320, 240).unwrap();
    let clean = run(
        &workload,
        FaultConfig::none(3),
        BURST,
        &LinkProtection::noisy(),
    )
    .unwrap();
    // The packing and the parity change the bytes, not what arrives.
    let plain = run(
        &workload,
        FaultConfig::none(3),
        BURST,
        &LinkProtection::clean(),
    )
    .unwrap();
    assert_eq!(plain.delivered, clean.delivered);
    assert!(plain.stats.bytes_received < clean.stats.bytes_received);
    let estimated = clean
        .delivered
        .iter()
        .filter(|(_, r)| matches!(r, PairResult::Estimated { .. }))
        .count();
    assert!(
        estimated >= FRAMES - 2,
        "clean run estimated only {estimated} pairs"
    );

    // Every kind at once, at a rate that damages nearly every frame of the burst. The burst
    // has some 4500 packets, so truncation runs at 2e-3 per packet (about 9 expected, none
    // with probability e^-9): the check below holds whatever the packet sizes and the seed.
    let faults = FaultConfig {
        truncate_rate: 2e-3,
        ..FaultKind::All.config(1e-4, 5)
    };
    let faulted = run(&workload, faults, BURST, &LinkProtection::noisy()).unwrap();
    let v = judge(&clean, &faulted, FRAMES, &BURST);
    let f = faulted.faults;
    assert!(
        f.bits_flipped > 0 && f.bytes_dropped > 0 && f.packets_truncated > 0,
        "{f:?}"
    );
    assert!(v.reported_damaged > 0, "no frame reported damaged: {v:?}");
    assert_eq!(v.wrong, 0, "{v:?}");
    assert_eq!(v.recovery, Some(0), "{v:?}");
    assert_eq!(v.bad_after_burst, 0, "{v:?}");
}

#[test]
fn a_changed_estimate_counts_as_wrong() {
    // The judge must be able to fail: tamper with one delivered result of a clean run.
    let workload = Workload::road(3, 5, 320, 240).unwrap();
    let clean = run(
        &workload,
        FaultConfig::none(5),
        0..0,
        &LinkProtection::clean(),
    )
    .unwrap();
    let mut tampered = clean.clone();
    let original = tampered.delivered[1].1;
    tampered.delivered[1].1 = match original {
        PairResult::Estimated {
            verge_deg,
            sigma_deg,
            ..
        } => PairResult::Estimated {
            verge_deg: f64::from_bits(verge_deg.to_bits() ^ 1),
            sigma_deg,
            salvaged: false,
        },
        PairResult::NoEstimate { .. } => PairResult::Estimated {
            verge_deg: 0.0,
            sigma_deg: 1.0,
            salvaged: false,
        },
    };
    assert_eq!(judge(&clean, &clean, 3, &(0..0)).wrong, 0);
    assert_eq!(judge(&clean, &tampered, 3, &(0..0)).wrong, 1);
    // A salvaged estimate may differ by up to its sigma, not beyond.
    if let PairResult::Estimated {
        verge_deg,
        sigma_deg,
        ..
    } = original
    {
        let salvaged = |offset: f64| PairResult::Estimated {
            verge_deg: verge_deg + offset,
            sigma_deg,
            salvaged: true,
        };
        tampered.delivered[1].1 = salvaged(0.5 * sigma_deg);
        assert_eq!(judge(&clean, &tampered, 3, &(0..0)).wrong, 0);
        // Its move in units of its own sigma, against a subset's standard deviation: none
        // when the sigma did not grow, sqrt(3)/2 when it doubled.
        assert!(salvage_moves(&clean, &clean).is_empty());
        let moves = salvage_moves(&clean, &tampered);
        assert_eq!(moves.len(), 1);
        assert!((moves[0].ratio - 0.5).abs() < 1e-9, "{moves:?}");
        assert_eq!(moves[0].subset_std, 0.0);
        tampered.delivered[1].1 = PairResult::Estimated {
            verge_deg: verge_deg + sigma_deg,
            sigma_deg: 2.0 * sigma_deg,
            salvaged: true,
        };
        let moves = salvage_moves(&clean, &tampered);
        assert!((moves[0].ratio - 0.5).abs() < 1e-9, "{moves:?}");
        assert!(
            (moves[0].subset_std - 0.75f64.sqrt()).abs() < 1e-9,
            "{moves:?}"
        );
        tampered.delivered[1].1 = salvaged(1.5 * sigma_deg);
        assert_eq!(judge(&clean, &tampered, 3, &(0..0)).wrong, 1);
        tampered.delivered[1].1 = PairResult::NoEstimate { salvaged: true };
        assert_eq!(judge(&clean, &tampered, 3, &(0..0)).wrong, 0);
    }
}

/// All bytes `link` hands out until it closes.
fn drain(mut link: impl Link) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = [0u8; 100];
    let deadline = Instant::now() + Duration::from_secs(1);
    loop {
        match link.recv(&mut buf, deadline) {
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(LinkError::Closed { .. }) => return out,
            Err(e) => panic!("{e}"),
        }
    }
}

/// Delimited "packets" of non-zero bytes, as the wire format's COBS frames are.
fn stream() -> Vec<u8> {
    (0..2000u32)
        .flat_map(|i| {
            let mut p: Vec<u8> = (0..(i % 37 + 3)).map(|j| (i + j) as u8 | 1).collect();
            p.push(0);
            p
        })
        .collect()
}

fn faulted(config: FaultConfig) -> Vec<u8> {
    let mut link = FaultLink::new(ReplayLink::new(stream()).with_chunk(777), config).unwrap();
    link.set_active(true);
    drain(link)
}

#[test]
fn damage_is_deterministic_by_seed_and_absent_when_off() {
    let mut config = FaultKind::All.config(1e-2, 11);
    config.stall = Duration::ZERO;
    let a = faulted(config);
    assert_eq!(a, faulted(config));
    assert_ne!(a, stream());
    assert_ne!(a, faulted(FaultConfig { seed: 12, ..config }));
    assert_eq!(faulted(FaultConfig::none(11)), stream());
    // Inactive, the configured faults do nothing.
    let idle = FaultLink::new(ReplayLink::new(stream()), config).unwrap();
    assert_eq!(drain(idle), stream());
}

#[test]
fn a_rate_outside_zero_to_one_is_refused() {
    let config = FaultConfig {
        bit_flip_rate: 1.5,
        ..FaultConfig::none(0)
    };
    let err = FaultLink::new(ReplayLink::new(Vec::new()), config)
        .err()
        .unwrap();
    assert_eq!(err.name, "bit_flip_rate");
}

/// The session (what `demo`, `eval`, `run` and `hil` use) over a damaging link: every frame
/// gets a record, a damaged pair is `dropped`, and every estimate equals the clean run's for
/// the same frame; frames after the burst are estimated again.
#[test]
fn a_session_over_a_damaging_link_drops_frames_and_keeps_estimates_exact() {
    use stereocal::link::InProcessLink;
    use stereocal::output::record::{FrameRecord, FrameStatus};
    use stereocal::session::{Session, SessionConfig};
    use stereocal_synth::{SceneKind, Sequence, SequenceConfig};
    use stereocal_tools::eval::sequence_calibration;

    let sequence = Sequence::builtin(
        SceneKind::Road,
        SequenceConfig {
            width: 320,
            height: 240,
            frames: FRAMES,
            seed: 4,
            ..SequenceConfig::for_scene(SceneKind::Road)
        },
    )
    .unwrap();
    let calib = sequence_calibration(&sequence).unwrap();
    let frames: Vec<_> = (0..FRAMES).map(|i| sequence.frame(i).unwrap()).collect();
    let run = |faults: FaultConfig| -> Vec<FrameRecord> {
        let mut link = FaultLink::new(InProcessLink::new().unwrap(), faults).unwrap();
        link.set_active(false);
        // The burst drops frames that come before the ones after it.
        let per_frame = SessionConfig::per_frame();
        let mut session = Session::with_device(link, calib, 320, 240, per_frame).unwrap();
        frames
            .iter()
            .map(|f| {
                session.device_mut().set_active(BURST.contains(&f.index));
                let images = f.images.as_ref().unwrap();
                session
                    .process(
                        f.index,
                        Some((images.left.as_raw(), images.right.as_raw())),
                        (320, 240),
                        f.timestamp_us,
                        Some(f.truth.verge_deg),
                    )
                    .expect("a damaged frame is a dropped record, not an error")
            })
            .collect()
    };
    let clean = run(FaultConfig::none(4));
    let faulted = run(FaultKind::All.config(1e-5, 4));
    assert_eq!(faulted.len(), FRAMES);
    let dropped = faulted
        .iter()
        .filter(|r| r.status == FrameStatus::Dropped)
        .count();
    assert!(dropped > 0, "no frame of the burst was damaged");
    for (c, f) in clean.iter().zip(&faulted) {
        match (f.status, f.raw_verge_deg, c.raw_verge_deg) {
            (FrameStatus::Ok, ..) => {
                assert_eq!(f.raw_verge_deg, c.raw_verge_deg, "frame {}", f.frame)
            }
            (FrameStatus::Salvaged, Some(v), Some(clean)) => {
                let sigma = f.raw_sigma_deg.unwrap_or(f64::NAN);
                assert!(
                    !is_wrong_estimate(v, sigma, true, clean),
                    "frame {}: salvaged {v} ± {sigma}, clean {clean}",
                    f.frame
                );
            }
            (FrameStatus::Salvaged, ..) => {
                panic!("frame {}: salvaged without a clean estimate", f.frame)
            }
            _ => {}
        }
        if !BURST.contains(&f.frame) {
            assert_eq!(f.status, c.status, "frame {} outside the burst", f.frame);
        }
    }
}

/// The soak, short: faults on every frame of a session, every estimate equal to the clean
/// run's for the same rendered pair (within its own sigma when salvaged), the estimated frames within the accuracy bar, and the
/// resident set sampled where it was asked for.
#[test]
fn a_short_soak_keeps_estimates_exact_and_samples_memory() {
    use stereocal_tools::soak::{soak, SoakConfig, MEDIAN_BAR_DEG};

    let config = SoakConfig {
        frames: 60,
        cycle: 6,
        seed: 1,
        width: 640,
        height: 480,
        kind: FaultKind::All,
        rate: 3e-8,
        sample_every: 20,
    };
    let s = soak(config, &|_| {}).unwrap();
    assert_eq!(s.frames, 60);
    assert_eq!(s.delivered + s.dropped, 60, "{s:?}");
    // Damaged frames are salvaged (or dropped) on the noisy-link guard the soak runs.
    assert!(s.salvaged + s.dropped > 0, "no frame was damaged: {s:?}");
    assert!(s.estimated > 0, "no frame was estimated: {s:?}");
    assert_eq!(s.wrong, 0, "{s:?}");
    // Six rendered pairs are too few for the soak's own median to be a statistic (which pairs
    // the faults happen to drop or salvage decides it): every delivered estimate equals the
    // clean run's for its pair, or lies within its own sigma of it when salvaged
    // (`wrong == 0`), so the bar is checked on the clean run over the six pairs.
    let clean = s.clean_median_deg.unwrap();
    assert!(
        clean <= MEDIAN_BAR_DEG,
        "clean median raw error {clean}°: {s:?}"
    );
    // Memory plumbing (flatness is judged on the long soak: this test shares its process
    // with the others).
    if std::path::Path::new("/proc/self/status").exists() {
        let frames: Vec<usize> = s.memory.iter().map(|m| m.frame).collect();
        assert_eq!(frames, [20, 40, 60]);
        assert!(s.memory.iter().all(|m| m.rss_kib > 0), "{:?}", s.memory);
        assert_eq!(s.baseline().unwrap().frame, 40);
        assert!(s.growth_kib().is_some());
    }
    let md = stereocal_tools::soak::markdown(&s, "stereocal reliability --soak 60");
    assert!(md.contains("| **wrong estimates** | **0** |"), "{md}");
}

#[test]
fn the_soak_section_is_replaced_in_place_or_appended() {
    use stereocal_tools::soak::{section, splice, SECTION_BEGIN, SECTION_END};

    let one = format!("{SECTION_BEGIN}\n## Soak\none\n{SECTION_END}\n");
    let two = format!("{SECTION_BEGIN}\n## Soak\ntwo\n{SECTION_END}\n");
    let doc = splice("# Sweep\n\ntable\n", &one);
    assert_eq!(doc, format!("# Sweep\n\ntable\n\n{one}"));
    assert_eq!(section(&doc), Some(one.as_str()));
    let doc = splice(&doc, &two);
    assert_eq!(doc, format!("# Sweep\n\ntable\n\n{two}"));
    assert_eq!(section("# Sweep\n"), None);
}
