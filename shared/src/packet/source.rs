//! The source byte of the header: which sender of a link's end wrote a packet.
//!
//! One end of a link can hold several senders that write independently: the soft-core's own
//! packets beside one channel per camera, each with its own fabric. Each source numbers its
//! own packets, so no sender has to know how many packets another sent, nor rewrite another's
//! frames to fit one numbering; the receiver checks the numbering of each source on its own.

use crate::packet::camera::Camera;

/// Who wrote a packet. Unknown values are kept so they round-trip; a receiver numbers them
/// like any other source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Source {
    /// `0`: the end itself: the host's packets, and on the device the soft-core's own
    /// (`Hello`, register answers, error reports, logs, encoders).
    Control,
    /// `1`: the left camera's channel (its frames' packets).
    Left,
    /// `2`: the right camera's channel.
    Right,
    /// Any other value.
    Unknown(u8),
}

impl Source {
    /// The source of `camera`'s channel: `1 + camera`, so that a head with more cameras
    /// numbers each channel apart. The camera byte 255, which no head has, shares 255 with
    /// camera 254 instead of wrapping onto [`Source::Control`].
    pub fn channel(camera: Camera) -> Source {
        Source::from(u8::from(camera).saturating_add(1))
    }
}

impl From<u8> for Source {
    fn from(value: u8) -> Self {
        match value {
            0 => Source::Control,
            1 => Source::Left,
            2 => Source::Right,
            other => Source::Unknown(other),
        }
    }
}

impl From<Source> for u8 {
    fn from(source: Source) -> u8 {
        match source {
            Source::Control => 0,
            Source::Left => 1,
            Source::Right => 2,
            Source::Unknown(other) => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_round_trips() {
        for byte in 0..=u8::MAX {
            assert_eq!(u8::from(Source::from(byte)), byte);
        }
        assert_eq!(Source::from(3), Source::Unknown(3));
    }

    #[test]
    fn each_camera_channel_has_its_own_source() {
        assert_eq!(Source::channel(Camera::Left), Source::Left);
        assert_eq!(Source::channel(Camera::Right), Source::Right);
        assert_eq!(Source::channel(Camera::Unknown(7)), Source::Unknown(8));
        assert_eq!(Source::channel(Camera::Unknown(255)), Source::Unknown(255));
    }
}
