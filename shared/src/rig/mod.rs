//! The rig's microcontroller logic, hardware-free: drive generation, estimation and safety.
//!
//! Everything here runs on the STM32G474 (Cortex-M4F, 170 MHz) unchanged; the firmware only
//! wires it to timers, the encoder, the PWM and the serial link. It is tested on the host, in
//! closed loop against the simulated pendulum (`tests/tests/closed_loop*.rs`) and, compiled for
//! `thumbv7em-none-eabihf`, on an emulated Cortex-M4 (`qemu/`), with bit-identical results.
//!
//! | module | concept |
//! |---|---|
//! | [`fixed`] | Q-format aliases, the wrapping [`fixed::Angle`], and every approximation (sin/cos, ln, sqrt, division) with its tested error bound |
//! | [`config`] | the rig configuration — stroke A, pendulum geometry, limits — as one type; R ↔ ω |
//! | [`fields`] | the safety range of each configuration field that guards the rig: numbers only |
//! | [`calibration`] | the bench's measured constants in the configuration: sensor zero and signs, servo map, current sense, estimator thresholds |
//! | [`closed_loop`] | the settings of closing the loop on R (carried and stored) |
//! | [`dds`] | the drive-phase accumulator: exact integer phase, rate-limited phase-continuous frequency changes, soft start and stop |
//! | [`phase_lock`] | the [`phase_lock::Motor`] trait and the crank phase-lock controller (feed-forward + PI on the phase error) |
//! | [`estimator`] | slow angle by synchronous averaging, slow frequency and decay, settled flag, R in situ, fast-wobble check of A |
//! | [`as5047`] | the pendulum sensor's SPI frames: parity, the error flag and its clearing read, diagnostics (magnet), health |
//! | [`bridge`] | the H-bridge's nFAULT and TIM1's break flag: ignored while it sleeps and wakes, a latched fault once awake |
//! | [`estop`] | the e-stop line debounced at the control tick; unknown counts as pressed |
//! | [`safety`] | limits, refusals with reasons, stall / over-current / e-stop faults, the link-silence policy |
//! | [`r_trim`] | closed-loop R: once settled, ω trimmed so the in-situ R equals the R asked for, within a band and a rate limit |
//! | [`controller`] | one rig: the above composed into a sample tick and a control tick |
//! | [`servo`] | θd → the tilt servo's pulse; the θd the rig starts from after a reset |
//! | [`retained`] | the last θd and fault, and what made the firmware fail, kept in RAM across a reset with a CRC; the reset's cause |
//! | [`watchdog`] | the independent watchdog's timeout from the control period and the flash's longest blocking step |
//!
//! # Rates (why these)
//!
//! ```text
//! sample / DDS tick  fs = 10 kHz   ≥ 150 samples per drive period up to ω = 420 rad/s (67 Hz),
//!                                  enough to average the fast wobble to < 1e-3 of its amplitude
//! control tick       fc = 1 kHz    ≥ 10× the phase-lock bandwidth (≈ 8 rad/s) and 20× the motor
//!                                  lag corner (τ ≈ 50 ms); safety reacts within 1 ms
//! estimator slow update  once per drive period (≈ 30–67 Hz): the rate the averaged φ exists at
//! ```
//! Costs per update and the 20 % budget at 170 MHz are measured in `docs/accuracy-mcu.md`.

pub mod as5047;
pub mod bridge;
pub mod calibration;
pub mod closed_loop;
pub mod config;
pub mod controller;
pub mod dds;
pub mod estimator;
pub mod estop;
pub mod fields;
pub mod fixed;
pub mod phase_lock;
pub mod r_trim;
pub mod retained;
pub mod safety;
pub mod servo;
pub mod watchdog;
