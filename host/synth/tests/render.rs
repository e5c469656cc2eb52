//! Ground-truth renderer: determinism, exact pinhole geometry, the verge sign, occlusion,
//! texture content of the built-in scenes, fields, dropped frames and the files written.

use image::GrayImage;
use nalgebra::{Matrix3, Vector3};
use stereocal_synth::{
    Intrinsics, Material, Scene, SceneBox, SceneKind, Sequence, SequenceConfig, Supersampling,
    SynthError, TrajectoryKind, Truth,
};

/// A small, noise-free sequence of `scene` with the `steps` trajectory at 0.4 fps, so that
/// frame 1 is t = 2.5 s (verge 2°, both cameras turned 2° more) and frame 3 is t = 7.5 s
/// (verge 10°: alpha_l = 7°, alpha_r = -3°).
fn still_config(width: u32, height: u32) -> SequenceConfig {
    SequenceConfig {
        width,
        height,
        frames: 4,
        fps: 0.4,
        trajectory: TrajectoryKind::Steps,
        noise_sigma: 0.0,
        supersampling: Supersampling::Adaptive { edge: 8 },
        head_start: [0.0, 0.0, 0.0],
        speed_mps: 0.0,
        tilt_deg: 3.0,
        ..SequenceConfig::for_scene(SceneKind::Lab)
    }
}

fn images(seq: &Sequence, i: usize) -> (GrayImage, GrayImage) {
    let f = seq.frame(i).expect("frame exists");
    let im = f.images.expect("not dropped");
    (im.left, im.right)
}

/// The pinhole model written out independently of the library: head pitched down by `tilt`,
/// camera yawed by `alpha` about its own vertical axis at `center`.
fn project(
    k: &Intrinsics,
    center: Vector3<f64>,
    truth: &Truth,
    alpha_deg: f64,
    p: Vector3<f64>,
) -> [f64; 2] {
    let (st, ct) = truth.tilt_deg.to_radians().sin_cos();
    let (sa, ca) = alpha_deg.to_radians().sin_cos();
    // Pitch down: the optical axis (0, 0, 1) turns to (0, sin, cos), toward +y (down).
    let head = Matrix3::new(1.0, 0.0, 0.0, 0.0, ct, st, 0.0, -st, ct);
    let yaw = Matrix3::new(ca, 0.0, sa, 0.0, 1.0, 0.0, -sa, 0.0, ca);
    let c = (head * yaw).transpose() * (p - center);
    [k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy]
}

/// Optical centres of a head standing at the origin: the right camera 0.3 m along the head's
/// x axis, which a pitch leaves unchanged.
fn head_centers() -> [Vector3<f64>; 2] {
    [Vector3::zeros(), Vector3::new(0.3, 0.0, 0.0)]
}

/// Area and centroid of a simple polygon (shoelace).
fn polygon_area_centroid(p: &[[f64; 2]]) -> (f64, [f64; 2]) {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let (p0, p1) = (p[i], p[(i + 1) % p.len()]);
        let cross = p0[0] * p1[1] - p1[0] * p0[1];
        a += cross;
        cx += (p0[0] + p1[0]) * cross;
        cy += (p0[1] + p1[1]) * cross;
    }
    a *= 0.5;
    (a.abs(), [cx / (6.0 * a), cy / (6.0 * a)])
}

/// Coverage-weighted area and centroid of the bright pixels (value / `full`).
fn image_area_centroid(img: &GrayImage, full: f64) -> (f64, [f64; 2]) {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for (x, y, p) in img.enumerate_pixels() {
        let c = f64::from(p.0[0]) / full;
        a += c;
        cx += c * f64::from(x);
        cy += c * f64::from(y);
    }
    (a, [cx / a, cy / a])
}

/// A zero-thickness white plate at depth `z` (only its front face can be seen).
fn plate(x: [f64; 2], y: [f64; 2], z: f64, value: f32) -> SceneBox {
    SceneBox {
        min: [x[0], y[0], z],
        max: [x[1], y[1], z],
        material: Material::Flat(value),
    }
}

