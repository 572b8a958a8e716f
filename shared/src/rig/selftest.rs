//! Deterministic scenarios run on the host and on the emulated MCU (filled in below).
