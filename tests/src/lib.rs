//! Hardware-in-the-loop simulation harness.
