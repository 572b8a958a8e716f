//! What accuracy costs on the MCU: every arithmetic choice for the estimator's per-sample kernel
//! and the drive-waveform generator, its error against f64 and the instructions it executes per
//! update, measured on the emulated Cortex-M4F.
//!
//! Instruction counts: run under `-icount shift=0` (one guest instruction per ns of virtual
//! time), the SysTick counts the virtual processor clock, and a calibration loop of known length
//! gives instructions per SysTick count; each kernel runs thousands of times and the loop's own
//! cost (measured with an empty body) is subtracted. Errors: against f64 libm on the same inputs,
//! computed here on the target. Prints Markdown rows; `qemu/cost.sh` runs it and
//! `docs/accuracy-mcu.md` quotes the output.

#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::Rig;
use kapitza_core::rig::dds::{word_from_omega, Dds};
use kapitza_core::rig::estimator::period::PeriodAverager;
use kapitza_core::rig::estimator::period_f32::PeriodAveragerF32;
use kapitza_core::rig::estimator::{Estimator, Tuning};
use kapitza_core::rig::fixed::trig::{self, Micromath, PolyF32, Table};
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::rig::safety::Request;

const N_BUF: usize = 10_000;
const TAU: f64 = core::f64::consts::TAU;

fn now() -> u32 {
    SYST::get_current()
}

/// SysTick counts elapsed between two readings of the 24-bit down-counter.
fn ticks(t0: u32, t1: u32) -> u32 {
    t0.wrapping_sub(t1) & 0x00FF_FFFF
}

/// Instructions per SysTick count, from a loop of 2 instructions per iteration (`subs`, `bne`).
fn calibrate() -> f64 {
    let n: u32 = 1_000_000;
    let t0 = now();
    unsafe {
        core::arch::asm!("2:", "subs {0}, #1", "bne 2b", inout(reg) n => _, options(nomem, nostack));
    }
    let t1 = now();
    2.0 * f64::from(n) / f64::from(ticks(t0, t1))
}

/// Mean instructions per call of `f` over `n` calls, the empty loop subtracted.
fn per_call(k: f64, n: u32, mut f: impl FnMut(u32)) -> f64 {
    let t0 = now();
    for i in 0..n {
        black_box(i);
    }
    let t1 = now();
    for i in 0..n {
        f(black_box(i));
    }
    let t2 = now();
    let base = f64::from(ticks(t0, t1));
    let full = f64::from(ticks(t1, t2));
    (full - base) * k / f64::from(n)
}

/// A synthetic pendulum near the inverted position (where f32 resolution is coarsest):
/// slow oscillation about 3.0 rad, fast wobble 0.03 rad at ω = 313 rad/s, 14-bit quantisation.
fn fill(buf: &mut [(Angle, Angle)]) {
    let mut dds = Dds::new(10_000, u32::MAX);
    dds.set_target(word_from_omega(313.0).unwrap_or(0));
    for (k, s) in buf.iter_mut().enumerate() {
        let psi = dds.tick();
        let t = k as f64 * 1e-4;
        let th = 3.0 + 0.1 * libm::cos(8.0 * t) + 0.03 * libm::cos(psi.to_rad());
        let code = libm::round(th / TAU * 16_384.0) as i32;
        *s = (Angle::from_bits(code << 18), psi);
    }
}

/// The f64 reference of one period: mean and I/Q over samples [a, b) of the buffer.
fn reference(buf: &[(Angle, Angle)], a: usize, b: usize) -> (f64, f64, f64) {
    let start = buf[a].0;
    let (mut s, mut c, mut q) = (0.0, 0.0, 0.0);
    let mut u = 0.0;
    let mut prev = start;
    for &(th, psi) in &buf[a..b] {
        u += (th - prev).to_rad();
        prev = th;
        s += u;
        let (sn, cs) = libm::sincos(psi.to_rad());
        c += u * cs;
        q += u * sn;
    }
    let n = (b - a) as f64;
    (start.to_rad() + s / n, 2.0 * c / n, 2.0 * q / n)
}

