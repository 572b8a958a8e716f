//! The rig loop end to end, bytes in and bytes out, as a deterministic scenario with a digest:
//! run by the host tests (`shared/tests/rig_selftest.rs`) and on the emulated Cortex-M4F
//! (`qemu/`) against the same expected digest, so the firmware's loop computes the same bits on
//! the target as the simulated rig does on the laptop. The digest and its regeneration are
//! [`super::rig`]'s.

use super::rig::{Case, Digest};
use crate::link::frame::{encode, Header};
use crate::link::{Request, MAX_REQUEST_FRAME};
use crate::persist::ConfigOrigin;
use crate::rig::as5047::Diagnostics;
use crate::rig::config::RigConfig;
use crate::rig::fixed::{Angle, Duty};
use crate::station::drive::Drive;
use crate::station::{RigLoop, Sample};

/// A crank that follows the duty with a first-order lag, in integers (0.9 · 500 rad/s at full
/// duty, τ = 60 ms, 1 ms steps), and a current sense reading 6/77 of the duty in counts.
struct Crank {
    angle: Angle,
    speed_q16: i64,
    duty: i64,
}

impl Drive for Crank {
    fn crank_raw(&mut self) -> Angle {
        self.angle
    }
    fn current_counts(&mut self) -> u16 {
        (self.duty.abs() * 6 / 77) as u16
    }
    fn set_duty(&mut self, d: Duty) {
        self.duty = i64::from(d.to_bits());
    }
}

impl Crank {
    fn step(&mut self) {
        self.speed_q16 += (self.duty * 900 - self.speed_q16) / 60;
        self.angle += Angle::from_bits(((self.speed_q16 * 10_430) / 1_000_000) as i32);
    }
}

fn frame(seq: u8, req: &Request, d: &mut [u8; MAX_REQUEST_FRAME]) -> usize {
    encode(Header::new(seq), req, d).unwrap_or(0)
}

/// A conversation with the reference rig through its rig loop: version, a drive (after its
/// pre-run check), telemetry, a damaged frame, a refused drive, the same configuration again, a
/// stop — 8 s of samples at 10 kHz with a synthetic pendulum; the digest covers every byte the
/// loop sends.
fn rig_loop_conversation() -> u64 {
    let cfg = RigConfig::REFERENCE;
    let mut rig = RigLoop::new(
        cfg,
        ConfigOrigin::Stored,
        Angle::from_deg(0.0),
        0,
        [0, 1, 0],
    );
    let mut crank = Crank {
        angle: Angle::from_deg(10.0),
        speed_q16: 0,
        duty: 0,
    };
    let mut d = Digest::default();
    let mut buf = [0u8; MAX_REQUEST_FRAME];
    let mut out = [0u8; 64];
    let mut t: u32 = 4_294_000_000; // the µs clock wraps during the run
    for k in 0..80_000u32 {
        let ms = k / 10;
        if k % 10 == 0 {
            let req = match ms {
                5 => Some(Request::GetVersion),
                10 => Some(Request::SetDrive {
                    r: 2 << 16,
                    theta_d_deg: 45 << 16,
                }),
                11 => Some(Request::Telemetry { period_ms: 50 }),
                3_000 => Some(Request::SetDrive {
                    r: 9 << 16,
                    theta_d_deg: 45 << 16,
                }),
                4_000 => Some(Request::SetConfig(cfg.into())),
                6_000 => Some(Request::Stop),
                7_500 => Some(Request::GetStatus),
                _ => None,
            };
            if let Some(r) = req {
                let n = frame((ms % 250) as u8 + 1, &r, &mut buf);
                rig.receive(&buf[..n], t);
            }
            if ms == 2_000 {
                let n = frame(9, &Request::GetStatus, &mut buf);
                buf[n / 2] ^= 0x40;
                rig.receive(&buf[..n], t);
            }
        }
        let x = f64::from(k) * 1e-4;
        let th = 0.7
            + 0.2 * libm::exp(-0.4 * x) * libm::cos(8.0 * x)
            + 0.03 * libm::cos(crank.angle.to_rad());
        let due = rig.sample(Sample {
            t_us: t,
            count: (libm::round(th / crate::math::TAU * 16_384.0) as i64).rem_euclid(16_384) as u16,
            failed: k % 997 == 0,
            late: false,
            sensor_failed: false,
            diagnostics: Some(Diagnostics::HEALTHY),
        });
        if due {
            let tick = rig.control(t, &mut crank, Some(false));
            d.u32(u32::from(tick.bridge));
            d.i32(tick.report.duty.to_bits().into());
            crank.step();
        }
        loop {
            let n = rig.transmit(&mut out);
            if n == 0 {
                break;
            }
            d.bytes(&out[..n]);
        }
        t = t.wrapping_add(100);
    }
    d.finish()
}

/// Every scenario of the rig loop, in order.
pub const CASES: &[Case] = &[Case {
    name: "rig_loop_conversation",
    run: rig_loop_conversation,
    expected: 0x2288_21ae_9278_5160,
}];
