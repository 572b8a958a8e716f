//! The pendulum sensor's SPI protocol: an AS5047P magnetic encoder (ams AS5047P datasheet,
//! "SPI Interface" and "Register Description"), pipelined one frame deep.
//!
//! ```text
//! command frame:  bit 15 even parity over bits 14..0, bit 14 read (1), bits 13..0 the address
//! answer frame:   bit 15 even parity over bits 14..0, bit 14 EF (error flag), bits 13..0 data
//!                 — the answer to the *previous* frame's command
//! ANGLECOM 0x3FFF  the angle, 2^14 counts per turn         read command 0xFFFF
//! ERRFL    0x0001  bit 2 PARERR, bit 1 INVCOMM, bit 0 FRERR — cleared by reading it (0x4001)
//! DIAAGC   0x3FFC  bit 11 MAGL, bit 10 MAGH, bit 9 COF, bit 8 LF, bits 7..0 AGC  (0xFFFC)
//! ```
//! Every frame is a command and the answer to the one before, so the sensor is read with one
//! frame per sample while all goes well. When an answer carries EF, the next frame reads ERRFL,
//! which is the only way the sensor clears the flag: without that read every later frame
//! carries EF too and θ freezes. Every [`DIAG_EVERY`] samples the diagnostics (DIAAGC) are read
//! in an extra frame, so magnet loss (MAGL, MAGH) and a CORDIC overflow (COF) are seen.
//!
//! **A broken cable must not look like a sensor.** With MISO floating low, the answer 0x0000
//! has even parity, no EF and angle 0: a pendulum "hanging, settled" that is not there. MISO
//! therefore has a pull-up (docs/hardware.md): a dead line reads 0xFFFF, whose EF bit is set
//! in every answer, ERRFL reads included, so no angle ever passes and after [`FAULT_AFTER`]
//! samples the sensor counts as failed. Answers that pass parity and EF but set bits their
//! register never sets (ERRFL bits 13..3, DIAAGC bits 13..12, MAGL and MAGH together) are
//! refused as [`FrameError::Bus`].
//!
//! The angle an answer carries was latched when the command frame before it ended (the
//! datasheet's "the response data is sent with the next read command frame"), so each
//! [`Reading`] carries the time of that frame, not of the frame that brought it.

use super::fixed::Angle;

/// Read ANGLECOM: address 0x3FFF with the read bit, parity 1 (15 ones before it).
pub const READ_ANGLE: u16 = command(0x3FFF);
/// Read ERRFL (clears it).
pub const READ_ERRFL: u16 = command(0x0001);
/// Read DIAAGC.
pub const READ_DIAAGC: u16 = command(0x3FFC);
/// Read the diagnostics once in this many samples (10 Hz at the 10 kHz sample rate: magnet
/// loss is a mechanical event, slow next to the 1 kHz safety tick, and the extra frame costs
/// 1/1000 of the SPI time).
pub const DIAG_EVERY: u16 = 1000;
/// Consecutive samples without a good angle before the sensor counts as failed (3.2 ms at
/// 10 kHz: the estimator holds the last angle meanwhile; a third of the pendulum's fastest slow
/// period of ≈ 130 ms would already be far too long, so this is well inside what it tolerates,
/// yet long enough to ride out single frames hit by the motor's commutation noise).
pub const FAULT_AFTER: u16 = 32;

/// The pendulum angle of a sensor count: `sign · (count − zero)` in 2^-14 turn, as an
/// [`Angle`] (2^32 per turn, so · 2^18, exact). `zero` is the count with the pendulum hanging
/// at rest, `sign` +1 if the count grows counter-clockwise seen from the front (physics §2).
pub fn angle(count: u16, zero: u16, sign: i8) -> Angle {
    let a = Angle::from_turns_u32(u32::from(count.wrapping_sub(zero) & 0x3FFF) << 18);
    if sign < 0 {
        Angle::ZERO - a
    } else {
        a
    }
}

