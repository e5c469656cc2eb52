//! The built-in worlds: where the boxes of the `road`, `lab` and `sparse` scenes go.
//!
//! The road is laid out across x like a two-lane city street (the head drives in the lane
//! around x = 0 toward +z); the furniture along z is drawn from the scene's seeded RNG.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::scene::{cell, Material, Pattern, Scene, SceneBox, Sky, Surface, TextureKind};

/// Start and end of the furnished street (m). 2 km is 200 s at the default 10 m/s.
pub(crate) const ROAD_Z: [f64; 2] = [-40.0, 2000.0];
/// Furniture continues past the end so the view ahead is never empty.
const ROAD_FURNISH_BEYOND_M: f64 = 500.0;

// Street cross-section (x, metres): lanes, parking strips, sidewalks, façade lines.
const LANE_RIGHT: f64 = 1.75;
const LANE_CENTRE: f64 = -1.75;
const LANE_LEFT: f64 = -5.25;
const PARKING_RIGHT: f64 = 4.0;
const PARKING_LEFT: f64 = -7.5;
const SIDEWALK_RIGHT: f64 = 7.0;
const SIDEWALK_LEFT: f64 = -10.5;

fn surface(texture: TextureKind, metres_per_texel: f64, mean: f32, contrast: f32) -> Surface {
    Surface {
        texture,
        metres_per_texel,
        offset: [0.0, 0.0],
        mean,
        contrast,
        macro_contrast: 0.0,
        pattern: Pattern::None,
    }
}

/// A surface with a random texture offset and macro variation, so no two objects look alike.
fn varied(mut s: Surface, rng: &mut ChaCha8Rng) -> Material {
    s.offset = [rng.random_range(0.0..1000.0), rng.random_range(0.0..1000.0)];
    s.macro_contrast = s.contrast * 0.5;
    Material::Surface(s)
}

fn push_box(scene: &mut Scene, [min, max]: [[f64; 3]; 2], material: Material) {
    scene.add_box(SceneBox { min, max, material });
}

