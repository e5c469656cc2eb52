//! The fabric's configuration as one typed value: what the driver writes and the model reads.

use crate::regs::output_mode::{self, SobelOutput};
use crate::regs::{contrast_threshold, edge_threshold, height, max_offset, octaves, width};
use crate::{Error, RegisterBus};

/// Everything the driver sets before arming a frame. [`FabricConfig::default`] is the reset
/// state of the registers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FabricConfig {
    /// Pixels per line, `MIN_SIDE..=MAX_WIDTH`.
    pub width: u16,
    /// Lines per frame, `MIN_SIDE..=MAX_HEIGHT`.
    pub height: u16,
    /// Octaves, `1..=MAX_OCTAVES`.
    pub octaves: u8,
    /// Contrast threshold of a kept extremum, Q8.8 grey levels (256 = 1.0): the model's
    /// `Config::contrast_threshold`, unchanged.
    pub contrast_threshold: u16,
    /// Lowe's principal-curvature ratio r, `1..=31`.
    pub edge_ratio: u8,
    /// Sobel rows or 16x16 patches.
    pub sobel_output: SobelOutput,
    /// Gaussian scale feeding the Sobel unit, `0..=3`.
    pub sobel_scale: u8,
    /// Most points per `PointBatch` packet, `1..=128` (the driver's packing, which the fabric
    /// does not read).
    pub points_per_batch: u8,
    /// Most pixels per `SobelRows` packet, `MIN_SIDE..=MAX_WIDTH`: wider rows go out in
    /// segments (the driver's packing, which the fabric does not read).
    pub row_segment: u16,
    /// Largest accepted refinement offset per axis, raw Q2.13, `0..=8191` (4096 = 0.5).
    pub max_offset: u16,
}

impl Default for FabricConfig {
    fn default() -> Self {
        Self {
            width: width::VALUE.reset as u16,
            height: height::VALUE.reset as u16,
            octaves: octaves::COUNT.reset as u8,
            contrast_threshold: contrast_threshold::VALUE.reset as u16,
            edge_ratio: edge_threshold::R.reset as u8,
            sobel_output: output_mode::SOBEL_OUTPUT_RESET,
            sobel_scale: output_mode::SOBEL_SCALE.reset as u8,
            points_per_batch: output_mode::POINTS_PER_BATCH.reset as u8,
            row_segment: output_mode::ROW_SEGMENT.reset as u16,
            max_offset: max_offset::VALUE.reset as u16,
        }
    }
}

impl FabricConfig {
    /// Checks every value against its field's range and the frame against the octave count.
    pub fn validate(&self) -> Result<(), Error> {
        width::VALUE.check(self.width.into())?;
        height::VALUE.check(self.height.into())?;
        octaves::COUNT.check(self.octaves.into())?;
        contrast_threshold::VALUE.check(self.contrast_threshold.into())?;
        edge_threshold::R.check(self.edge_ratio.into())?;
        output_mode::SOBEL_SCALE.check(self.sobel_scale.into())?;
        output_mode::POINTS_PER_BATCH.check(self.points_per_batch.into())?;
        output_mode::ROW_SEGMENT.check(self.row_segment.into())?;
        max_offset::VALUE.check(self.max_offset.into())?;
        // `octaves` is in 1..=MAX_OCTAVES here, so the shift is small.
        let step = 1u16 << (self.octaves - 1);
        if self.width % step != 0 || self.height % step != 0 {
            return Err(Error::FrameNotDivisible {
                width: self.width,
                height: self.height,
                octaves: self.octaves,
            });
        }
        Ok(())
    }

    /// Validates, then writes the configuration registers (nothing is written if a value is
    /// invalid).
    pub fn write_to<B: RegisterBus + ?Sized>(&self, bus: &mut B) -> Result<(), Error> {
        self.validate()?;
        bus.write_field(&width::VALUE, self.width.into())?;
        bus.write_field(&height::VALUE, self.height.into())?;
        bus.write_field(&octaves::COUNT, self.octaves.into())?;
        bus.write_field(&contrast_threshold::VALUE, self.contrast_threshold.into())?;
        bus.write_field(&edge_threshold::R, self.edge_ratio.into())?;
        let mode = output_mode::SOBEL_OUTPUT.insert(0, self.sobel_output.bits())?;
        let mode = output_mode::SOBEL_SCALE.insert(mode, self.sobel_scale.into())?;
        let mode = output_mode::POINTS_PER_BATCH.insert(mode, self.points_per_batch.into())?;
        let mode = output_mode::ROW_SEGMENT.insert(mode, self.row_segment.into())?;
        bus.write(output_mode::OFFSET, mode);
        bus.write_field(&max_offset::VALUE, self.max_offset.into())?;
        Ok(())
    }