/// A read command for `addr` (14 bits) with its even-parity bit.
pub const fn command(addr: u16) -> u16 {
    let w = 0x4000 | (addr & 0x3FFF);
    if w.count_ones() % 2 == 1 {
        w | 0x8000
    } else {
        w
    }
}

/// Why a frame gave no angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// The SPI peripheral reported an error.
    Spi,
    /// Odd parity over the 16 bits.
    Parity,
    /// The sensor's error flag: the frame before went wrong (ERRFL says how).
    ErrorFlag,
    /// An answer no live sensor gives (bits set that the register never sets): a dead line.
    Bus,
    /// No angle asked for yet: the first sample after power-up.
    NotYet,
}

/// The diagnostics register.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Diagnostics {
    /// Automatic gain control: 0 strongest field, 255 weakest.
    pub agc: u8,
    /// Field too low (MAGL) or too high (MAGH).
    pub magnet_low: bool,
    pub magnet_high: bool,
    /// CORDIC overflow: the angle is invalid.
    pub cordic_overflow: bool,
    /// Offset compensation finished (the sensor is ready). A sensor that was ready does not
    /// lose it; a MISO line stuck low does (every frame 0x0000 passes parity and the error
    /// flag and reads as DIAAGC 0: AGC 0, LF clear, magnet "ok"), so a loss while the drive
    /// runs is a sensor fault ([`super::safety`]).
    pub ready: bool,
}

impl Diagnostics {
    /// A ready sensor with the magnet in range (AGC mid-scale): what a healthy bench reads.
    pub const HEALTHY: Self = Self {
        agc: 96,
        magnet_low: false,
        magnet_high: false,
        cordic_overflow: false,
        ready: true,
    };

    /// The field is in range and the angle computation valid.
    pub fn magnet_ok(&self) -> bool {
        !(self.magnet_low || self.magnet_high || self.cordic_overflow)
    }
}

/// The last ERRFL contents (what went wrong in a flagged frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorFlags {
    pub parity: bool,
    pub invalid_command: bool,
    pub framing: bool,
}

/// One sample's result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reading {
    /// When the angle was latched: the time of the frame that asked for it (the sample before,
    /// while all goes well); for a failed read, the time the missing angle was asked for.
    pub t_us: u32,
    /// The angle count (0..2^14), or why there is none this sample.
    pub count: Result<u16, FrameError>,
}

/// What the driver knows about the sensor's health.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Health {
    /// Samples in a row without a good angle.
    pub bad_run: u16,
    /// The last diagnostics read, if any yet.
    pub diagnostics: Option<Diagnostics>,
    /// The last ERRFL read.
    pub errors: ErrorFlags,
}

impl Health {
    /// The sensor counts as failed: [`FAULT_AFTER`] samples in a row without an angle, or the
    /// magnet out of range.
    pub fn failed(&self) -> bool {
        self.bad_run >= FAULT_AFTER || self.diagnostics.is_some_and(|d| !d.magnet_ok())
    }
}

/// What a frame asked for, so its answer (one frame later) is read as that register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Asked {
    /// Nothing yet: the first frame's answer belongs to no command of ours.
    Nothing,
    Angle {
        at_us: u32,
    },
    ErrorFlags,
    Diagnostics,
}

/// The AS5047P driver's state: what the last frame asked, the health, the diagnostic schedule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct As5047 {
    asked: Asked,
    health: Health,
    since_diag: u16,
}

impl Default for As5047 {
    fn default() -> Self {
        Self::new()
    }
}

impl As5047 {
    pub const fn new() -> Self {
        Self {
            asked: Asked::Nothing,
            health: Health {
                bad_run: 0,
                diagnostics: None,
                errors: ErrorFlags {
                    parity: false,
                    invalid_command: false,
                    framing: false,
                },
            },
            // The first sample reads the diagnostics: a missing magnet shows at once.
            since_diag: DIAG_EVERY,
        }
    }

