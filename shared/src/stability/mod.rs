//! Stability theory (SPEC §4).
