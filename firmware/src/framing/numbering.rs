//! One source's sequence numbers.
//!
//! Each sender on the link (the soft-core's control packets, each camera channel's stream
//! engine) is a wire source with a numbering of its own, kept by the sender: a channel numbers
//! its frames' packets without knowing how many another channel sent, so channels can run on
//! separate cores and their frames be queued in any order without touching their bytes.

use stereocal_wire::Source;

/// The source a sender writes as and the number its next packet carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Numbering {
    source: Source,
    next_seq: u16,
}

impl Numbering {
    /// The numbering of `source`, whose first packet gets sequence number 0.
    pub const fn new(source: Source) -> Self {
        Self {
            source,
            next_seq: 0,
        }
    }

    /// The source the packets are written as.
    pub fn source(&self) -> Source {
        self.source
    }

    /// The sequence number the next packet will carry.
    pub fn next_seq(&self) -> u16 {
        self.next_seq
    }

    /// Uses up the next number (after its packet was encoded).
    pub(crate) fn advance(&mut self) {
        self.next_seq = self.next_seq.wrapping_add(1);
    }
}
