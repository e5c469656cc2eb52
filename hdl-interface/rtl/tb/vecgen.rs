//! Test vectors for sc_extrema, sc_edge, sc_refine, sc_sobel and sc_cordic from the Rust
//! model. Built and run by `hdl-interface/rtl/tb/run.sh` outside the workspace (it is not a
//! workspace member): `vecgen <outdir> <random-count> [seed]` writes extrema.hex, edge.hex,
//! refine.hex, sobel.hex, cordic.hex (one record per line, most significant field first; the
//! layouts are in tb_comb.v and tb_cordic.v) and prints what it wrote.

use std::fmt::Write as _;
use std::fs;

use stereocal_firmware::fabric::cordic::CordicPipeline;
use stereocal_firmware::fabric::edge::passes_edge_test;
use stereocal_firmware::fabric::extrema::{is_extremum, Cube};
use stereocal_firmware::fabric::refine::refine;
use stereocal_firmware::fabric::sobel::sobel;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + self.below((hi - lo + 1) as u64) as i64
    }
    fn i16(&mut self) -> i16 {
        self.next() as i16
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 > 1.0 - p
    }
}

/// A cube of a random "family" (edge cases weighted in).
fn gen_cube(r: &mut Rng) -> Cube {
    let mut c: Cube = [[[0; 3]; 3]; 3];
    let fam = r.below(10);
    let lim: i64 = [1, 3, 16, 200, 4000, 32768][r.below(6) as usize];
    for (i, v) in c.iter_mut().flatten().flatten().enumerate() {
        let (s, y, x) = (i / 9, i / 3 % 3, i % 3);
        *v = match fam {
            0 | 1 => r.i16(),
            2 => [-32768, 32767][r.below(2) as usize],
            3 => [-32768, 32767, 0, -1, 1, -32767][r.below(6) as usize],
            // Extreme centre and faces, edges from {-32768, 0, 32767}, corners random: the
            // largest Hessians, cofactors and determinants.
            4 => match (s == 1) as u8 + (y == 1) as u8 + (x == 1) as u8 {
                3 | 2 => [-32768, 32767][r.below(2) as usize],
                1 => [-32768, 0, 32767][r.below(3) as usize],
                _ => r.i16(),
            },
            _ => r.range(-lim, (lim - 1).min(32767)) as i16,
        };
    }
    match r.below(8) {
        // Centre a strict max / min of the cube.
        0 | 1 => {
            let mut m = c.iter().flatten().flatten().copied().max().unwrap();
            if m == i16::MAX {
                for v in c.iter_mut().flatten().flatten() {
                    *v = (*v).min(32766);
                }
                m = 32766;
            }
            c[1][1][1] = m + 1;
        }
        2 => {
            let mut m = c.iter().flatten().flatten().copied().min().unwrap();
            if m == i16::MIN {
                for v in c.iter_mut().flatten().flatten() {
                    *v = (*v).max(-32767);
                }
                m = -32767;
            }
            c[1][1][1] = m - 1;
        }
        // Plateau: a neighbour equal to the centre.
        3 => {
            let v = c[1][1][1];
            let (s, y, x) = (
                r.below(3) as usize,
                r.below(3) as usize,
                r.below(3) as usize,
            );
            c[s][y][x] = v;
        }
        // Degenerate: separable in one axis only (det 0) or all equal.
        4 => {
            let axis = r.below(4);
            for s in 0..3 {
                for y in 0..3 {
                    for x in 0..3 {
                        let k = match axis {
                            0 => x,
                            1 => y,
                            2 => s,
                            _ => 1,
                        };
                        c[s][y][x] = c[1][1][k];
                    }
                }
            }
        }
        _ => {}
    }
    c
}

fn gen_threshold(r: &mut Rng, c: &Cube) -> u16 {
    let v = c[1][1][1] as i32;
    match r.below(6) {
        0 => r.next() as u16,
        1 => [0u16, 1, 32767, 32768, 65535][r.below(5) as usize],
        // Around |v|: v == t, v == t + 1, v == -t.
        _ => (v.abs() + r.range(-2, 1) as i32).clamp(0, 65535) as u16,
    }
}

