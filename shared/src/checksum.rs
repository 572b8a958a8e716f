//! The one checksum the rig uses: CRC-32C (Castagnoli, as in iSCSI), over link frames, the flash
//! record and the state kept across a reset.

/// CRC-32C: init 0xFFFFFFFF, reflected, final XOR 0xFFFFFFFF.
pub const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
