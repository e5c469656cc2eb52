//! Contiguous bit ranges inside a 32-bit word.

/// Bits `lsb .. lsb + width` of a 32-bit word.
///
/// Every method is total: a range reaching past bit 31 simply has no bits there, so nothing
/// here can panic on a hand-built value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BitRange {
    pub lsb: u8,
    pub width: u8,
}

impl BitRange {
    /// Largest value the range holds (unshifted).
    pub const fn max_value(self) -> u32 {
        if self.width >= 32 {
            u32::MAX
        } else {
            (1u32 << self.width) - 1
        }
    }

    /// The range's bits in the word.
    pub const fn mask(self) -> u32 {
        match self.max_value().checked_shl(self.lsb as u32) {
            Some(m) => m,
            None => 0,
        }
    }

    /// The range's value in `word`.
    pub const fn extract(self, word: u32) -> u32 {
        match word.checked_shr(self.lsb as u32) {
            Some(v) => v & self.max_value(),
            None => 0,
        }
    }

    /// `word` with the range replaced by `value`, or `None` when `value` does not fit.
    pub const fn insert(self, word: u32, value: u32) -> Option<u32> {
        if value > self.max_value() {
            return None;
        }
        let cleared = word & !self.mask();
        if value == 0 {
            return Some(cleared);
        }
        match value.checked_shl(self.lsb as u32) {
            // Bits shifted past bit 31 would be lost: the value does not fit there.
            Some(shifted) if shifted >> self.lsb == value => Some(cleared | shifted),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::BitRange;

    #[test]
    fn extract_and_insert_round_trip() {
        let r = BitRange { lsb: 4, width: 2 };
        assert_eq!(r.mask(), 0x30);
        assert_eq!(r.insert(0xFFFF_FFFF, 1), Some(0xFFFF_FFDF));
        assert_eq!(r.extract(0xFFFF_FFDF), 1);
        assert_eq!(r.insert(0, 4), None);
    }

    #[test]
    fn full_word_and_out_of_word_ranges_do_not_panic() {
        let full = BitRange { lsb: 0, width: 32 };
        assert_eq!(full.mask(), u32::MAX);
        assert_eq!(full.insert(0, u32::MAX), Some(u32::MAX));
        let outside = BitRange { lsb: 40, width: 3 };
        assert_eq!(outside.mask(), 0);
        assert_eq!(outside.extract(u32::MAX), 0);
        assert_eq!(outside.insert(0, 1), None);
        assert_eq!(outside.insert(7, 0), Some(7));
    }
}
