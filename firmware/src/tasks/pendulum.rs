//! The pendulum sensor: an AS5047P on SPI, read at the sample rate.
//!
//! The frames, the error flag and its clearing read, the diagnostics and the sensor's health
//! are `kapitza_core::rig::as5047`, the count → angle map the rig loop's (with the
//! configuration's calibration); this task keeps the sample clock and moves the words. The
//! clock carries the tick's remainder (`kapitza_core::station::clock`), so a rate that does not
//! divide embassy-time's 1 MHz tick (12 kHz) is exact on average. Missed sample times are
//! skipped, never caught up in a burst, and the sample after a skip is marked late (an overrun
//! in the status). Each sample carries the time its angle was latched (the frame before).

use embassy_time::{Instant, Timer, TICK_HZ};
use kapitza_core::rig::as5047::As5047;
use kapitza_core::station::clock::SampleClock;
use kapitza_core::station::Sample;

use crate::board::PendulumBus;
use crate::channels::{SAMPLES, SAMPLE_HZ};

#[embassy_executor::task]
pub async fn run(mut bus: PendulumBus, sample_hz: u32) {
    let mut hz = defmt::unwrap!(SAMPLE_HZ.receiver());
    let mut sensor = As5047::new();
    let mut held = 0u16;
    let mut late = false;
    // The sensor answers 10 ms after its supply comes up (AS5047P datasheet, "power-up time"
    // tPwrUp); frames before that would count towards a sensor fault at every boot.
    Timer::after_millis(10).await;
    // Prime the pipeline: the first answer belongs to no command of ours.
    let t0 = Instant::now();
    sensor.sample(t0.as_micros() as u32, |w| bus.transfer(w));
    let mut clock = SampleClock::new(t0.as_ticks(), TICK_HZ, sample_hz);
    loop {
        let (due, skipped) = clock.advance(Instant::now().as_ticks());
        late |= skipped > 0;
        Timer::at(Instant::from_ticks(due)).await;
        if let Some(new) = hz.try_changed() {
            clock.set_rate(new);
        }
        let read = sensor.sample(Instant::now().as_micros() as u32, |w| bus.transfer(w));
        if let Ok(count) = read.count {
            held = count;
        }
        let s = Sample {
            t_us: read.t_us,
            count: held,
            failed: read.count.is_err(),
            late,
            sensor_failed: sensor.health().failed(),
            diagnostics: sensor.health().diagnostics,
        };
        // A full queue means the control loop is behind: the sample is lost and the next one
        // says so (no log line here: this runs 10 000 times a second).
        late = SAMPLES.try_send(s).is_err();
    }
}
