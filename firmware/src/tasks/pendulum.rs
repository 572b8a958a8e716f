//! The pendulum sensor: an AS5047P magnetic absolute encoder on SPI, read at the sample rate.
//!
//! ```text
//! command ANGLECOM (0x3FFF), read:  0xFFFF   (bit 15 even parity, bit 14 read)
//! answer (to the previous command): bit 15 even parity over all 16 bits, bit 14 error flag,
//!                                   bits 13..0 the angle, 2^14 counts per turn
//! θ = sign · (count − zero) · 2^18    (Angle: 2^32 per turn)
//! ```
//! Reading ANGLECOM continuously makes every frame both the next command and the previous
//! answer, so one 16-bit transfer per sample. A failed read repeats the last good angle and is
//! flagged in the sample (counted in the status).

use defmt::warn;
use embassy_time::{Duration, Instant, Ticker};
use kapitza_core::rig::fixed::Angle;

use crate::board::{PendulumBus, PENDULUM_SIGN, PENDULUM_ZERO};
use kapitza_core::station::Sample;

use crate::channels::{SAMPLES, SAMPLE_HZ};

/// Read ANGLECOM (0x3FFF) with the read bit and even parity.
const READ_ANGLE: u16 = 0xFFFF;

/// The angle count of an answer frame, if its parity is even and its error flag clear.
fn decode(word: u16) -> Option<u16> {
    (word.count_ones().is_multiple_of(2) && word & 0x4000 == 0).then_some(word & 0x3FFF)
}

fn angle_of(count: u16) -> Angle {
    let off = u32::from(count.wrapping_sub(PENDULUM_ZERO) & 0x3FFF) << 18;
    let a = Angle::from_turns_u32(off);
    if PENDULUM_SIGN < 0 {
        Angle::ZERO - a
    } else {
        a
    }
}

fn period(hz: u32) -> Duration {
    Duration::from_hz(u64::from(hz.max(1)))
}

#[embassy_executor::task]
pub async fn run(mut bus: PendulumBus, sample_hz: u32) {
    let mut hz = defmt::unwrap!(SAMPLE_HZ.receiver());
    let mut dt = period(sample_hz);
    let mut ticker = Ticker::every(dt);
    let mut last = Angle::ZERO;
    let mut prev = Instant::now();
    // Prime the pipeline: the first answer belongs to no command of ours.
    let _ = bus.transfer(READ_ANGLE);
    loop {
        ticker.next().await;
        if let Some(new) = hz.try_changed() {
            dt = period(new);
            ticker = Ticker::every(dt);
        }
        let now = Instant::now();
        let late = now.duration_since(prev) > dt + dt / 2;
        prev = now;
        let read = bus.transfer(READ_ANGLE).ok().and_then(decode);
        if let Some(c) = read {
            last = angle_of(c);
        }
        let s = Sample {
            t_us: now.as_micros() as u32,
            angle: last,
            failed: read.is_none(),
            late,
        };
        if SAMPLES.try_send(s).is_err() {
            // The control loop is behind by a whole queue: it will see `late` samples.
            warn!("pendulum: sample queue full");
        }
    }
}
