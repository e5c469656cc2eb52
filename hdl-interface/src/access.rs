//! Access types of register fields.

/// How the bus may use a field. The fabric itself can set every field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Bus reads see the fabric's value; bus writes are ignored.
    Ro,
    /// Bus reads return what the bus last wrote.
    Rw,
    /// The fabric sets it; a bus write of 1 clears it, 0 leaves it.
    W1c,
    /// A strobe: the fabric sees what the bus wrote; bus reads return 0.
    Wo,
}
