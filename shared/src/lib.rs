//! Wire format shared by the soft-core firmware and the host.
#![no_std]
