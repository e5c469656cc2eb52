//! Hardware in the loop: the firmware ELF on an emulated RISC-V soft-core (QEMU `virt`) or
//! on the SoC in the loop (a real core and the fabric's RTL under Verilator, the binary
//! `sc-soc-sim`, which takes QEMU's place: [`MachineConfig::soc`]), speaking the wire format to
//! the same host driver, session and estimator as the in-process device. Both are a
//! *machine* here: the SoC's board is started and spoken to exactly as QEMU is.
//!
//! The frames go into the soft-core's frame-grabber region before it boots ([`GrabberInput`];
//! the UART is far too slow for pixels); the configuration, the packets and the firmware's
//! defmt logs go over the UART, which the machine puts on a Unix socket ([`MachineDevice`]).
//! [`run_on_machine`] runs any session on it and stops the machine on every path;
//! [`run_sequence`] is `stereocal hil`, with the in-process comparison
//! ([`compare_streams`]); [`SocReport`] reads what the SoC's board measured. The
//! `stereocal-hil` tests check that the bytes are the in-process device's bytes and the
//! estimates the same numbers.

mod device_log;
mod error;
mod input;
mod machine;
mod run;
mod soc_report;
mod stream_compare;

pub use device_log::{instruction_reports, kernel_report, DeviceLog, LogDecoder};
pub use error::{FirmwareExit, HilError, TimeoutKind};
pub use input::GrabberInput;
pub use machine::{MachineConfig, MachineDevice, MachineEnd, MachineTimeouts, DEFAULT_QEMU};
pub use run::{run_on_machine, run_sequence, MachineRun, SequenceRun};
pub use soc_report::{ImageTiming, Latency, SimEnd, SocReport};
pub use stream_compare::{compare_streams, StreamMismatch};
