//! The frame-grabber input of the emulated soft-core: camera frames in a RAM region.
//!
//! QEMU has no camera, so the host puts the frames into RAM before the firmware starts
//! (`-device loader,file=FRAMES.bin,addr=0x81000000`, see [`VIRT_FRAME_REGION`]) and the
//! firmware reads them where a real frame grabber's DMA would have written them. The same
//! layout is written by the host's runner through [`InputHeader::emit`].
//!
//! ```text
//!  0      4    5       6      8       10      12            16
//! +------+----+-------+------+-------+-------+-------------+
//! |"SCFI"|ver |cameras|width |height | flags | frame_count |   header, little-endian
//! |  4 B | u8 |  u8   | u16  |  u16  |  u16  |     u32     |
//! +------+----+-------+------+-------+-------+-------------+
//! then frame_count x cameras images, for each frame the left image first:
//! +------------------+---------------------------+
//! | timestamp_us u64 | width*height pixels, u8   |   one image record
//! +------------------+---------------------------+
//! ```
//! Pixels are 8-bit grey in raster order. `flags` bit 0 ([`FLAG_AUTOSTART`]) starts the run
//! with the register reset values instead of waiting for the host to set `CONTROL.ENABLE`;
//! bit 1 ([`FLAG_REGISTER_MODEL`]) runs the register-level fabric model instead of the fast
//! path; bit 2 ([`FLAG_COUNT_INSTRUCTIONS`]) reports every image's instruction counts in a
//! `Log` packet (and after the last frame the stack high-water marks, `super::stack`); bit 3
//! ([`FLAG_WIRED_CAMERAS`]) says the board's cameras are wired to a real fabric.
//! Other bits must be 0.

/// Start of the input region on the QEMU `virt` machine (16 MiB into DRAM, above the
/// program; see `firmware/memory.x`).
pub const VIRT_FRAME_REGION: usize = 0x8100_0000;
/// Bytes of the input region: up to the end of QEMU's default 128 MiB of DRAM.
pub const VIRT_FRAME_REGION_LEN: usize = 0x8800_0000 - VIRT_FRAME_REGION;

/// First bytes of the region.
pub const MAGIC: [u8; 4] = *b"SCFI";
/// Layout version this firmware reads.
pub const VERSION: u8 = 1;
/// Bytes of the header.
pub const HEADER_LEN: usize = 16;
/// Bytes before the pixels of each image record.
pub const IMAGE_HEADER_LEN: usize = 8;
/// Run without waiting for the host's `CONTROL.ENABLE`.
pub const FLAG_AUTOSTART: u16 = 1 << 0;
/// Use the register-level fabric model instead of the fast path.
pub const FLAG_REGISTER_MODEL: u16 = 1 << 1;
/// After every image, log the instructions it took (`minstret`; instructions only under
/// QEMU's `-icount`) in the front end and in the whole frame. Off by default: the log packets
/// are packets the in-process device does not send, so a run with them is not byte-identical
/// to it.
pub const FLAG_COUNT_INSTRUCTIONS: u16 = 1 << 2;
/// The board is the SoC in the loop with its cameras wired to the fabric
/// (`hdl-interface/soc/`): the channels drive the real fabric at MMIO (`softcore::wired`,
/// built for the soft-core only) and the images here are what the cameras send, not what the
/// driver offers.
pub const FLAG_WIRED_CAMERAS: u16 = 1 << 3;
const KNOWN_FLAGS: u16 =
    FLAG_AUTOSTART | FLAG_REGISTER_MODEL | FLAG_COUNT_INSTRUCTIONS | FLAG_WIRED_CAMERAS;

/// What is wrong with an input region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputError {
    /// The region is shorter than the header.
    Truncated,
    /// The first four bytes are not [`MAGIC`] (nothing was loaded, or at another address).
    BadMagic,
    /// A layout version this firmware does not read.
    UnsupportedVersion(u8),
    /// `cameras` is neither 1 nor 2.
    BadCameraCount(u8),
    /// Width or height is 0.
    EmptyFrame,
    /// A flag bit this firmware does not know.
    UnknownFlags(u16),
    /// The frames announced need more bytes than the region has.
    TooLarge {
        /// Bytes the header announces (header included).
        needed: u64,
        /// Bytes available.
        available: usize,
    },
}

