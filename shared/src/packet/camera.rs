//! Which camera of the stereo head a packet is about.

/// The camera byte. Unknown values are kept so they round-trip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Camera {
    /// `0`: the left camera (the reference frame of the head).
    Left,
    /// `1`: the right camera, at `+baseline` along x.
    Right,
    /// Any other value.
    Unknown(u8),
}

impl From<u8> for Camera {
    fn from(value: u8) -> Self {
        match value {
            0 => Camera::Left,
            1 => Camera::Right,
            other => Camera::Unknown(other),
        }
    }
}

impl From<Camera> for u8 {
    fn from(camera: Camera) -> u8 {
        match camera {
            Camera::Left => 0,
            Camera::Right => 1,
            Camera::Unknown(other) => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_round_trips() {
        for byte in 0..=u8::MAX {
            assert_eq!(u8::from(Camera::from(byte)), byte);
        }
        assert_eq!(Camera::from(7), Camera::Unknown(7));
    }
}
