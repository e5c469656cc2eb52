//! The frame-grabber input of the emulated soft-core: every stereo pair of a run, laid out as
//! `stereocal_firmware::softcore::frame_input` reads it, for QEMU's `-device loader`.
//!
//! The UART carries well under a megabyte per second, too slow for pixels, so the frames are
//! in RAM before the firmware boots, where a frame grabber's DMA would have put them. Each
//! pair's digest is kept so the device can check that the host later asks for the same pairs
//! in the same order.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};

use stereocal_firmware::softcore::frame_input::{InputHeader, HEADER_LEN, VIRT_FRAME_REGION_LEN};

use super::HilError;

/// What identifies a loaded pair: its timestamp and a hash of each image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PairDigest {
    timestamp_us: u64,
    left: u64,
    right: u64,
}

impl PairDigest {
    pub(crate) fn of(left: &[u8], right: &[u8], timestamp_us: u64) -> Self {
        let hash = |image: &[u8]| {
            // `DefaultHasher::new` has fixed keys: the same bytes give the same digest.
            let mut h = DefaultHasher::new();
            image.hash(&mut h);
            h.finish()
        };
        Self {
            timestamp_us,
            left: hash(left),
            right: hash(right),
        }
    }
}

/// Stereo pairs for the soft-core's frame region, in the order the firmware runs them.
#[derive(Debug, Clone)]
pub struct GrabberInput {
    width: u16,
    height: u16,
    /// Image records (timestamp, pixels), left then right per pair; the header goes in front
    /// when the file is written.
    records: Vec<u8>,
    pub(crate) digests: Vec<PairDigest>,
}

impl GrabberInput {
    /// No pairs yet; every image must be `width` x `height`.
    pub fn new(width: u16, height: u16) -> Self {
        Self {
            width,
            height,
            records: Vec::new(),
            digests: Vec::new(),
        }
    }

    /// Pairs loaded so far.
    pub fn pairs(&self) -> usize {
        self.digests.len()
    }

    /// Appends a pair captured at `timestamp_us`.
    pub fn push_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), HilError> {
        let pixels = usize::from(self.width) * usize::from(self.height);
        for image in [left, right] {
            if image.len() != pixels {
                return Err(HilError::ImageSize {
                    pair: self.pairs(),
                    got: image.len(),
                    width: self.width,
                    height: self.height,
                });
            }
        }
        let needed = self.header(0, self.pairs() as u64 + 1).total_len();
        if needed > VIRT_FRAME_REGION_LEN as u64 {
            return Err(HilError::InputTooLarge {
                pairs: self.pairs() + 1,
                width: self.width,
                height: self.height,
                needed,
                available: VIRT_FRAME_REGION_LEN,
            });
        }
        for image in [left, right] {
            self.records.extend_from_slice(&timestamp_us.to_le_bytes());
            self.records.extend_from_slice(image);
        }
        self.digests.push(PairDigest::of(left, right, timestamp_us));
        Ok(())
    }

    /// The region's bytes: the header with `flags` (`frame_input`'s `FLAG_*`: with
    /// `FLAG_COUNT_INSTRUCTIONS` the firmware logs each image's instruction counts, with
    /// `FLAG_WIRED_CAMERAS` the board's cameras send the images to a real fabric), then every
    /// image record.
    pub fn to_bytes(&self, flags: u16) -> Vec<u8> {
        let header = self.header(flags, self.pairs() as u64);
        let mut bytes = Vec::with_capacity(HEADER_LEN + self.records.len());
        bytes.extend_from_slice(&header.emit());
        bytes.extend_from_slice(&self.records);
        bytes
    }

    fn header(&self, flags: u16, pairs: u64) -> InputHeader {
        InputHeader {
            cameras: 2,
            width: self.width,
            height: self.height,
            flags,
            // The region is far smaller than 2^32 pairs; `push_pair` checked the size.
            frame_count: u32::try_from(pairs).unwrap_or(u32::MAX),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal_firmware::softcore::frame_input::FrameInput;
    use stereocal_firmware::softcore::frame_input::FLAG_COUNT_INSTRUCTIONS;

    #[test]
    fn the_firmware_reads_what_is_written() {
        let mut input = GrabberInput::new(4, 2);
        input.push_pair(&[1; 8], &[2; 8], 100).unwrap();
        input.push_pair(&[3; 8], &[4; 8], 200).unwrap();
        let bytes = input.to_bytes(FLAG_COUNT_INSTRUCTIONS);
        let region = FrameInput::new(&bytes).unwrap();
        assert_eq!(region.header().frame_count, 2);
        assert!(region.header().has_flag(FLAG_COUNT_INSTRUCTIONS));
        let right1 = region.image(1, 1).unwrap();
        assert_eq!((right1.timestamp_us, right1.pixels), (200, &[4u8; 8][..]));
        assert!(!FrameInput::new(&input.to_bytes(0))
            .unwrap()
            .header()
            .has_flag(FLAG_COUNT_INSTRUCTIONS));
    }

    #[test]
    fn wrong_sizes_and_too_many_frames_are_refused() {
        let mut input = GrabberInput::new(4, 2);
        assert!(matches!(
            input.push_pair(&[1; 8], &[2; 7], 0),
            Err(HilError::ImageSize { got: 7, .. })
        ));
        // Two 64 MiB images are more than the 112 MiB region.
        let mut huge = GrabberInput::new(8192, 8192);
        let image = vec![0; 8192 * 8192];
        assert!(matches!(
            huge.push_pair(&image, &image, 0),
            Err(HilError::InputTooLarge { pairs: 1, .. })
        ));
        assert_eq!(huge.pairs(), 0);
    }
}