/// The street scene of thesis 5.1.2.
pub(crate) fn road(scene: &mut Scene, rng: &mut ChaCha8Rng) {
    scene.ground = Some(Material::Road);
    scene.sky = Sky::default();
    scene.extent_z = ROAD_Z;
    let z_end = ROAD_Z[1] + ROAD_FURNISH_BEYOND_M;
    for side in [1.0f64, -1.0] {
        let facade_x = if side > 0.0 {
            SIDEWALK_RIGHT
        } else {
            -SIDEWALK_LEFT
        };
        // Façades with windows; sometimes a gap shows the sky or a far building.
        let mut z = ROAD_Z[0] - 20.0;
        while z < z_end {
            let width = rng.random_range(8.0..30.0);
            if rng.random_bool(0.2) {
                let far = facade_x + rng.random_range(25.0..60.0);
                let h = rng.random_range(10.0..35.0);
                let s = surface(TextureKind::Fractal, 0.04, rng.random_range(0.4..0.7), 0.06);
                let m = varied(s, rng);
                push_box(scene, x_box(side, far, far + 15.0, -h, z, z + width), m);
            } else {
                let setback = rng.random_range(0.0..2.0);
                let h = rng.random_range(6.0..22.0);
                let mut s = surface(
                    TextureKind::Fractal,
                    0.02,
                    rng.random_range(0.4..0.78),
                    0.07,
                );
                s.pattern = Pattern::Windows {
                    spacing: [rng.random_range(2.6..3.6), rng.random_range(3.0..3.6)],
                    size: [rng.random_range(1.1..1.6), rng.random_range(1.3..1.9)],
                    glass: rng.random_range(0.08..0.2),
                };
                let x0 = facade_x + setback;
                let m = varied(s, rng);
                push_box(scene, x_box(side, x0, x0 + 12.0, -h, z, z + width), m);
            }
            z += width
                + if rng.random_bool(0.15) {
                    rng.random_range(3.0..12.0)
                } else {
                    0.0
                };
        }
        // Trees on the sidewalk.
        let tree_x = if side > 0.0 {
            5.6
        } else {
            -SIDEWALK_LEFT - 1.6
        };
        let mut z = ROAD_Z[0] + rng.random_range(0.0..10.0);
        while z < z_end {
            let bark = surface(TextureKind::Rough, 0.004, rng.random_range(0.2..0.35), 0.08);
            let m = varied(bark, rng);
            let trunk_h = rng.random_range(2.2..3.2);
            push_box(
                scene,
                x_box(
                    side,
                    tree_x - 0.17,
                    tree_x + 0.17,
                    -trunk_h,
                    z - 0.17,
                    z + 0.17,
                ),
                m,
            );
            let r = rng.random_range(1.0..1.9);
            let leaves = surface(TextureKind::Rough, 0.01, rng.random_range(0.22..0.42), 0.16);
            let m = varied(leaves, rng);
            let top = -trunk_h - rng.random_range(2.0..4.0);
            // The crown's bottom hangs a little below the trunk's top.
            let mut crown = x_box(side, tree_x - r, tree_x + r, top, z - r, z + r);
            crown[1][1] = -trunk_h + 0.4;
            push_box(scene, crown, m);
            z += rng.random_range(9.0..26.0);
        }
        // Lamp poles at the kerb, arm over the parking strip.
        let pole_x = if side > 0.0 {
            PARKING_RIGHT + 0.3
        } else {
            -PARKING_LEFT + 0.3
        };
        let mut z = ROAD_Z[0] + rng.random_range(0.0..20.0);
        while z < z_end {
            let metal = surface(TextureKind::Smooth, 0.01, rng.random_range(0.45..0.6), 0.05);
            let m = varied(metal, rng);
            push_box(
                scene,
                x_box(side, pole_x - 0.07, pole_x + 0.07, -7.0, z - 0.07, z + 0.07),
                m,
            );
            push_box(
                scene,
                x_box(side, pole_x - 1.5, pole_x, -7.1, z - 0.06, z + 0.06),
                m,
            );
            z += rng.random_range(25.0..40.0);
        }
        // Parked vehicles.
        let (car_x0, car_x1) = if side > 0.0 {
            (2.0, 3.8)
        } else {
            (-PARKING_LEFT - 1.8 - 0.2, -PARKING_LEFT - 0.2)
        };
        let mut z = ROAD_Z[0] + rng.random_range(0.0..6.0);
        while z < z_end {
            let len = rng.random_range(3.8..4.9);
            if rng.random_bool(0.7) {
                let paint = surface(
                    TextureKind::Fractal,
                    0.004,
                    rng.random_range(0.15..0.85),
                    0.05,
                );
                let m = varied(paint, rng);
                // The body floats 15 cm above the road: wheels are not modelled.
                let mut body = x_box(side, car_x0, car_x1, -1.05, z, z + len);
                body[1][1] = -0.15;
                push_box(scene, body, m);
                let glass = surface(TextureKind::Fractal, 0.01, rng.random_range(0.1..0.3), 0.05);
                let m = varied(glass, rng);
                push_box(
                    scene,
                    x_box(
                        side,
                        car_x0 + 0.1,
                        car_x1 - 0.1,
                        -1.5,
                        z + 1.0,
                        z + len - 0.8,
                    ),
                    m,
                );
            }
            z += len + rng.random_range(0.8..6.0);
        }
    }
}

/// A box between `x0..x1` on the right side (`side` = 1) or its mirror image on the left.
fn x_box(side: f64, x0: f64, x1: f64, top: f64, z0: f64, z1: f64) -> [[f64; 3]; 2] {
    let (a, b) = if side > 0.0 { (x0, x1) } else { (-x1, -x0) };
    [[a, top, z0], [b, 0.0, z1]]
}

