//! The simulated AS5047P as its SPI pins see it, so the simulated rig reads its pendulum
//! through the same driver as the firmware ([`crate::rig::as5047`]), faults included.
//!
//! ```text
//! every frame: send the answer prepared by the previous command (EF set while ERRFL ≠ 0),
//!              then execute this command: parity error → ERRFL.PARERR; unknown address →
//!              ERRFL.INVCOMM; read ERRFL → its contents, then ERRFL cleared; else the register
//! ```
//! (ams AS5047P datasheet: "SPI Command Frame", "SPI Read Data Frame", "ERRFL", "DIAAGC".)
//! The angle register holds what [`Chip::angle`] was last set to, so an answer is as old as
//! the frame that asked for it, as on the real chip.

/// DIAAGC of a healthy sensor: offset compensation finished (LF, bit 8), AGC mid-scale.
pub const DIAAGC_OK: u16 = 0x0100 | 0x60;
/// DIAAGC with the magnet gone: MAGL (bit 11), AGC at its end (255).
pub const DIAAGC_NO_MAGNET: u16 = 0x0800 | 0xFF;

/// What the driver's MISO pin reads when nothing drives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    /// The sensor is connected.
    Connected,
    /// The cable is cut; MISO has its pull-up (docs/hardware.md): every bit reads 1.
    CutPulledUp,
    /// The cable is cut and MISO is pulled low (or floats low): every bit reads 0.
    CutPulledDown,
}

/// The chip's registers, its pending answer, and the faults a bench sees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Chip {
    /// ANGLECOM (14 bits): set by the simulation before each frame.
    pub angle: u16,
    /// DIAAGC (14 bits).
    pub diagnostics: u16,
    pub line: Line,
    /// Flip one bit of the next command on MOSI (motor noise): the chip sees a parity error.
    pub glitch_next_command: bool,
    errfl: u16,
    answer: u16,
}

impl Default for Chip {
    fn default() -> Self {
        Self {
            angle: 0,
            diagnostics: DIAAGC_OK,
            line: Line::Connected,
            glitch_next_command: false,
            errfl: 0,
            answer: 0,
        }
    }
}

impl Chip {
    /// The chip's error register now (bit 2 PARERR, bit 1 INVCOMM, bit 0 FRERR).
    pub fn errfl(&self) -> u16 {
        self.errfl
    }

    /// One 16-bit frame: the word on MISO for `mosi` sent.
    pub fn frame(&mut self, mosi: u16) -> u16 {
        let ef = if self.errfl != 0 { 0x4000 } else { 0 };
        let out = with_parity(ef | (self.answer & 0x3FFF));
        let cmd = if core::mem::take(&mut self.glitch_next_command) {
            mosi ^ 0x0100
        } else {
            mosi
        };
        if self.line == Line::Connected {
            self.execute(cmd);
        }
        match self.line {
            Line::Connected => out,
            Line::CutPulledUp => 0xFFFF,
            Line::CutPulledDown => 0x0000,
        }
    }

    fn execute(&mut self, cmd: u16) {
        if !cmd.count_ones().is_multiple_of(2) {
            self.errfl |= 0x4;
            self.answer = 0;
            return;
        }
        self.answer = match cmd & 0x3FFF {
            0x3FFF => self.angle & 0x3FFF,
            0x3FFC => self.diagnostics,
            0x0001 => core::mem::take(&mut self.errfl),
            0x0000 => 0,
            _ => {
                self.errfl |= 0x2;
                0
            }
        };
    }
}

/// `w` with bit 15 set so the 16 bits have even parity.
fn with_parity(w: u16) -> u16 {
    let w = w & 0x7FFF;
    if w.count_ones() % 2 == 1 {
        w | 0x8000
    } else {
        w
    }
}