#[test]
fn same_seed_same_pixels_other_seed_other_pixels() {
    let config = |seed| SequenceConfig {
        width: 96,
        height: 64,
        frames: 3,
        seed,
        ..SequenceConfig::for_scene(SceneKind::Road)
    };
    let a = Sequence::builtin(SceneKind::Road, config(5)).unwrap();
    let b = Sequence::builtin(SceneKind::Road, config(5)).unwrap();
    let c = Sequence::builtin(SceneKind::Road, config(6)).unwrap();
    assert_eq!(a.frame(2).unwrap(), a.frame(2).unwrap());
    assert_eq!(a.frame(2).unwrap(), b.frame(2).unwrap());
    // Random access and iteration agree.
    assert_eq!(a.iter().nth(2).unwrap(), b.frame(2).unwrap());
    assert_ne!(images(&a, 2).0, images(&c, 2).0);
    // Left and right differ (different cameras, independent noise).
    let (l, r) = images(&a, 1);
    assert_ne!(l, r);
}

/// A rendered rectangle has the area, centroid and per-row extent that the pinhole projection
/// of its corners gives, to a few hundredths of a pixel: the verge downstream needs 0.1 px
/// (0.01° at fx = 600), so the renderer must be far better than that.
fn check_plate_geometry(interlaced: bool) {
    let mut scene = Scene::empty(1, 0.0);
    let (x, y, z) = ([-0.45, 0.62], [-0.38, 0.29], 4.0);
    scene.add_box(plate(x, y, z, 1.0));
    let config = SequenceConfig {
        interlaced,
        ..still_config(240, 180)
    };
    let seq = Sequence::new(scene, config).unwrap();
    for frame in [1usize, 2, 3] {
        let truth = seq.truth(frame).unwrap();
        let ks = seq.frame_intrinsics(frame);
        let centers = head_centers();
        let alphas = [truth.alpha_l_deg, truth.alpha_r_deg];
        let poses = seq.camera_poses(frame).unwrap();
        let (l, r) = images(&seq, frame);
        for (side, img) in [l, r].iter().enumerate() {
            let corners: Vec<[f64; 2]> = [(0, 0), (1, 0), (1, 1), (0, 1)]
                .iter()
                .map(|&(i, j)| {
                    let p = Vector3::new(x[i], y[j], z);
                    let uv = project(&ks[side], centers[side], &truth, alphas[side], p);
                    let lib = poses[side].project(&p).unwrap();
                    assert!((uv[0] - lib[0]).abs() < 1e-9 && (uv[1] - lib[1]).abs() < 1e-9);
                    uv
                })
                .collect();
            let full = f64::from(img.pixels().map(|p| p.0[0]).max().unwrap());
            assert!(full > 150.0, "the plate is bright");
            let (area, centroid) = image_area_centroid(img, full);
            let (want_area, want_centroid) = polygon_area_centroid(&corners);
            let ctx = format!("frame {frame} side {side} interlaced {interlaced}");
            // A field samples every other frame row, so its area and vertical centroid depend on
            // which rows the top and bottom edges fall in: only frames are checked for those.
            if !interlaced {
                assert!(
                    (area - want_area).abs() < 0.002 * want_area,
                    "{ctx}: area {area} vs {want_area}"
                );
                for a in 0..2 {
                    assert!(
                        (centroid[a] - want_centroid[a]).abs() < 0.02,
                        "{ctx}: centroid {centroid:?} vs {want_centroid:?}"
                    );
                }
            }
            // Per row: the coverage sum is the plate's width at the row centre and the partial
            // pixel on the left gives the left edge (the edges are straight, so their average
            // over the row's height is their value at its middle).
            let v_mid = want_centroid[1].round() as u32;
            for v in v_mid - 5..=v_mid + 5 {
                let row: Vec<f64> = (0..img.width())
                    .map(|u| f64::from(img.get_pixel(u, v).0[0]) / full)
                    .collect();
                let sum: f64 = row.iter().sum();
                let at = |a: [f64; 2], b: [f64; 2]| {
                    a[0] + (b[0] - a[0]) * (f64::from(v) - a[1]) / (b[1] - a[1])
                };
                // Corners: 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left.
                let left = at(corners[0], corners[3]);
                let width = at(corners[1], corners[2]) - left;
                assert!(
                    (sum - width).abs() < 0.03,
                    "{ctx} row {v}: {sum} vs {width}"
                );
                let first = row.iter().position(|&c| c > 0.0).unwrap();
                let edge = first as f64 + 0.5 - row[first];
                assert!(
                    (edge - left).abs() < 0.02,
                    "{ctx} row {v}: left edge {edge} vs {left}"
                );
            }
        }
    }
}

