//! The firmware's defmt logs, read back from the UART transcript.
//!
//! The firmware sends a defmt frame in each `Log` packet: an index into the format strings
//! that stay in the ELF, and the arguments. `defmt-decoder` turns them back into text with
//! the table it reads from the same ELF, so the firmware never stores or sends its strings.
//! Instruction reports ([`InstructionReport`], [`KernelReport`]) are such logs too.

use std::path::Path;

use defmt_decoder::Table;
use stereocal_firmware::softcore::instructions::{InstructionReport, KernelReport};
use stereocal_wire::{Accumulator, FeedResult, PacketRepr, MAX_ENCODED_LEN};

use super::HilError;

/// One decoded log packet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeviceLog {
    /// Sequence number of the packet.
    pub seq: u16,
    /// `error`, `info`, ...; `None` for `println` (instruction reports).
    pub level: Option<&'static str>,
    /// The message; a note with the raw bytes when the table does not know the frame.
    pub text: String,
}

impl std::fmt::Display for DeviceLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.level {
            Some(level) => write!(f, "[seq {}] {level}: {}", self.seq, self.text),
            None => write!(f, "[seq {}] {}", self.seq, self.text),
        }
    }
}

/// The defmt table of a firmware ELF.
pub struct LogDecoder {
    table: Table,
}

impl LogDecoder {
    /// Reads the table from the ELF at `elf`.
    pub fn from_elf(elf: &Path) -> Result<Self, HilError> {
        let bytes = std::fs::read(elf).map_err(|source| HilError::File {
            path: elf.to_path_buf(),
            source,
        })?;
        let table_error = |reason: String| HilError::DefmtTable {
            path: elf.to_path_buf(),
            reason,
        };
        match Table::parse(&bytes) {
            Ok(Some(table)) => Ok(Self { table }),
            Ok(None) => Err(table_error("the ELF has no .defmt section".into())),
            Err(e) => Err(table_error(format!("{e:#}"))),
        }
    }

    /// Every `Log` packet in `transcript` (device-to-host bytes), decoded, in order. Damaged
    /// link frames are skipped: the host driver counts those.
    pub fn logs(&self, transcript: &[u8]) -> Vec<DeviceLog> {
        let mut accumulator = Box::new(Accumulator::<{ MAX_ENCODED_LEN - 1 }>::new());
        let mut logs = Vec::new();
        let mut window = transcript;
        while !window.is_empty() {
            window = match accumulator.feed(window) {
                FeedResult::Consumed => &[],
                FeedResult::OverFull(rest) => rest,
                FeedResult::DecodeError { remaining, .. } => remaining,
                FeedResult::Success {
                    header,
                    packet,
                    remaining,
                } => {
                    if let PacketRepr::Log(log) = packet {
                        logs.push(self.decode(header.seq, log.frame));
                    }
                    remaining
                }
            };
        }
        logs
    }

    fn decode(&self, seq: u16, frame: &[u8]) -> DeviceLog {
        match self.table.decode(frame) {
            Ok((decoded, _)) => DeviceLog {
                seq,
                level: decoded.level().map(|l| l.as_str()),
                text: decoded.display_message().to_string(),
            },
            Err(e) => DeviceLog {
                seq,
                level: None,
                text: format!("<log frame {frame:02x?} not in the ELF's defmt table: {e}>"),
            },
        }
    }
}

/// The instruction reports among `logs`, in order.
pub fn instruction_reports(logs: &[DeviceLog]) -> Vec<InstructionReport> {
    logs.iter()
        .filter(|log| log.level.is_none())
        .filter_map(|log| InstructionReport::parse(&log.text))
        .collect()
}

/// The row-kernel report among `logs` (the firmware sends one per run).
pub fn kernel_report(logs: &[DeviceLog]) -> Option<KernelReport> {
    logs.iter()
        .filter(|log| log.level.is_none())
        .find_map(|log| KernelReport::parse(&log.text))
}
