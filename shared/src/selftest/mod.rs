//! Deterministic scenarios with digests of everything they compute, run by the host tests and,
//! compiled for `thumbv7em-none-eabihf`, by the on-target harness on the emulated Cortex-M4F
//! (`qemu/`): passing on both proves the results bit-identical. They sit above every module they
//! exercise, the simulated sensor included.
//!
//! | module | scenarios |
//! |---|---|
//! | [`rig`] | the rig logic piece by piece: drive generator, phase lock, estimator, supervisor, bench faults |
//! | [`station`] | the rig loop as the firmware runs it: bytes in, frames out |

pub mod rig;
pub mod station;
