//! The packet checksum: CRC-32C (Castagnoli), as used by iSCSI, SCTP and ext4.
//!
//! Parameters (Rocksoft model): width 32, poly `0x1EDC6F41`, init `0xFFFFFFFF`, refin true,
//! refout true, xorout `0xFFFFFFFF`, check (`"123456789"`) `0xE3069283`. Chosen over
//! CRC-32/ISO-HDLC because it detects every 5-bit error up to 655-byte packets (Hamming
//! distance 6) where ISO-HDLC stops at 371 bytes.
//!
//! On the soft-core (`target_os = "none"`) the byte-wise table of the `crc` crate costs 1 KiB
//! of read-only data. A host checks every byte of a full-Sobel stream (2.6 MB per 1264x376
//! pair), where even a slice-by-16 table was 4% of the whole chain, so it uses the `crc32c`
//! crate: the SSE 4.2 / ARMv8 CRC instructions (three streams interleaved), detected at run
//! time, with a software fallback. Both give the same checksum (tested below).

#[cfg(target_os = "none")]
static CRC32C: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// CRC-32C of `bytes`.
#[cfg(target_os = "none")]
pub fn crc32c(bytes: &[u8]) -> u32 {
    CRC32C.checksum(bytes)
}

/// CRC-32C of `bytes`.
#[cfg(not(target_os = "none"))]
pub fn crc32c(bytes: &[u8]) -> u32 {
    crc32c::crc32c(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn check_value_matches_the_catalogue() {
        assert_eq!(crc32c(b"123456789"), 0xE306_9283);
    }

    proptest! {
        /// The host's CRC agrees with the soft-core's table, at every length and alignment.
        #[test]
        fn host_crc_matches_the_soft_core_table(
            bytes in proptest::collection::vec(any::<u8>(), 0..2000),
            skip in 0usize..16,
        ) {
            let table = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
            let bytes = bytes.get(skip..).unwrap_or_default();
            prop_assert_eq!(crc32c(bytes), table.checksum(bytes));
        }
    }
}