fn hex_cube(s: &mut String, c: &Cube) {
    // Element (s,y,x) at bits ((s*3+y)*3+x)*16: most significant = (2,2,2).
    for i in (0..27).rev() {
        let v = c[i / 9][(i / 3) % 3][i % 3] as u16;
        write!(s, "{v:04x}").unwrap();
    }
}

fn hex_plane(s: &mut String, d: &[[i16; 3]; 3]) {
    for i in (0..9).rev() {
        write!(s, "{:04x}", d[i / 3][i % 3] as u16).unwrap();
    }
}

/// Exact raw quotients (no rejection), for biasing the selection only; `None` if det == 0.
fn raw_q(c: &Cube) -> Option<([i128; 3], [bool; 3])> {
    let v = |s: usize, y: usize, x: usize| c[s][y][x] as i128;
    let c0 = v(1, 1, 1);
    let g2 = [
        v(1, 1, 2) - v(1, 1, 0),
        v(1, 2, 1) - v(1, 0, 1),
        v(2, 1, 1) - v(0, 1, 1),
    ];
    let hxx = 4 * (v(1, 1, 2) + v(1, 1, 0) - 2 * c0);
    let hyy = 4 * (v(1, 2, 1) + v(1, 0, 1) - 2 * c0);
    let hss = 4 * (v(2, 1, 1) + v(0, 1, 1) - 2 * c0);
    let hxy = v(1, 2, 2) - v(1, 2, 0) - v(1, 0, 2) + v(1, 0, 0);
    let hxs = v(2, 1, 2) - v(2, 1, 0) - v(0, 1, 2) + v(0, 1, 0);
    let hys = v(2, 2, 1) - v(2, 0, 1) - v(0, 2, 1) + v(0, 0, 1);
    let h = [[hxx, hxy, hxs], [hxy, hyy, hys], [hxs, hys, hss]];
    let a00 = h[1][1] * h[2][2] - h[1][2] * h[2][1];
    let a01 = h[0][2] * h[2][1] - h[0][1] * h[2][2];
    let a02 = h[0][1] * h[1][2] - h[0][2] * h[1][1];
    let a11 = h[0][0] * h[2][2] - h[0][2] * h[2][0];
    let a12 = h[0][2] * h[1][0] - h[0][0] * h[1][2];
    let a22 = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    let adj = [[a00, a01, a02], [a01, a11, a12], [a02, a12, a22]];
    let det = h[0][0] * a00 + h[0][1] * a01 + h[0][2] * a02;
    if det == 0 {
        return None;
    }
    let mut q = [0; 3];
    let mut tie = [false; 3];
    for i in 0..3 {
        let dot: i128 = (0..3).map(|j| adj[i][j] * g2[j]).sum();
        let num = -2 * dot * 8192;
        let (na, da) = (num.abs(), det.abs());
        tie[i] = 2 * (na % da) == da;
        let m = (na + da / 2) / da;
        q[i] = if (num < 0) != (det < 0) { -m } else { m };
    }
    Some((q, tie))
}

/// Cubes built to hit the rounding ties and the |q| = 32767 / 32768 boundary.
fn special_refine_cubes(r: &mut Rng, n_tie: usize, n_big: usize) -> Vec<Cube> {
    let (mut ties, mut bigs) = (Vec::new(), Vec::new());
    let mut tries = 0u64;
    while (ties.len() < n_tie || bigs.len() < n_big) && tries < 200_000_000 {
        tries += 1;
        let mut c: Cube = [[[0; 3]; 3]; 3];
        let lim = [2i64, 4, 8, 30][r.below(4) as usize];
        let sparse = r.chance(0.5);
        for v in c.iter_mut().flatten().flatten() {
            *v = if sparse && r.chance(0.6) {
                0
            } else {
                r.range(-lim, lim) as i16
            };
        }
        let Some((q, tie)) = raw_q(&c) else { continue };
        if ties.len() < n_tie && tie.iter().any(|&t| t) && q.iter().all(|q| q.abs() < 40000) {
            ties.push(c);
        } else if bigs.len() < n_big && q.iter().any(|q| (32760..=32776).contains(&q.abs())) {
            bigs.push(c);
        }
    }
    eprintln!(
        "refine specials: {} ties, {} near 2^15 ({} tries)",
        ties.len(),
        bigs.len(),
        tries
    );
    ties.extend(bigs);
    ties
}