#[test]
fn rendered_plate_matches_pinhole_projection() {
    check_plate_geometry(false);
}

#[test]
fn interlaced_fields_match_field_intrinsics() {
    check_plate_geometry(true);
    let seq = Sequence::new(
        Scene::empty(1, 0.0),
        SequenceConfig {
            interlaced: true,
            ..still_config(64, 48)
        },
    )
    .unwrap();
    assert_eq!(seq.image_size(), (64, 24));
    let [even, _] = seq.frame_intrinsics(0);
    let [odd, _] = seq.frame_intrinsics(1);
    assert_eq!(seq.frame(1).unwrap().field_parity, Some(1));
    assert!((even.cy - odd.cy - 0.5).abs() < 1e-12);
    assert!((even.fy * 2.0 - seq.frame_intrinsics(0)[0].fx).abs() < 1e-12);
}

#[test]
fn toe_in_moves_far_points_left_in_left_and_right_in_right() {
    // A plate 500 m ahead: all but pure rotation.
    let (x, y, z) = ([-5.0, 5.0], [-5.0, 5.0], 500.0);
    let mut scene = Scene::empty(2, 0.0);
    scene.add_box(plate(x, y, z, 1.0));
    let seq = Sequence::new(scene, still_config(320, 120)).unwrap();
    let truth = seq.truth(3).unwrap();
    assert!((truth.verge_deg - 10.0).abs() < 1e-9 && (truth.alpha_l_deg - 7.0).abs() < 1e-9);
    let ks = seq.frame_intrinsics(3);
    let (l, r) = images(&seq, 3);
    let alphas = [truth.alpha_l_deg, truth.alpha_r_deg];
    let mut centroids = Vec::new();
    for (side, img) in [l, r].iter().enumerate() {
        let full = f64::from(img.pixels().map(|p| p.0[0]).max().unwrap());
        let (_, got) = image_area_centroid(img, full);
        let corners: Vec<[f64; 2]> = [(0, 0), (1, 0), (1, 1), (0, 1)]
            .iter()
            .map(|&(i, j)| {
                project(
                    &ks[side],
                    head_centers()[side],
                    &truth,
                    alphas[side],
                    Vector3::new(x[i], y[j], z),
                )
            })
            .collect();
        let (_, want) = polygon_area_centroid(&corners);
        assert!(
            (got[0] - want[0]).abs() < 0.05,
            "side {side}: {got:?} vs {want:?}"
        );
        // The head is tilted 3° down: a point ahead at eye height appears above the centre.
        let above = ks[side].cy - 0.9 * ks[side].fy * 3f64.to_radians().tan();
        assert!(got[1] < above, "side {side}: {got:?}");
        centroids.push(got[0] - ks[side].cx);
    }
    // alpha_l = +7°: the left camera looks right of the point, which appears left of centre;
    // alpha_r = -3°: the right camera looks left of it, it appears right of centre.
    let fx = ks[0].fx;
    assert!(
        centroids[0] < -0.9 * fx * 7f64.to_radians().tan(),
        "{centroids:?}"
    );
    assert!(
        centroids[1] > 0.9 * ks[1].fx * 3f64.to_radians().tan(),
        "{centroids:?}"
    );
}

#[test]
fn nearest_surface_wins_whatever_the_order() {
    let near = plate([-0.3, 0.3], [-0.3, 0.3], 2.0, 0.3);
    let far = plate([-2.0, 2.0], [-2.0, 2.0], 6.0, 0.9);
    let build = |boxes: [SceneBox; 2]| {
        let mut scene = Scene::empty(3, 0.0);
        for b in boxes {
            scene.add_box(b);
        }
        let seq = Sequence::new(scene, still_config(96, 64)).unwrap();
        images(&seq, 0).0
    };
    let a = build([near, far]);
    let b = build([far, near]);
    assert_eq!(a, b);
    let k = Sequence::new(Scene::empty(3, 0.0), still_config(96, 64))
        .unwrap()
        .frame_intrinsics(0)[0];
    // Frame 0: no yaw, 3° tilt. The near plate covers the principal point...
    let centre = a.get_pixel(k.cx.round() as u32, k.cy.round() as u32).0[0];
    // ...and the far plate shows beside it (x = 1 m at 6 m depth, pixel ≈ cx + 100·k.fx/600).
    let side = a
        .get_pixel((k.cx + k.fx / 6.0).round() as u32, k.cy.round() as u32)
        .0[0];
    let shade = f64::from(side) / 0.9;
    assert!(
        (f64::from(centre) - 0.3 * shade).abs() <= 1.0,
        "near plate: {centre}"
    );
    assert!(side > 150, "far plate: {side}");
}