impl core::fmt::Display for InputError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Truncated => write!(f, "frame input: region shorter than its 16-byte header"),
            Self::BadMagic => write!(f, "frame input: no \"SCFI\" magic at the region start"),
            Self::UnsupportedVersion(v) => write!(f, "frame input: layout version {v} unsupported"),
            Self::BadCameraCount(n) => write!(f, "frame input: {n} cameras (1 or 2 expected)"),
            Self::EmptyFrame => write!(f, "frame input: width or height is 0"),
            Self::UnknownFlags(bits) => write!(f, "frame input: unknown flag bits {bits:#06x}"),
            Self::TooLarge { needed, available } => write!(
                f,
                "frame input: frames need {needed} bytes, the region has {available}"
            ),
        }
    }
}

/// The header of the input region.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputHeader {
    /// 1 (left only) or 2 (left, then right, per frame).
    pub cameras: u8,
    /// Pixels per line.
    pub width: u16,
    /// Lines per frame.
    pub height: u16,
    /// [`FLAG_AUTOSTART`], [`FLAG_REGISTER_MODEL`].
    pub flags: u16,
    /// Frames (stereo pairs when `cameras` is 2).
    pub frame_count: u32,
}

impl InputHeader {
    /// Bytes of one image record (timestamp and pixels): at most 2^32 + 8.
    pub fn image_record_len(&self) -> u64 {
        IMAGE_HEADER_LEN as u64 + u64::from(self.width) * u64::from(self.height)
    }

    /// Bytes of the whole input, header included (saturating: a header announcing more than
    /// `u64::MAX` bytes is as much too large as one announcing `u64::MAX`).
    pub fn total_len(&self) -> u64 {
        let images = u64::from(self.frame_count) * u64::from(self.cameras);
        images
            .saturating_mul(self.image_record_len())
            .saturating_add(HEADER_LEN as u64)
    }

    /// Whether `flag` is set.
    pub const fn has_flag(&self, flag: u16) -> bool {
        self.flags & flag != 0
    }

    /// The 16 header bytes.
    pub fn emit(&self) -> [u8; HEADER_LEN] {
        let mut out = [0; HEADER_LEN];
        out[0..4].copy_from_slice(&MAGIC);
        out[4] = VERSION;
        out[5] = self.cameras;
        out[6..8].copy_from_slice(&self.width.to_le_bytes());
        out[8..10].copy_from_slice(&self.height.to_le_bytes());
        out[10..12].copy_from_slice(&self.flags.to_le_bytes());
        out[12..16].copy_from_slice(&self.frame_count.to_le_bytes());
        out
    }

    /// Reads and checks the header at the start of `region` against the region's length.
    pub fn parse(region: &[u8]) -> Result<Self, InputError> {
        let head: &[u8; HEADER_LEN] = region
            .get(..HEADER_LEN)
            .and_then(|h| h.try_into().ok())
            .ok_or(InputError::Truncated)?;
        if head[0..4] != MAGIC {
            return Err(InputError::BadMagic);
        }
        if head[4] != VERSION {
            return Err(InputError::UnsupportedVersion(head[4]));
        }
        let header = Self {
            cameras: head[5],
            width: u16::from_le_bytes([head[6], head[7]]),
            height: u16::from_le_bytes([head[8], head[9]]),
            flags: u16::from_le_bytes([head[10], head[11]]),
            frame_count: u32::from_le_bytes([head[12], head[13], head[14], head[15]]),
        };
        if !(1..=2).contains(&header.cameras) {
            return Err(InputError::BadCameraCount(header.cameras));
        }
        if header.width == 0 || header.height == 0 {
            return Err(InputError::EmptyFrame);
        }
        if header.flags & !KNOWN_FLAGS != 0 {
            return Err(InputError::UnknownFlags(header.flags & !KNOWN_FLAGS));
        }
        if header.total_len() > region.len() as u64 {
            return Err(InputError::TooLarge {
                needed: header.total_len(),
                available: region.len(),
            });
        }
        Ok(header)
    }
}

/// One camera image of the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputImage<'a> {
    /// Capture time, microseconds (passed to FrameStart unchanged).
    pub timestamp_us: u64,
    /// `width * height` pixels, raster order.
    pub pixels: &'a [u8],
}

/// A checked input region.
#[derive(Clone, Copy, Debug)]
pub struct FrameInput<'a> {
    header: InputHeader,
    region: &'a [u8],
}