/// Period boundaries of the buffer (indices where the drive phase wraps).
fn boundaries(buf: &[(Angle, Angle)], out: &mut [usize; 64]) -> usize {
    let mut n = 0;
    for k in 1..buf.len() {
        if buf[k].1.to_turns_u32() < buf[k - 1].1.to_turns_u32() && n < out.len() {
            out[n] = k;
            n += 1;
        }
    }
    n
}

fn wrap(x: f64) -> f64 {
    libm::remainder(x, TAU)
}

struct Errs {
    mean: f64,
    iq: f64,
}

/// Max errors of a kernel's period results against the f64 reference.
fn errors(buf: &[(Angle, Angle)], results: &[(f64, f64, f64)], b: &[usize]) -> Errs {
    let mut e = Errs { mean: 0.0, iq: 0.0 };
    // result j covers the period [b[j−1], b[j]) (the first complete one starts at b[0])
    for (j, r) in results.iter().enumerate().skip(1) {
        if j >= b.len() {
            break;
        }
        let (m, i, q) = reference(buf, b[j - 1], b[j]);
        e.mean = e.mean.max(wrap(r.0 - m).abs());
        e.iq = e.iq.max((r.1 - i).abs()).max((r.2 - q).abs());
    }
    e
}

fn trig_error(f: impl Fn(Angle) -> (f64, f64)) -> f64 {
    let mut worst: f64 = 0.0;
    for k in 0..4099u32 {
        let a = Angle::from_turns_u32(k.wrapping_mul(1_047_811));
        let (s, c) = f(a);
        let (es, ec) = libm::sincos(a.to_rad());
        worst = worst.max((s - es).abs()).max((c - ec).abs());
    }
    worst
}

struct DummyMotor {
    crank: Angle,
    step: Angle,
}
impl Motor for DummyMotor {
    fn crank_angle(&mut self) -> Angle {
        self.crank += self.step;
        self.crank
    }
    fn current(&mut self) -> Amps {
        Amps::from_num(0.5)
    }
    fn set_duty(&mut self, d: Duty) {
        black_box(d);
    }
}