    pub fn health(&self) -> &Health {
        &self.health
    }

    /// One sample at `now_us`: one frame, or up to three when the sensor's error flag must be
    /// cleared or the diagnostics are due. `transfer` sends one 16-bit frame (chip select
    /// around it) and returns the answer.
    pub fn sample<E>(
        &mut self,
        now_us: u32,
        mut transfer: impl FnMut(u16) -> Result<u16, E>,
    ) -> Reading {
        self.since_diag = self.since_diag.saturating_add(1);
        let mut first = if self.since_diag >= DIAG_EVERY {
            self.since_diag = 0;
            Asked::Diagnostics
        } else {
            Asked::Angle { at_us: now_us }
        };
        let wanted_us = match self.asked {
            Asked::Angle { at_us } => at_us,
            _ => now_us,
        };
        let mut angle = None;
        let mut error = None;
        // At most three frames: [diagnostics or ERRFL,] ANGLECOM, each answering the one before.
        for _ in 0..3 {
            let cmd = match first {
                Asked::Diagnostics => READ_DIAAGC,
                Asked::ErrorFlags => READ_ERRFL,
                Asked::Angle { .. } | Asked::Nothing => READ_ANGLE,
            };
            let asked = core::mem::replace(&mut self.asked, first);
            let got = match transfer(cmd) {
                Ok(w) => self.answer(asked, w),
                Err(_) => Err(FrameError::Spi),
            };
            match got {
                Ok(Some(a)) => angle = Some(a),
                Ok(None) => {}
                Err(e) => error = Some(e),
            }
            first = match (got, self.asked) {
                // The error flag stays set until ERRFL is read: read it next.
                (Err(FrameError::ErrorFlag), a) if a != Asked::ErrorFlags => Asked::ErrorFlags,
                // The last frame asked for the angle: its answer comes with the next sample.
                (_, Asked::Angle { .. }) => break,
                _ => Asked::Angle { at_us: now_us },
            };
        }
        match angle {
            Some((count, t_us)) => {
                self.health.bad_run = 0;
                Reading {
                    t_us,
                    count: Ok(count),
                }
            }
            None => {
                self.health.bad_run = self.health.bad_run.saturating_add(1);
                Reading {
                    t_us: wanted_us,
                    count: Err(error.unwrap_or(FrameError::NotYet)),
                }
            }
        }
    }

    /// Reads `word` as the answer to `asked`: an angle and its time, nothing, or an error.
    fn answer(&mut self, asked: Asked, word: u16) -> Result<Option<(u16, u32)>, FrameError> {
        if !word.count_ones().is_multiple_of(2) {
            return Err(FrameError::Parity);
        }
        if word & 0x4000 != 0 {
            return Err(FrameError::ErrorFlag);
        }
        let data = word & 0x3FFF;
        match asked {
            Asked::Nothing => Ok(None),
            Asked::Angle { at_us } => Ok(Some((data, at_us))),
            Asked::ErrorFlags => {
                if data & !0x7 != 0 {
                    return Err(FrameError::Bus);
                }
                self.health.errors = ErrorFlags {
                    parity: data & 0x4 != 0,
                    invalid_command: data & 0x2 != 0,
                    framing: data & 0x1 != 0,
                };
                Ok(None)
            }
            Asked::Diagnostics => {
                let magnet_low = data & 0x800 != 0;
                let magnet_high = data & 0x400 != 0;
                if data & 0x3000 != 0 || (magnet_low && magnet_high) {
                    return Err(FrameError::Bus);
                }
                self.health.diagnostics = Some(Diagnostics {
                    agc: (data & 0xFF) as u8,
                    magnet_low,
                    magnet_high,
                    cordic_overflow: data & 0x200 != 0,
                    ready: data & 0x100 != 0,
                });
                Ok(None)
            }
        }
    }
}