/// Mean absolute horizontal difference (grey levels) of a noise-free image.
fn texture_energy(img: &GrayImage) -> f64 {
    let mut sum = 0.0;
    let mut n = 0.0;
    for y in 0..img.height() {
        for x in 1..img.width() {
            sum += (f64::from(img.get_pixel(x, y).0[0]) - f64::from(img.get_pixel(x - 1, y).0[0]))
                .abs();
            n += 1.0;
        }
    }
    sum / n
}

/// Band energy at octave `k`: the image box-averaged down by 2^k, then the mean absolute
/// difference between neighbours, i.e. the structure a DoG at that octave can see.
fn octave_energy(img: &GrayImage, k: u32) -> f64 {
    let s = 1u32 << k;
    let (w, h) = (img.width() / s, img.height() / s);
    let small = GrayImage::from_fn(w, h, |x, y| {
        let mut acc = 0u32;
        for dy in 0..s {
            for dx in 0..s {
                acc += u32::from(img.get_pixel(x * s + dx, y * s + dy).0[0]);
            }
        }
        image::Luma([(acc / (s * s)) as u8])
    });
    texture_energy(&small)
}

fn noise_free(kind: SceneKind, width: u32, height: u32) -> SequenceConfig {
    SequenceConfig {
        width,
        height,
        frames: 2,
        noise_sigma: 0.0,
        ..SequenceConfig::for_scene(kind)
    }
}

#[test]
fn road_has_structure_at_four_octaves_and_sparse_has_almost_none() {
    let road = Sequence::builtin(SceneKind::Road, noise_free(SceneKind::Road, 320, 240)).unwrap();
    let lab = Sequence::builtin(SceneKind::Lab, noise_free(SceneKind::Lab, 320, 240)).unwrap();
    let sparse =
        Sequence::builtin(SceneKind::Sparse, noise_free(SceneKind::Sparse, 320, 240)).unwrap();
    let (road_l, _) = images(&road, 1);
    let (lab_l, _) = images(&lab, 1);
    let (sparse_l, _) = images(&sparse, 1);
    for k in 0..4 {
        let (r, l) = (octave_energy(&road_l, k), octave_energy(&lab_l, k));
        assert!(r > 1.5 && l > 1.5, "octave {k}: road {r:.2}, lab {l:.2}");
    }
    let s = texture_energy(&sparse_l);
    assert!(s < 0.3, "sparse scene has texture energy {s}");
    let mean = sparse_l.pixels().map(|p| f64::from(p.0[0])).sum::<f64>() / f64::from(320 * 240);
    let spread = sparse_l
        .pixels()
        .map(|p| (f64::from(p.0[0]) - mean).abs())
        .fold(0.0, f64::max);
    assert!(
        spread < 30.0,
        "sparse: one wall and one floor, no objects (spread {spread})"
    );
}

#[test]
fn dropped_frames_have_no_images_and_keep_their_truth() {
    let config = SequenceConfig {
        width: 32,
        height: 24,
        frames: 40,
        drop_rate: 0.3,
        seed: 11,
        ..SequenceConfig::for_scene(SceneKind::Sparse)
    };
    let seq = Sequence::builtin(SceneKind::Sparse, config).unwrap();
    let dropped: Vec<usize> = (0..seq.len()).filter(|&i| seq.is_dropped(i)).collect();
    assert!(!dropped.is_empty() && dropped.len() < 25, "{dropped:?}");
    for &i in &dropped {
        let f = seq.frame(i).unwrap();
        assert!(f.dropped() && f.images.is_none());
        assert_eq!(f.truth, seq.truth(i).unwrap());
    }
    assert!(!seq
        .frame((0..40).find(|i| !dropped.contains(i)).unwrap())
        .unwrap()
        .dropped());
}