fn refine_line(s: &mut String, c: &Cube, m: u16) -> bool {
    let res = refine(c, m);
    let (ok, o) = match res {
        Some(o) => (1, [o[0].to_bits(), o[1].to_bits(), o[2].to_bits()]),
        None => (0, [0, 0, 0]),
    };
    // {ds, dy, dx, ok(4), max_offset, cube}
    write!(
        s,
        "{:04x}{:04x}{:04x}{:x}{:04x}",
        o[2] as u16, o[1] as u16, o[0] as u16, ok, m
    )
    .unwrap();
    hex_cube(s, c);
    s.push('\n');
    ok == 1
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = &args[1];
    let n: usize = args[2].parse().unwrap();
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().unwrap());
    let mut r = Rng(seed);

    // ---- extrema: {is_ext(4), threshold, cube}
    let mut s = String::new();
    let (mut cnt, mut pos) = (0, 0);
    let mut ext_cubes = Vec::new();
    for _ in 0..n {
        let c = gen_cube(&mut r);
        let t = gen_threshold(&mut r, &c);
        let e = is_extremum(&c, t);
        if e && ext_cubes.len() < n / 4 {
            ext_cubes.push(c);
        }
        write!(s, "{:x}{t:04x}", e as u8).unwrap();
        hex_cube(&mut s, &c);
        s.push('\n');
        cnt += 1;
        pos += e as usize;
    }
    fs::write(format!("{dir}/extrema.hex"), &s).unwrap();
    println!("extrema {cnt} vectors, {pos} extrema");

    // ---- edge: {pass(4), ratio, d}
    let mut s = String::new();
    let (mut cnt, mut pos, mut eq) = (0, 0, 0);
    let mut emit = |s: &mut String, d: &[[i16; 3]; 3], ratio: u8| {
        let p = passes_edge_test(d, ratio);
        write!(s, "{:x}{ratio:02x}", p as u8).unwrap();
        hex_plane(s, d);
        s.push('\n');
        cnt += 1;
        pos += p as usize;
    };
    let edge_terms = |d: &[[i16; 3]; 3], r: i64| {
        let v = |y: usize, x: usize| d[y][x] as i64;
        let dxx4 = 4 * (v(1, 2) + v(1, 0) - 2 * v(1, 1));
        let dyy4 = 4 * (v(2, 1) + v(0, 1) - 2 * v(1, 1));
        let dxy4 = v(2, 2) - v(2, 0) - v(0, 2) + v(0, 0);
        let tr = dxx4 + dyy4;
        let det = dxx4 * dyy4 - dxy4 * dxy4;
        (tr * tr * r, (r + 1) * (r + 1) * det, det)
    };
    let mut k = 0;
    while k < n {
        let c = gen_cube(&mut r);
        let ratio = match r.below(4) {
            0 => r.next() as u8,
            1 => [0u8, 1, 10, 254, 255][r.below(5) as usize],
            _ => r.range(1, 20) as u8,
        };
        let mut d = c[r.below(3) as usize];
        if r.chance(0.05) {
            // Search a small plane on the boundary tr²r == (r+1)²det (the test must fail).
            let ratio = r.range(1, 12) as u8;
            for _ in 0..10_000 {
                for v in d.iter_mut().flatten() {
                    *v = r.range(-6, 6) as i16;
                }
                let (l, rh, det) = edge_terms(&d, ratio as i64);
                if det > 0 && (l - rh).abs() <= 1 {
                    eq += (l == rh) as usize;
                    break;
                }
            }
            emit(&mut s, &d, ratio);
        } else {
            emit(&mut s, &d, ratio);
        }
        k += 1;
    }
    // Extreme planes: every corner of {-32768, 32767}^9 (512), ratios 1, 10, 255 in turn.
    for m in 0..512u32 {
        let mut d = [[0i16; 3]; 3];
        for i in 0..9 {
            d[i / 3][i % 3] = if m >> i & 1 == 1 { 32767 } else { -32768 };
        }
        emit(&mut s, &d, [1u8, 10, 255][m as usize % 3]);
    }
    // Maximal positive det, tr == 0 and boundary cases.
    for d in [
        [[0, 32767, 0], [32767, -32768, 32767], [0, 32767, 0]],
        [[0, -32768, 0], [-32768, 32767, -32768], [0, -32768, 0]],
        [
            [32767, 32767, -32768],
            [32767, -32768, 32767],
            [-32768, 32767, 32767],
        ],
        [[0, 1, 0], [-1, 0, 1], [0, -1, 0]],
    ] {
        for ratio in [0u8, 1, 2, 10, 255] {
            emit(&mut s, &d, ratio);
        }
    }
    fs::write(format!("{dir}/edge.hex"), &s).unwrap();
    println!("edge {cnt} vectors, {pos} pass, {eq} exact-equality boundaries");

    // ---- refine: {ds, dy, dx, ok(4), max_offset, cube}
    let mut s = String::new();
    let (mut cnt, mut pos) = (0, 0);
    let specials = special_refine_cubes(&mut r, (n / 200).max(10), (n / 200).max(10));
    let mut cubes: Vec<Cube> = Vec::new();
    for _ in 0..n {
        cubes.push(gen_cube(&mut r));
    }
    cubes.extend(ext_cubes);
    cubes.extend(specials);
    // All-extreme cubes with a structure: centre +-32767/-32768, ring of the opposite.
    for m in 0..32u32 {
        let mut c: Cube = [[[0; 3]; 3]; 3];
        for (i, v) in c.iter_mut().flatten().flatten().enumerate() {
            *v = if (m as usize + i * 7) % 5 < 2 {
                32767
            } else {
                -32768
            };
        }
        cubes.push(c);
        c[1][1][1] = if m & 1 == 0 { 32767 } else { -32768 };
        cubes.push(c);
    }
    for c in &cubes {
        let m = match r.below(5) {
            0 => r.next() as u16,
            1 => [0u16, 1, 4096, 32767, 32768, 65535][r.below(6) as usize],
            2 => 4096,
            _ => 65535,
        };
        pos += refine_line(&mut s, c, m) as usize;
        cnt += 1;
        // The acceptance boundary: max |o| == max_offset and max_offset - 1.
        if let Some(o) = refine(c, 65535) {
            let a = o.iter().map(|v| v.to_bits().unsigned_abs()).max().unwrap();
            pos += refine_line(&mut s, c, a) as usize;
            cnt += 1;
            if a > 0 {
                pos += refine_line(&mut s, c, a - 1) as usize;
                cnt += 1;
            }
        }
    }
    fs::write(format!("{dir}/refine.hex"), &s).unwrap();
    println!("refine {cnt} vectors, {pos} accepted");

    // ---- sobel: {sy(20), sx(20), p}
    let mut s = String::new();
    let mut cnt = 0;
    let mut emit = |s: &mut String, p: &[[u16; 3]; 3]| {
        let (sx, sy) = sobel(p);
        write!(s, "{:05x}{:05x}", sy as u32 & 0xfffff, sx as u32 & 0xfffff).unwrap();
        for i in (0..9).rev() {
            write!(s, "{:04x}", p[i / 3][i % 3]).unwrap();
        }
        s.push('\n');
        cnt += 1;
    };
    for m in 0..512u32 {
        let mut p = [[0u16; 3]; 3];
        for i in 0..9 {
            p[i / 3][i % 3] = if m >> i & 1 == 1 { 65535 } else { 0 };
        }
        emit(&mut s, &p);
    }
    for _ in 0..n {
        let mut p = [[0u16; 3]; 3];
        let lim = [2u64, 256, 65536][r.below(3) as usize];
        for v in p.iter_mut().flatten() {
            *v = r.below(lim) as u16;
        }
        emit(&mut s, &p);
    }
    fs::write(format!("{dir}/sobel.hex"), &s).unwrap();
    println!("sobel {cnt} vectors");

    // ---- cordic: per clock {empty(4), ori(8), mag, out_y, out_x, out_valid(4),
    //                         sy(20), sx(20), in_y, in_x, {start, en, in_valid}(4)}
    // Expected outputs are the output register before the edge (peeked on a clone).
    let mut s = String::new();
    let mut p = CordicPipeline::new();
    let (mut clocks, mut inputs, mut outs) = (0, 0, 0);
    let mut special: Vec<(i32, i32)> = Vec::new();
    for k in [
        0i32, 1, 2, 3, 255, 256, 4096, 131071, 262140, 262143, 262144,
    ] {
        for (a, b) in [
            (k, 0),
            (0, k),
            (k, k),
            (k, 1),
            (1, k),
            (k, k - 1),
            (k - 1, k),
        ] {
            for (sa, sb) in [(1, 1), (-1, 1), (1, -1), (-1, -1)] {
                special.push((sa * a, sb * b));
            }
        }
    }
    for a in -4..=4 {
        for b in -4..=4 {
            special.push((a, b));
        }
    }
    let in_range = |v: i32| (-262144..=262143).contains(&v);
    special.retain(|&(a, b)| in_range(a) && in_range(b));
    let n_special = special.len();
    let mut k = 0usize;
    let mut t = 0usize;
    let mut tail = 0;
    while tail < 12 {
        t += 1;
        let flush = k >= n + n_special;
        tail += flush as usize;
        let start = !flush && (t % 997 == 500 || t == 1);
        let en = flush || (!start && r.chance(0.85));
        let valid = !flush && r.chance(0.9);
        let (sx, sy) = if k < n_special {
            special[k]
        } else {
            match r.below(4) {
                0 => (
                    r.range(-262144, 262143) as i32,
                    r.range(-262144, 262143) as i32,
                ),
                1 => (r.range(-300, 300) as i32, r.range(-300, 300) as i32),
                2 => {
                    let m = r.range(0, 262143) as i32;
                    let a = [
                        (m, 0),
                        (0, m),
                        (-m, 0),
                        (0, -m),
                        (m, m),
                        (-m, m),
                        (m, -m),
                        (-m, -m),
                    ];
                    a[r.below(8) as usize]
                }
                _ => (
                    r.range(-262140, 262140) as i32,
                    r.range(-262140, 262140) as i32,
                ),
            }
        };
        let (ix, iy) = (r.next() as u16, r.next() as u16);
        let out = p.clone().clock(None);
        let empty = p.is_empty();
        if start {
            p = CordicPipeline::new();
        } else if en {
            let got = p.clock(valid.then_some((ix, iy, sx, sy)));
            assert_eq!(got, out);
            if valid {
                inputs += 1;
                k += 1;
            }
            outs += got.is_some() as usize;
        }
        let (ov, ox, oy, om, oo) = match out {
            Some((x, y, m, o)) => (1, x, y, m, o),
            None => (0, 0, 0, 0, 0),
        };
        let ctl = (start as u8) << 2 | (en as u8) << 1 | valid as u8;
        writeln!(
            s,
            "{:x}{oo:02x}{om:02x}{oy:04x}{ox:04x}{ov:x}{:05x}{:05x}{iy:04x}{ix:04x}{ctl:x}",
            empty as u8,
            sy as u32 & 0xfffff,
            sx as u32 & 0xfffff
        )
        .unwrap();
        clocks += 1;
    }
    fs::write(format!("{dir}/cordic.hex"), &s).unwrap();
    println!("cordic {clocks} clocks, {inputs} vectors in, {outs} out ({n_special} special)");
}