impl<'a> FrameInput<'a> {
    /// Checks the header of `region`; afterwards every image of the header is inside it.
    pub fn new(region: &'a [u8]) -> Result<Self, InputError> {
        let header = InputHeader::parse(region)?;
        Ok(Self { header, region })
    }

    /// The header.
    pub fn header(&self) -> &InputHeader {
        &self.header
    }

    /// Image of `camera` (0 = left, 1 = right) in frame `frame`; `None` past the end.
    pub fn image(&self, frame: u32, camera: u8) -> Option<InputImage<'a>> {
        if frame >= self.header.frame_count || camera >= self.header.cameras {
            return None;
        }
        // `new` checked that every record lies inside the region, so these fit a usize.
        let record_len = usize::try_from(self.header.image_record_len()).ok()?;
        let index = frame as usize * self.header.cameras as usize + camera as usize;
        let start = HEADER_LEN + index * record_len;
        let record = self.region.get(start..start + record_len)?;
        let (stamp, pixels) = record.split_at(IMAGE_HEADER_LEN);
        let mut le = [0; IMAGE_HEADER_LEN];
        le.copy_from_slice(stamp);
        Some(InputImage {
            timestamp_us: u64::from_le_bytes(le),
            pixels,
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const HEADER: InputHeader = InputHeader {
        cameras: 2,
        width: 4,
        height: 2,
        flags: FLAG_AUTOSTART,
        frame_count: 2,
    };

    /// Header, then 4 images whose timestamps are 100 + i and pixels 10*i + p.
    fn region() -> Vec<u8> {
        let mut bytes = HEADER.emit().to_vec();
        for i in 0..4u8 {
            bytes.extend_from_slice(&(100 + u64::from(i)).to_le_bytes());
            bytes.extend((0..8).map(|p| 10 * i + p));
        }
        bytes
    }

    #[test]
    fn header_bytes_are_the_documented_layout() {
        assert_eq!(
            HEADER.emit(),
            [b'S', b'C', b'F', b'I', 1, 2, 4, 0, 2, 0, 1, 0, 2, 0, 0, 0]
        );
    }

    #[test]
    fn images_come_left_then_right_per_frame() {
        let bytes = region();
        let input = FrameInput::new(&bytes).unwrap();
        assert_eq!(*input.header(), HEADER);
        let right1 = input.image(1, 1).unwrap();
        assert_eq!(right1.timestamp_us, 103);
        assert_eq!(right1.pixels, &[30, 31, 32, 33, 34, 35, 36, 37]);
        assert_eq!(input.image(0, 0).unwrap().pixels[0], 0);
        assert_eq!(input.image(2, 0), None);
        assert_eq!(input.image(0, 2), None);
    }

    #[test]
    fn bad_regions_are_named() {
        let bytes = region();
        assert_eq!(
            FrameInput::new(&bytes[..10]).err(),
            Some(InputError::Truncated)
        );
        assert_eq!(
            FrameInput::new(&bytes[..bytes.len() - 1]).err(),
            Some(InputError::TooLarge {
                needed: bytes.len() as u64,
                available: bytes.len() - 1
            })
        );
        let mut bad = bytes.clone();
        bad[0] = b'X';
        assert_eq!(FrameInput::new(&bad).err(), Some(InputError::BadMagic));
        let mut bad = bytes.clone();
        bad[4] = 9;
        assert_eq!(
            FrameInput::new(&bad).err(),
            Some(InputError::UnsupportedVersion(9))
        );
        let mut bad = bytes.clone();
        bad[5] = 3;
        assert_eq!(
            FrameInput::new(&bad).err(),
            Some(InputError::BadCameraCount(3))
        );
        let mut bad = bytes.clone();
        bad[6] = 0;
        assert_eq!(FrameInput::new(&bad).err(), Some(InputError::EmptyFrame));
        let mut bad = bytes;
        bad[11] = 0x80;
        assert_eq!(
            FrameInput::new(&bad).err(),
            Some(InputError::UnknownFlags(0x8000))
        );
    }

    #[test]
    fn huge_counts_do_not_overflow() {
        let header = InputHeader {
            frame_count: u32::MAX,
            width: u16::MAX,
            height: u16::MAX,
            ..HEADER
        };
        let bytes = header.emit();
        assert!(matches!(
            FrameInput::new(&bytes).err(),
            Some(InputError::TooLarge { .. })
        ));
    }
}