/// The street surface at ground point (x, z).
/// Returns the intensity and the region (lane 0, marking 1, parking 2, sidewalk 3 or 4 on a
/// seam, verge 5): region changes are intensity steps the renderer supersamples.
pub(crate) fn shade_road(scene: &Scene, uv: [f64; 2], footprint_m: f64) -> (f32, u32) {
    let [x, z] = uv;
    const ASPHALT: Surface = Surface {
        texture: TextureKind::Fractal,
        metres_per_texel: 0.008,
        offset: [0.0, 0.0],
        mean: 0.33,
        contrast: 0.06,
        macro_contrast: 0.03,
        pattern: Pattern::None,
    };
    let marking = |scene: &Scene| {
        let (asphalt, _) = scene.shade_surface(&ASPHALT, uv, footprint_m, false);
        (0.82 + 0.03 * (asphalt - 0.33), 1)
    };
    if (LANE_LEFT..LANE_RIGHT).contains(&x) {
        // Edge lines, dashed centre line, zebra crossings every 150 m.
        let edge = (x - (LANE_RIGHT - 0.2)).abs() < 0.075 || (x - (LANE_LEFT + 0.2)).abs() < 0.075;
        let (_, dash) = cell(z, 9.0);
        let centre = (x - LANE_CENTRE).abs() < 0.06 && dash < 3.0;
        let (_, zebra_z) = cell(z - 60.0, 150.0);
        let (_, stripe) = cell(x, 1.0);
        let zebra =
            zebra_z < 4.0 && stripe < 0.5 && (LANE_LEFT + 0.5..LANE_RIGHT - 0.5).contains(&x);
        if edge || centre || zebra {
            return marking(scene);
        }
        return scene.shade_surface(&ASPHALT, uv, footprint_m, false);
    }
    if (PARKING_LEFT..PARKING_RIGHT).contains(&x) {
        let mut s = ASPHALT;
        s.mean = 0.29;
        s.offset = [311.0, 17.0];
        return (scene.shade_surface(&s, uv, footprint_m, false).0, 2);
    }
    if (SIDEWALK_LEFT..SIDEWALK_RIGHT).contains(&x) {
        let s = Surface {
            texture: TextureKind::Fractal,
            metres_per_texel: 0.01,
            offset: [53.0, 101.0],
            mean: 0.55,
            contrast: 0.06,
            macro_contrast: 0.04,
            pattern: Pattern::Paving {
                tile_m: 0.5,
                seam_m: 0.02,
            },
        };
        let (value, seam) = scene.shade_surface(&s, uv, footprint_m, false);
        return (value, 3 + seam);
    }
    let gravel = Surface {
        texture: TextureKind::Rough,
        metres_per_texel: 0.02,
        offset: [7.0, 5.0],
        mean: 0.4,
        contrast: 0.1,
        macro_contrast: 0.06,
        pattern: Pattern::None,
    };
    (scene.shade_surface(&gravel, uv, footprint_m, false).0, 5)
}