#[test]
fn writes_images_calibration_and_truth() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("seq");
    let config = SequenceConfig {
        width: 48,
        height: 32,
        frames: 12,
        drop_rate: 0.25,
        seed: 4,
        ..SequenceConfig::for_scene(SceneKind::Lab)
    };
    let seq = Sequence::builtin(SceneKind::Lab, config).unwrap();
    seq.write_sequence(&out).unwrap();
    let kept: Vec<usize> = (0..12).filter(|&i| !seq.is_dropped(i)).collect();
    for dir in ["left", "right"] {
        let mut names: Vec<String> = std::fs::read_dir(out.join(dir))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let want: Vec<String> = kept.iter().map(|i| format!("{i:06}.png")).collect();
        assert_eq!(names, want);
    }
    let img = image::open(out.join("left").join(format!("{:06}.png", kept[0]))).unwrap();
    assert_eq!(img.color(), image::ColorType::L8);
    assert_eq!(
        img.to_luma8(),
        seq.frame(kept[0]).unwrap().images.unwrap().left
    );

    let calib: toml::Table = std::fs::read_to_string(out.join("calib.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let mut keys: Vec<&str> = calib.keys().map(String::as_str).collect();
    keys.sort();
    assert_eq!(keys, ["baseline_m", "left", "right"]);
    assert_eq!(calib["baseline_m"].as_float(), Some(0.3));
    let ks = seq.intrinsics();
    for (name, k) in [("left", ks[0]), ("right", ks[1])] {
        let t = calib[name].as_table().unwrap();
        let mut keys: Vec<&str> = t.keys().map(String::as_str).collect();
        keys.sort();
        assert_eq!(keys, ["cx", "cy", "fx", "fy"]);
        assert_eq!(t["fx"].as_float(), Some(k.fx));
        assert_eq!(t["cy"].as_float(), Some(k.cy));
    }

    let truth = std::fs::read_to_string(out.join("truth.csv")).unwrap();
    let lines: Vec<&str> = truth.lines().collect();
    assert_eq!(lines[0], "frame,verge_deg");
    assert_eq!(lines.len(), 13);
    let (frame, verge) = lines[5].split_once(',').unwrap();
    assert_eq!(frame, "4");
    assert!((verge.parse::<f64>().unwrap() - seq.truth(4).unwrap().verge_deg).abs() < 1e-8);

    // A second write into the now non-empty directory is refused, and nothing is left over.
    assert!(matches!(
        seq.write_sequence(&out),
        Err(SynthError::OutputNotEmpty(_))
    ));
    let entries = std::fs::read_dir(tmp.path()).unwrap().count();
    assert_eq!(entries, 1, "no staging directory left behind");
}

#[test]
fn bad_configs_are_named_errors() {
    let base = SequenceConfig::for_scene(SceneKind::Sparse);
    let field = |c: SequenceConfig| match Sequence::builtin(SceneKind::Sparse, c) {
        Err(SynthError::InvalidConfig { field, .. }) => field,
        other => panic!("expected InvalidConfig, got {other:?}"),
    };
    assert_eq!(
        field(SequenceConfig {
            width: 0,
            ..base.clone()
        }),
        "width"
    );
    assert_eq!(
        field(SequenceConfig {
            fps: f64::NAN,
            ..base.clone()
        }),
        "fps"
    );
    assert_eq!(
        field(SequenceConfig {
            height: 481,
            interlaced: true,
            ..base.clone()
        }),
        "height"
    );
    assert_eq!(
        field(SequenceConfig {
            drop_rate: 1.0,
            ..base.clone()
        }),
        "drop_rate"
    );
    assert_eq!(
        field(SequenceConfig {
            supersampling: Supersampling::Uniform { per_axis: 0 },
            ..base.clone()
        }),
        "supersampling"
    );
    let seq = Sequence::builtin(
        SceneKind::Sparse,
        SequenceConfig {
            frames: 3,
            width: 16,
            height: 16,
            ..base.clone()
        },
    )
    .unwrap();
    assert!(matches!(
        seq.frame(3),
        Err(SynthError::FrameOutOfRange { index: 3, len: 3 })
    ));
    // The street ends: a sequence driving past it is refused, not rendered into emptiness.
    let road = SequenceConfig {
        frames: 100_000,
        ..SequenceConfig::for_scene(SceneKind::Road)
    };
    assert!(matches!(
        Sequence::builtin(SceneKind::Road, road),
        Err(SynthError::OutsideScene { .. })
    ));
    assert!(matches!(
        "moon".parse::<SceneKind>(),
        Err(SynthError::UnknownScene(_))
    ));
}