#[entry]
fn main() -> ! {
    let mut cp = cortex_m::Peripherals::take().unwrap();
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();
    let k = calibrate();
    hprintln!("calibration: {:.3} instructions per SysTick count", k);

    let mut buf = [(Angle::ZERO, Angle::ZERO); N_BUF];
    fill(&mut buf);
    let mut b = [0usize; 64];
    let nb = boundaries(&buf, &mut b);
    let b = &b[..nb];

    hprintln!("| kernel | variant | instructions / update | max error vs f64 |");
    hprintln!("|---|---|---:|---|");

    // --- sin/cos alone
    let e = trig_error(|a| {
        let (s, c) = trig::sin_cos(a);
        (s.to_num(), c.to_num())
    });
    let i = per_call(k, 20_000, |n| {
        black_box(trig::sin_cos(Angle::from_bits(
            (n as i32).wrapping_mul(214_013),
        )));
    });
    hprintln!("| sin+cos | fixed Q30, polynomial | {:.1} | {:.1e} |", i, e);
    let e = trig_error(|a| {
        let (s, c) = trig::sin_cos_table(a);
        (s.to_num(), c.to_num())
    });
    let i = per_call(k, 20_000, |n| {
        black_box(trig::sin_cos_table(Angle::from_bits(
            (n as i32).wrapping_mul(214_013),
        )));
    });
    hprintln!(
        "| sin+cos | fixed Q30, 257-entry table | {:.1} | {:.1e} |",
        i,
        e
    );
    let e = trig_error(|a| {
        let (s, c) = trig::sin_cos_f32_poly(a);
        (f64::from(s), f64::from(c))
    });
    let i = per_call(k, 20_000, |n| {
        black_box(trig::sin_cos_f32_poly(Angle::from_bits(
            (n as i32).wrapping_mul(214_013),
        )));
    });
    hprintln!("| sin+cos | f32, polynomial | {:.1} | {:.1e} |", i, e);
    let e = trig_error(|a| {
        let (s, c) = trig::sin_cos_f32_micromath(a);
        (f64::from(s), f64::from(c))
    });
    let i = per_call(k, 20_000, |n| {
        black_box(trig::sin_cos_f32_micromath(Angle::from_bits(
            (n as i32).wrapping_mul(214_013),
        )));
    });
    hprintln!("| sin+cos | f32, micromath | {:.1} | {:.1e} |", i, e);
    let e = trig_error(|a| {
        let x = a.to_bits() as f32 * (core::f32::consts::TAU / 4_294_967_296.0);
        let (s, c) = libm::sincosf(x);
        (f64::from(s), f64::from(c))
    });
    let i = per_call(k, 20_000, |n| {
        let x =
            (n as i32).wrapping_mul(214_013) as f32 * (core::f32::consts::TAU / 4_294_967_296.0);
        black_box(libm::sincosf(x));
    });
    hprintln!("| sin+cos | f32, libm sincosf | {:.1} | {:.1e} |", i, e);

    let e = trig_error(|a| {
        let (s, c) = trig::sin_cos_cordic_model(a);
        (s.to_num(), c.to_num())
    });
    let i = per_call(k, 20_000, |n| {
        black_box(trig::sin_cos_cordic_model(Angle::from_bits(
            (n as i32).wrapping_mul(214_013),
        )));
    });
    hprintln!(
        "| sin+cos | CORDIC algorithm in software (24 iterations, 24-bit; error model for the unit) | {:.1} | {:.1e} |",
        i,
        e
    );

    // --- drive-waveform generator: phase + cos of the phase, per sample tick
    let mut dds = Dds::new(10_000, 62);
    dds.set_target(word_from_omega(313.0).unwrap_or(0));
    dds.advance(1_000_000);
    let mut d1 = dds;
    let i = per_call(k, 50_000, |_| {
        black_box(d1.tick());
    });
    hprintln!("| DDS tick | integer, exact phase | {:.1} | 0 (exact) |", i);
    let mut d2 = dds;
    let i = per_call(k, 50_000, |_| {
        black_box(trig::sin_cos(d2.tick()));
    });
    hprintln!(
        "| DDS tick + waveform | integer + Q30 polynomial | {:.1} | 4e-9 |",
        i
    );
    let mut d3 = dds;
    let i = per_call(k, 50_000, |_| {
        black_box(trig::sin_cos_table(d3.tick()));
    });
    hprintln!(
        "| DDS tick + waveform | integer + Q30 table | {:.1} | 5e-6 |",
        i
    );
    // f32 phase accumulator: φ += ω·dt, wrapped at 2π; error against the exact phase after 60 s.
    let w = 313.0f32;
    let dt = 1e-4f32;
    let mut ph = 0.0f32;
    let i = per_call(k, 50_000, |_| {
        ph += w * dt;
        if ph >= core::f32::consts::TAU {
            ph -= core::f32::consts::TAU;
        }
        black_box(micromath::F32(ph).cos());
    });
    let mut ph = 0.0f32;
    for _ in 0..600_000 {
        ph += w * dt;
        if ph >= core::f32::consts::TAU {
            ph -= core::f32::consts::TAU;
        }
    }
    let exact = wrap(f64::from(w) * 60.0);
    let drift = wrap(f64::from(ph) - exact).abs();
    hprintln!("| DDS tick + waveform | f32 accumulator + micromath cos | {:.1} | phase {:.1e} rad after 60 s (grows) |", i, drift);

    // --- estimator per-sample kernel: synchronous average + I/Q (period ends amortised)
    let mut res = [(0.0f64, 0.0f64, 0.0f64); 64];
    macro_rules! fixed_kernel {
        ($name:expr, $ty:ty) => {{
            let mut p: PeriodAverager<$ty> = PeriodAverager::with_trig();
            let i = per_call(k, N_BUF as u32, |n| {
                let (th, psi) = buf[n as usize];
                black_box(p.push(n * 100, th, psi));
            });
            let mut p: PeriodAverager<$ty> = PeriodAverager::with_trig();
            let mut m = 0;
            for (n, &(th, psi)) in buf.iter().enumerate() {
                if let Some(r) = p.push(n as u32 * 100, th, psi) {
                    let q20 = TAU / 1_048_576.0;
                    if m < res.len() {
                        res[m] = (r.mean.to_rad(), r.i as f64 * q20, r.q as f64 * q20);
                        m += 1;
                    }
                }
            }
            // the fixed averager skips the first period (no previous stamp): align with b[1..]
            let e = errors(&buf, &res[..m.min(res.len())], &b[1..]);
            hprintln!(
                "| estimator sample | {} | {:.1} | mean {:.1e} rad, I/Q {:.1e} rad |",
                $name,
                i,
                e.mean,
                e.iq
            );
        }};
    }
    fixed_kernel!("fixed, Q30 polynomial (the rig's)", trig::Poly);
    fixed_kernel!("fixed, Q30 table", Table);
    macro_rules! f32_kernel {
        ($name:expr, $ty:ty) => {{
            let mut p: PeriodAveragerF32<$ty> = PeriodAveragerF32::new();
            let i = per_call(k, N_BUF as u32, |n| {
                let (th, psi) = buf[n as usize];
                black_box(p.push(th, psi));
            });
            let mut p: PeriodAveragerF32<$ty> = PeriodAveragerF32::new();
            let mut m = 0;
            for &(th, psi) in buf.iter() {
                if let Some(r) = p.push(th, psi) {
                    if m < res.len() {
                        res[m] = (f64::from(r.mean), f64::from(r.i), f64::from(r.q));
                        m += 1;
                    }
                }
            }
            let e = errors(&buf, &res[..m.min(res.len())], b);
            hprintln!(
                "| estimator sample | {} | {:.1} | mean {:.1e} rad, I/Q {:.1e} rad |",
                $name,
                i,
                e.mean,
                e.iq
            );
        }};
    }
    f32_kernel!("f32, polynomial", PolyF32);
    f32_kernel!("f32, micromath", Micromath);

    // --- the whole estimator (per sample, slow updates amortised) and its worst single sample
    let cfg = RigConfig::REFERENCE;
    let mut est = Estimator::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(180.0));
    let i = per_call(k, N_BUF as u32, |n| {
        let (th, psi) = buf[n as usize];
        black_box(est.push(n * 100, th, psi));
    });
    let mut worst = 0u32;
    for rep in 0..3u32 {
        for (n, &(th, psi)) in buf.iter().enumerate() {
            let t = (rep * N_BUF as u32 + n as u32) * 100;
            let t0 = now();
            black_box(est.push(t, th, psi));
            worst = worst.max(ticks(t0, now()));
        }
    }
    hprintln!(
        "| estimator, whole | fixed (mean per sample) | {:.1} | see the closed-loop table |",
        i
    );
    hprintln!(
        "| estimator, whole | fixed (worst single sample, period end) | {:.0} | — |",
        f64::from(worst) * k
    );

    // --- the control tick: safety + drive target + phase lock, running steadily
    let mut rig = Rig::new(&cfg, &Tuning::DEFAULT, Angle::from_deg(90.0), 0);
    let _ = rig.request(Request::Start { omega: 313.0 });
    let step = Angle::from_bits(((313.0 / 1000.0 / TAU) * 4_294_967_296.0) as i32);
    let mut motor = DummyMotor {
        crank: Angle::ZERO,
        step,
    };
    let mut t = 0u32;
    for _ in 0..8_000 {
        t += 1000;
        rig.link_message(t);
        rig.control(t, &mut motor, false);
        for s in 0..10 {
            rig.sample(t + s * 100, Angle::ZERO);
        }
    }
    let i = per_call(k, 5_000, |n| {
        let tt = t + n * 1000;
        rig.link_message(tt);
        black_box(rig.control(tt, &mut motor, false));
    });
    hprintln!(
        "| control tick | fixed: safety + DDS target + phase lock | {:.1} | — |",
        i
    );

    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
}
