//! The independent watchdog's timeout, from the control period and the longest step that keeps
//! the thread executor (which feeds the watchdog after each control tick) from running.
//!
//! ```text
//! t_block = t_ERASE(page, max) + 256 · t_prog(64 bit, max)
//!         = 24.47 ms + 256 · 90.76 µs = 47.705 ms                              [1]
//!           (a 2 KiB page erased and programmed in full, by double words; embassy-stm32's
//!            blocking erase and write busy-wait on the thread executor throughout)
//! gap     = T + t_block + T    the longest time between two feeds: up to one period since
//!                              the last feed when the step starts, the step, then up to one
//!                              period for the next tick's heartbeat to reach the feed
//! need    = max(3 T, gap)      at least three control periods, T = 1 / control_hz
//! timeout = need · 34 / 32 kHz + 1 ms
//!           the driver counts in nominal 32 kHz LSI ticks; the LSI runs up to 34 kHz [2], which
//!           expires the watchdog after 32/34 of the time asked for; the driver also rounds its
//!           reload down, by less than one count (4 / 32 kHz = 125 µs below 512 ms) [3]
//! ```
//! Between the control rate's floor (100 Hz, [`super::fields::BOUNDS`]) and its ceiling the
//! need runs from 67.7 ms to 47.9 ms: the page step dominates every admitted rate. The firmware
//! programs [`TIMEOUT_US`], the timeout of the floor, which covers every configuration that
//! validation admits; so a `SetConfig` never has to reprogram the watchdog (which would race
//! the very store it triggers), at the price of ≤ 20 ms more before a hung loop is reset.
//!
//! [1] STM32G474xB/xC/xE datasheet (DS12288), "Flash memory characteristics": tERASE (page,
//!     2 KB) max 24.47 ms, tprog (64-bit) max 90.76 µs.
//! [2] DS12288, "LSI oscillator characteristics": fLSI 29.5 – 34 kHz over voltage and
//!     temperature.
//! [3] embassy-stm32 0.6 `wdg::IndependentWatchdog::new` (prescaler, reload from 32 kHz).

use super::fields::{bound, Field};

/// A 2 KiB page's erase and program, worst case (µs) [1].
pub const BLOCK_US: u32 = 24_470 + (256 * 9_076u32).div_ceil(100);
/// The slowest LSI over the one the driver assumes, as a ratio (kHz) [2].
const LSI_MAX_KHZ: u64 = 34;
const LSI_NOMINAL_KHZ: u64 = 32;
/// Room for the driver's rounding of its reload [3].
const ROUNDING_US: u32 = 1_000;

/// The slowest control rate the configuration's range admits (Hz).
pub fn control_hz_floor() -> u32 {
    bound(Field::ControlHz).lo.value() as u32
}

/// The watchdog timeout to program (µs) for a control rate (Hz, at least 1).
pub const fn timeout_us(control_hz: u32) -> u32 {
    let hz = if control_hz == 0 { 1 } else { control_hz };
    let period = 1_000_000u32.div_ceil(hz);
    let three = 3 * period;
    let gap = BLOCK_US + 2 * period;
    let need = if three > gap { three } else { gap } as u64;
    ((need * LSI_MAX_KHZ).div_ceil(LSI_NOMINAL_KHZ)) as u32 + ROUNDING_US
}

/// The timeout the firmware programs: that of the slowest admitted control rate.
pub const TIMEOUT_US: u32 = timeout_us(100);

#[cfg(test)]
mod tests {
    use super::*;

    /// embassy-stm32 0.6's IWDG set-up (wdg/mod.rs), restated: the smallest prescaler whose
    /// 12-bit reload reaches the timeout, the reload rounded down, both from 32 kHz; the
    /// period it gives when the LSI actually runs at `lsi_hz`.
    fn driver_period_us(timeout_us: u32, lsi_hz: u64) -> u64 {
        let psc = (2..=8u32)
            .map(|p| 1u64 << p)
            .find(|&psc| u64::from(timeout_us) <= 1_000_000 * 4096 / (32_000 / psc))
            .unwrap();
        let rl = u64::from(timeout_us) / psc * 32_000 / 1_000_000 - 1;
        (rl + 1) * psc * 1_000_000 / lsi_hz
    }

    #[test]
    fn floor_is_the_range_table_and_covers_every_rate() {
        assert_eq!(control_hz_floor(), 100);
        assert_eq!(TIMEOUT_US, timeout_us(control_hz_floor()));
        let hi = bound(Field::ControlHz).hi.value() as u32;
        for hz in control_hz_floor()..=hi {
            let t = timeout_us(hz);
            assert!(t <= TIMEOUT_US, "{hz} Hz: {t} µs");
            // With the LSI at its fastest, the driver's period still spans three control
            // periods and the page step between two feeds.
            let period = 1e6 / f64::from(hz);
            let real = driver_period_us(t, 34_000) as f64;
            assert!(real >= 3.0 * period, "{hz} Hz");
            assert!(real >= f64::from(BLOCK_US) + 2.0 * period, "{hz} Hz");
        }
    }

    #[test]
    fn timeouts_from_the_datasheet_figures() {
        // 24.47 ms + 256 · 90.76 µs = 47.70456 ms, rounded up to the µs [1].
        assert_eq!(BLOCK_US, 47_705);
        // 100 Hz: (47.705 + 20) ms · 34/32 + 1 ms = 72.9366 ms, rounded up.
        assert_eq!(timeout_us(100), 72_937);
        // 1 kHz: (47.705 + 2) ms · 34/32 + 1 ms = 53.8116 ms, rounded up.
        assert_eq!(timeout_us(1_000), 53_812);
        // 1 Hz (below the floor, where three periods dominate): 3 s · 34/32 + 1 ms = 3.1885 s.
        assert_eq!(timeout_us(1), 3_188_500);
        assert_eq!(timeout_us(0), timeout_us(1));
    }
}
