//! The register writes of a [`FabricConfig`] and what each register must read back.
//!
//! `FabricConfig::write_to` is the one definition of which fields go where; running it
//! against an in-memory [`RegisterBank`] that records the bus writes turns it into wire
//! `RegisterWrite` packets without restating the register map, and the bank's read-back
//! (with the map's access rules: reserved bits read 0) is what the device must answer.
//! [`writes`] does the same for any other register operation, such as the generated
//! [`stereocal_hdl::Registers`] setters.

use stereocal_hdl::{Error, FabricConfig, RegisterBank, RegisterBus};

/// Register writes in order, then the registers to read back with their expected values.
pub(crate) struct Plan {
    pub writes: Vec<(u16, u32)>,
    pub read_back: Vec<(u16, u32)>,
}

/// A bank that remembers the writes made through it.
struct Recorder {
    bank: RegisterBank,
    writes: Vec<(u16, u32)>,
}

impl RegisterBus for Recorder {
    fn read(&mut self, offset: u16) -> u32 {
        self.bank.read(offset)
    }

    fn write(&mut self, offset: u16, value: u32) {
        self.bank.write(offset, value);
        self.writes.push((offset, value));
    }
}

impl Recorder {
    fn new() -> Self {
        Self {
            bank: RegisterBank::new(),
            writes: Vec::new(),
        }
    }
}

/// The register writes `op` makes on a bus whose registers are at their reset values, in
/// order, as the device must receive them: what a program that speaks to a device through
/// `RegisterWrite` packets (or a test that drives registers itself) sends for a register
/// operation, e.g. `register_writes(|bus| config.write_to(bus))` (re-exported as
/// [`crate::driver::register_writes`]).
pub fn writes(
    op: impl FnOnce(&mut dyn RegisterBus) -> Result<(), Error>,
) -> Result<Vec<(u16, u32)>, Error> {
    let mut recorder = Recorder::new();
    op(&mut recorder)?;
    Ok(recorder.writes)
}

/// The writes `config` needs, validated first.
pub(crate) fn plan(config: &FabricConfig) -> Result<Plan, Error> {
    let mut recorder = Recorder::new();
    config.write_to(&mut recorder)?;
    let mut read_back: Vec<(u16, u32)> = Vec::new();
    for &(addr, _) in &recorder.writes {
        if !read_back.iter().any(|&(a, _)| a == addr) {
            read_back.push((addr, recorder.bank.read(addr)));
        }
    }
    Ok(Plan {
        writes: recorder.writes,
        read_back,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal_hdl::regs;

    #[test]
    fn plan_writes_every_configuration_register_once() {
        let config = FabricConfig {
            width: 320,
            height: 240,
            octaves: 3,
            contrast_threshold: 5 << 8,
            edge_ratio: 12,
            sobel_output: regs::output_mode::SobelOutput::Rows,
            sobel_scale: 2,
            points_per_batch: 16,
            row_segment: 1280,
            max_offset: 4096,
        };
        let plan = plan(&config).unwrap();
        let offsets: Vec<u16> = plan.read_back.iter().map(|&(a, _)| a).collect();
        assert_eq!(
            offsets,
            [
                regs::width::OFFSET,
                regs::height::OFFSET,
                regs::octaves::OFFSET,
                regs::contrast_threshold::OFFSET,
                regs::edge_threshold::OFFSET,
                regs::output_mode::OFFSET,
                regs::max_offset::OFFSET
            ]
        );
        assert!(plan.read_back.contains(&(regs::width::OFFSET, 320)));
        // Rows (0), scale 2, 16 points per batch, whole rows of up to 1280 pixels.
        assert!(plan
            .read_back
            .contains(&(regs::output_mode::OFFSET, 1280 << 16 | 16 << 8 | 2 << 4)));
    }

    #[test]
    fn enabling_is_one_write_of_control_enable() {
        use stereocal_hdl::Registers;
        let enable = writes(|bus| bus.set_control_enable(true)).unwrap();
        assert_eq!(enable, [(regs::control::OFFSET, 1)]);
    }

    #[test]
    fn invalid_config_plans_nothing() {
        let config = FabricConfig {
            width: 322,
            ..FabricConfig::default()
        };
        assert!(matches!(
            plan(&config),
            Err(Error::FrameNotDivisible { .. })
        ));
    }
}
