//! Runs of fixed-size records inside a payload (points, Sobel pixels), without allocation.
//!
//! A received packet holds its records as bytes; a sender holds them as a slice of values.
//! [`Records`] is either, so one `Repr` type serves both sides: the host iterates the bytes it
//! received, the firmware hands in the slice it filled from a FIFO.

use core::fmt;
use core::iter::FusedIterator;
use core::slice::ChunksExact;

/// A value with a fixed little-endian layout of [`Record::LEN`] bytes.
pub trait Record: Copy {
    /// Bytes one record takes on the wire.
    const LEN: usize;
    /// Reads a record from the first [`Record::LEN`] bytes of `bytes`.
    ///
    /// # Panics
    /// If `bytes` is shorter than [`Record::LEN`]; [`Records`] never calls it so.
    fn read(bytes: &[u8]) -> Self;
    /// Writes the record into the first [`Record::LEN`] bytes of `bytes`.
    ///
    /// # Panics
    /// If `bytes` is shorter than [`Record::LEN`]; [`Records`] never calls it so.
    fn write(&self, bytes: &mut [u8]);
}

/// A run of records: either received bytes or values to send. Equality compares the records.
#[derive(Clone, Copy)]
pub enum Records<'a, R: Record> {
    /// Records as they are on the wire, [`Record::LEN`] bytes each (a trailing partial record
    /// is ignored; the parsers never produce one).
    Wire(&'a [u8]),
    /// Records as values.
    Values(&'a [R]),
}

impl<'a, R: Record> Records<'a, R> {
    /// Number of records.
    pub fn len(&self) -> usize {
        match self {
            Records::Wire(bytes) => bytes.len() / R::LEN,
            Records::Values(values) => values.len(),
        }
    }

    /// `true` when there are no records.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The record at `index`, if there is one.
    pub fn get(&self, index: usize) -> Option<R> {
        match self {
            Records::Wire(bytes) => bytes.chunks_exact(R::LEN).nth(index).map(R::read),
            Records::Values(values) => values.get(index).copied(),
        }
    }

    /// Iterates over the records in wire order.
    pub fn iter(&self) -> RecordIter<'a, R> {
        let inner = match *self {
            Records::Wire(bytes) => Source::Wire(bytes.chunks_exact(R::LEN)),
            Records::Values(values) => Source::Values(values.iter()),
        };
        RecordIter { inner }
    }

    /// Bytes the records take on the wire.
    pub(crate) fn wire_len(&self) -> usize {
        self.len() * R::LEN
    }

    /// Writes every record into `out`, which is [`Self::wire_len`] bytes long.
    ///
    /// One loop per variant rather than one over [`Self::iter`]: a Sobel row is thousands of
    /// records, and the iterator's per-record variant match kept the loop from vectorising.
    pub(crate) fn write(&self, out: &mut [u8]) {
        match self {
            Records::Wire(bytes) => {
                let whole = bytes.len() - bytes.len() % R::LEN;
                for (out, byte) in out.iter_mut().zip(bytes.get(..whole).unwrap_or_default()) {
                    *out = *byte;
                }
            }
            Records::Values(values) => {
                for (record, chunk) in values.iter().zip(out.chunks_exact_mut(R::LEN)) {
                    record.write(chunk);
                }
            }
        }
    }
}

impl<'a, R: Record> IntoIterator for Records<'a, R> {
    type Item = R;
    type IntoIter = RecordIter<'a, R>;
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<R: Record + PartialEq> PartialEq for Records<'_, R> {
    fn eq(&self, other: &Self) -> bool {
        self.iter().eq(other.iter())
    }
}

impl<R: Record + Eq> Eq for Records<'_, R> {}

impl<R: Record + fmt::Debug> fmt::Debug for Records<'_, R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(feature = "defmt")]
impl<R: Record> defmt::Format for Records<'_, R> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "[{} records]", self.len());
    }
}

/// Iterator over [`Records`], yielding records by value.
#[derive(Clone, Debug)]
pub struct RecordIter<'a, R: Record> {
    inner: Source<'a, R>,
}

#[derive(Clone, Debug)]
enum Source<'a, R: Record> {
    Wire(ChunksExact<'a, u8>),
    Values(core::slice::Iter<'a, R>),
}

impl<R: Record> Iterator for RecordIter<'_, R> {
    type Item = R;
    fn next(&mut self) -> Option<R> {
        match &mut self.inner {
            Source::Wire(chunks) => chunks.next().map(R::read),
            Source::Values(values) => values.next().copied(),
        }
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        match &self.inner {
            Source::Wire(chunks) => chunks.size_hint(),
            Source::Values(values) => values.size_hint(),
        }
    }
}

impl<R: Record> ExactSizeIterator for RecordIter<'_, R> {}
impl<R: Record> FusedIterator for RecordIter<'_, R> {}