/// The lab of thesis 5.1.1: a closed room with textured furniture 1-5 m from the head.
pub(crate) fn lab(scene: &mut Scene, rng: &mut ChaCha8Rng) {
    scene.ground = Some(varied(surface(TextureKind::Rough, 0.008, 0.42, 0.07), rng));
    scene.extent_z = [-1.0, 1.0];
    let wall = |rng: &mut ChaCha8Rng| {
        varied(
            surface(
                TextureKind::Fractal,
                0.01,
                rng.random_range(0.55..0.7),
                0.05,
            ),
            rng,
        )
    };
    // Walls, ceiling (y = -3 m).
    let m = wall(rng);
    push_box(scene, [[-3.2, -3.0, -2.0], [-3.0, 0.0, 6.5]], m);
    let m = wall(rng);
    push_box(scene, [[3.0, -3.0, -2.0], [3.2, 0.0, 6.5]], m);
    let m = wall(rng);
    push_box(scene, [[-3.2, -3.0, 6.0], [3.2, 0.0, 6.2]], m);
    let m = wall(rng);
    push_box(scene, [[-3.2, -3.0, -2.2], [3.2, 0.0, -2.0]], m);
    let m = wall(rng);
    push_box(scene, [[-3.2, -3.2, -2.2], [3.2, -3.0, 6.2]], m);
    // Posters on the walls: high-contrast prints a few millimetres proud of the wall.
    for _ in 0..10 {
        let (w, h) = (rng.random_range(0.5..1.4), rng.random_range(0.5..1.2));
        let y0 = rng.random_range(-2.6..-1.0 - h * 0.5);
        let kind = [
            TextureKind::Fractal,
            TextureKind::Rough,
            TextureKind::Smooth,
        ][rng.random_range(0..3)];
        let m = varied(surface(kind, rng.random_range(0.002..0.006), 0.5, 0.2), rng);
        match rng.random_range(0..3) {
            0 => {
                let x0 = rng.random_range(-2.8..2.8 - w);
                push_box(scene, [[x0, y0, 5.99], [x0 + w, y0 + h, 6.0]], m);
            }
            1 => {
                let z0 = rng.random_range(0.5..5.5 - w);
                push_box(scene, [[-3.0, y0, z0], [-2.99, y0 + h, z0 + w]], m);
            }
            _ => {
                let z0 = rng.random_range(0.5..5.5 - w);
                push_box(scene, [[2.99, y0, z0], [3.0, y0 + h, z0 + w]], m);
            }
        }
    }
    // A table with things on it, and boxes on the floor.
    let wood = varied(surface(TextureKind::Fractal, 0.004, 0.5, 0.12), rng);
    push_box(scene, [[-0.8, -0.78, 1.8], [0.8, -0.74, 2.6]], wood);
    for (x, z) in [(-0.75, 1.85), (0.71, 1.85), (-0.75, 2.51), (0.71, 2.51)] {
        push_box(scene, [[x, -0.74, z], [x + 0.04, 0.0, z + 0.04]], wood);
    }
    for _ in 0..5 {
        let s = rng.random_range(0.08..0.3);
        let x0 = rng.random_range(-0.75..0.75 - s);
        let z0 = rng.random_range(1.85..2.55 - s);
        let m = varied(
            surface(
                TextureKind::Fractal,
                0.002,
                rng.random_range(0.3..0.8),
                0.18,
            ),
            rng,
        );
        push_box(
            scene,
            [
                [x0, -0.78 - s * rng.random_range(0.5..1.5), z0],
                [x0 + s, -0.78, z0 + s],
            ],
            m,
        );
    }
    for _ in 0..12 {
        let s = rng.random_range(0.25..0.9);
        let z0 = rng.random_range(1.0..5.0);
        let x0 = rng.random_range(-2.9..2.9 - s);
        if (-1.0..1.0).contains(&x0) && (1.5..2.8).contains(&z0) {
            continue;
        }
        let kind = [TextureKind::Fractal, TextureKind::Rough][rng.random_range(0..2)];
        let m = varied(
            surface(
                kind,
                0.004,
                rng.random_range(0.25..0.8),
                rng.random_range(0.1..0.22),
            ),
            rng,
        );
        push_box(
            scene,
            [
                [x0, -s * rng.random_range(0.6..2.2), z0],
                [x0 + s, 0.0, z0 + s],
            ],
            m,
        );
    }
}

/// A nearly uniform wall 6 m ahead and a floor, both at about one grey level of contrast.
pub(crate) fn sparse(scene: &mut Scene) {
    let plain = |mean: f32, offset: f64| {
        Material::Surface(Surface {
            texture: TextureKind::Smooth,
            metres_per_texel: 0.05,
            offset: [offset, offset],
            mean,
            contrast: 0.003,
            macro_contrast: 0.002,
            pattern: Pattern::None,
        })
    };
    scene.ground = Some(plain(0.5, 0.0));
    scene.extent_z = [-1.0, 1.0];
    push_box(
        scene,
        [[-200.0, -200.0, 6.0], [200.0, 0.0, 6.5]],
        plain(0.56, 300.0),
    );
}