    /// Reads the configuration registers and validates what they hold.
    pub fn read_from<B: RegisterBus + ?Sized>(bus: &mut B) -> Result<Self, Error> {
        let mode = bus.read(output_mode::OFFSET);
        let output_bits = output_mode::SOBEL_OUTPUT.extract(mode);
        let config = Self {
            width: narrow(&width::VALUE, bus.read_field(&width::VALUE))?,
            height: narrow(&height::VALUE, bus.read_field(&height::VALUE))?,
            octaves: narrow(&octaves::COUNT, bus.read_field(&octaves::COUNT))?,
            contrast_threshold: narrow(
                &contrast_threshold::VALUE,
                bus.read_field(&contrast_threshold::VALUE),
            )?,
            edge_ratio: narrow(&edge_threshold::R, bus.read_field(&edge_threshold::R))?,
            sobel_output: SobelOutput::from_bits(output_bits).ok_or(Error::UnknownEnumValue {
                field: output_mode::SOBEL_OUTPUT.name,
                value: output_bits,
            })?,
            sobel_scale: narrow(
                &output_mode::SOBEL_SCALE,
                output_mode::SOBEL_SCALE.extract(mode),
            )?,
            points_per_batch: narrow(
                &output_mode::POINTS_PER_BATCH,
                output_mode::POINTS_PER_BATCH.extract(mode),
            )?,
            row_segment: narrow(
                &output_mode::ROW_SEGMENT,
                output_mode::ROW_SEGMENT.extract(mode),
            )?,
            max_offset: narrow(&max_offset::VALUE, bus.read_field(&max_offset::VALUE))?,
        };
        config.validate()?;
        Ok(config)
    }
}

/// `value` in the config's integer type, or the field's range error.
fn narrow<T: TryFrom<u32>>(field: &crate::Field, value: u32) -> Result<T, Error> {
    let value = field.check(value)?;
    T::try_from(value).map_err(|_| Error::FieldOutOfRange {
        field: field.name,
        value,
        min: field.min,
        max: field.max,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RegisterBank;

    #[test]
    fn default_is_the_reset_state() {
        let mut bank = RegisterBank::new();
        assert_eq!(
            FabricConfig::read_from(&mut bank),
            Ok(FabricConfig::default())
        );
    }

    #[test]
    fn write_then_read_round_trips() {
        let mut bank = RegisterBank::new();
        let config = FabricConfig {
            width: 1280,
            height: 1024,
            octaves: 3,
            contrast_threshold: 0x0C80,
            edge_ratio: 12,
            sobel_output: SobelOutput::Rows,
            sobel_scale: 2,
            points_per_batch: 128,
            row_segment: 100,
            max_offset: 8191,
        };
        config.write_to(&mut bank).unwrap();
        assert_eq!(FabricConfig::read_from(&mut bank), Ok(config));
    }

    #[test]
    fn invalid_configs_are_rejected_before_any_write() {
        let mut bank = RegisterBank::new();
        let odd = FabricConfig {
            width: 642,
            ..FabricConfig::default()
        };
        assert_eq!(
            odd.write_to(&mut bank),
            Err(Error::FrameNotDivisible {
                width: 642,
                height: 480,
                octaves: 4
            })
        );
        let zero_octaves = FabricConfig {
            octaves: 0,
            ..FabricConfig::default()
        };
        assert!(matches!(
            zero_octaves.write_to(&mut bank),
            Err(Error::FieldOutOfRange {
                field: "OCTAVES.COUNT",
                ..
            })
        ));
        let far = FabricConfig {
            max_offset: 8192,
            ..FabricConfig::default()
        };
        assert!(matches!(
            far.write_to(&mut bank),
            Err(Error::FieldOutOfRange {
                field: "MAX_OFFSET.VALUE",
                value: 8192,
                ..
            })
        ));
        assert_eq!(bank, RegisterBank::new());
    }

    #[test]
    fn a_register_value_outside_its_range_is_reported_on_read() {
        let mut bank = RegisterBank::new();
        bank.write(octaves::OFFSET, 7);
        assert!(matches!(
            FabricConfig::read_from(&mut bank),
            Err(Error::FieldOutOfRange {
                field: "OCTAVES.COUNT",
                value: 7,
                ..
            })
        ));
    }
}
