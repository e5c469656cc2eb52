//! A seeded generator for the tests' stimulus.

/// splitmix64: deterministic stimulus without an RNG dependency.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        self.bits() % n
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: u64, hi: u64) -> u64 {
        lo + self.below(hi - lo + 1)
    }

    /// True with probability `per_mille / 1000`.
    pub fn chance(&mut self, per_mille: u64) -> bool {
        self.below(1000) < per_mille
    }

    /// Noise with structure, `w` x `h`: round blobs of random brightness (radius 1 to 4, one
    /// per 40 pixels) on a background of grey levels 96 to 127.
    pub fn blob_image(&mut self, w: usize, h: usize) -> Vec<u8> {
        let mut img: Vec<u8> = (0..w * h).map(|_| 96 + self.below(32) as u8).collect();
        for _ in 0..(w * h / 40).max(3) {
            let (cx, cy) = (self.below(w as u64) as i64, self.below(h as u64) as i64);
            let rad = 1 + self.below(4) as i64;
            let v = self.bits() as u8;
            for y in (cy - rad).max(0)..(cy + rad + 1).min(h as i64) {
                for x in (cx - rad).max(0)..(cx + rad + 1).min(w as i64) {
                    if (x - cx).pow(2) + (y - cy).pow(2) <= rad * rad {
                        img[y as usize * w + x as usize] = v;
                    }
                }
            }
        }
        img
    }
}
