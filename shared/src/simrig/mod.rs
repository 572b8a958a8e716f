//! The simulated rig: the physics of a real bench around the same [`RigLoop`] the firmware
//! runs, stepped one pendulum sample at a time. The host tool serves it on a pseudo-terminal or
//! runs it in-process when no hardware is attached; the end-to-end tests drive it.
//!
//! | module | concept |
//! |---|---|
//! | [`plant`] | the pendulum driven by the crank's actual angle, the DC motor, friction |
//! | [`sensor`] | the pendulum sensor's chip behind its SPI pins (AS5047P), with its faults |
//! | [`hand`] | a lab hand that lifts and lets go of the pendulum when calibration asks for it |
//! | [`body`] | the actuator's body: the rod stays within 90° of the blade, a lossy contact |
//! | [`bridge`] | the H-bridge's supply through the e-stop's relay, its under-voltage nFAULT, TIM1's break |
//!
//! ```text
//! every sample period h = 1/fs:
//!   sensors → the AS5047P's register (14-bit angle with noise, its own zero and sign), read
//!             through the firmware's driver (rig::as5047) → Sample
//!   RigLoop::sample; when due RigLoop::control(crank counts, motor current, bridge lines,
//!                    e-stop) → duty (0 while the bridge sleeps or its break holds), θd
//!   the bridge: VM through the e-stop's relay; nFAULT low → TIM1's break cuts the outputs
//!   servo slews the mount toward θd at its own rate;  plant: one RK4 step of h;
//!   the body (if any) keeps the rod within 90° of the blade
//! ```
//! The true parameters ([`Params`]) may differ from the configuration the rig was given, the
//! way a real rig differs from what was typed in: the hidden ones (sensor zero and sign, crank
//! and motor direction, servo offset, current offset) are those calibration must find. The
//! hardware is the reference board's: the sensor's counts, the crank encoder as wired, the
//! current sense's ADC counts ([`Calibration::DEFAULT`]'s gain) and the servo's pulse
//! ([`ServoMap::REFERENCE`]) are produced from the truth and read back through the
//! *configured* calibration, so a mis-calibrated configuration is visibly off.
//! Everything is deterministic under [`Params::seed`].

pub mod body;
pub mod bridge;
pub mod hand;
pub mod plant;
pub mod sensor;

use crate::integrate::{rk4_step, Stats};
use crate::link::message::Counters;
use crate::math;
use crate::model::Geometry;
use crate::persist::ConfigOrigin;
use crate::rig::as5047::As5047;
use crate::rig::bridge::Lines;
use crate::rig::calibration::Calibration;
use crate::rig::config::RigConfig;
use crate::rig::fixed::{Angle, Duty};
use crate::rig::servo::ServoMap;
use crate::sim::noise::Noise;
use crate::station::drive::Drive;
use crate::station::serve::Activity;
use crate::station::{RigLoop, Sample};
use body::Body;
use bridge::Bridge;
use hand::Hand;
use plant::{MotorModel, Plant};
use sensor::{Chip, Line};

/// Crank encoder counts per turn (a power of two, as the firmware's board constant).
pub const CRANK_COUNTS: u32 = 4096;
/// Pendulum sensor bits per turn (AS5047P: 14).
pub const SENSOR_BITS: u32 = 14;

/// The true rig: what the bench really is, whatever the configuration says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    pub geometry: Geometry,
    pub gravity: f64,
    /// The crank radius A (m).
    pub amplitude: f64,
    /// The slider-crank's connecting rod b (m), for the second harmonic; `None`: a pure sine.
    pub connecting_rod: Option<f64>,
    /// Viscous damping c (1/s) and Coulomb friction μ (rad/s²).
    pub damping: f64,
    pub coulomb: f64,
    pub motor: MotorModel,
    /// Sensor noise (rad, standard deviation) before the 14-bit quantisation.
    pub sensor_noise: f64,
    /// Where the sensor reads zero (rad from hanging) and +1/−1 for its direction.
    pub sensor_zero: f64,
    pub sensor_sign: f64,
    /// +1/−1: the crank encoder counts with the crank, or against it (swapped channels).
    pub crank_sign: f64,
    /// The servo's speed (deg/s) and the mount's true angle minus the commanded one (deg).
    pub servo_rate_deg: f64,
    pub servo_offset_deg: f64,
    /// The current sensor's reading at zero current (A).
    pub current_offset: f64,
    /// The crank is jammed: the motor cannot turn it.
    pub stalled: bool,
    /// The pendulum sensor's cable: connected, or cut.
    pub sensor_line: Line,
    /// The pendulum's angle (rad) at power-up, at rest.
    pub theta0: f64,
    /// A lab hand ([`hand`]): the angle counter-clockwise of hanging (rad) it lifts the
    /// pendulum to and lets go from whenever the rig enters bring-up mode with the motor off;
    /// `None`: nobody at the rig.
    pub hand: Option<f64>,
    /// The actuator's body ([`body`]); `None`: a rig without one, where the rod swings freely.
    pub body: Option<Body>,
    pub seed: u64,
}

impl Params {
    /// The demo rod of physics §4 (L = 0.25 m, A = 12.7 mm), damped to Q = 10 (c = ω0/Q with
    /// ω0 = √(3g/2L) = 7.672 rad/s), on the default motor, a quiet sensor (0.02°) and a fast
    /// servo, hanging at rest, its actuator's body in place.
    pub const DEMO: Self = Self {
        geometry: Geometry::Rod { length: 0.25 },
        gravity: 9.81,
        amplitude: 0.0127,
        connecting_rod: None,
        damping: 0.7672,
        coulomb: 0.0,
        motor: MotorModel::DEFAULT,
        sensor_noise: 3.5e-4,
        sensor_zero: 0.0,
        sensor_sign: 1.0,
        crank_sign: 1.0,
        servo_rate_deg: 300.0,
        servo_offset_deg: 0.0,
        current_offset: 0.0,
        stalled: false,
        sensor_line: Line::Connected,
        theta0: 0.0,
        hand: None,
        body: Some(Body::DEFAULT),
        seed: 1,
    };

    /// The rig configuration a careful user would type for this rig: the reference limits and
    /// motor tuning with this rig's own pendulum, stroke and gravity.
    pub fn configured(&self) -> RigConfig {
        RigConfig {
            amplitude: self.amplitude,
            connecting_rod: self.connecting_rod.unwrap_or(0.0),
            geometry: self.geometry,
            gravity: self.gravity,
            ..RigConfig::REFERENCE
        }
    }
}

/// A whole simulated rig.
#[derive(Debug, Clone)]
pub struct SimRig {
    params: Params,
    rig: RigLoop,
    plant: Plant,
    y: [f64; 4],
    noise: Noise,
    /// Samples since power-up.
    k: u64,
    /// The servo's commanded position (deg along the travel).
    servo_target_deg: f64,
    servo_deg: f64,
    pub estop: bool,
    /// The H-bridge and TIM1's break; its supply can be made to sag.
    pub bridge: Bridge,
    chip: Chip,
    driver: As5047,
    /// The last good count (a failed read repeats it, as the firmware does).
    held: u16,
    stats: Stats,
    hand: Option<Hand>,
}

impl SimRig {
    /// The rig `params` configured with `cfg` (validated by the caller, as flash would hold it),
    /// powered up at its clock's 0, the mount at θd = 0.
    pub fn new(params: Params, cfg: RigConfig, origin: ConfigOrigin, firmware: [u16; 3]) -> Self {
        let ell = params.geometry.equivalent_length();
        let second = params
            .connecting_rod
            .map_or(0.0, |b| params.amplitude * params.amplitude / (4.0 * b));
        let servo0 = 0f64.clamp(
            cfg.limits.drive_angle_min_deg,
            cfg.limits.drive_angle_max_deg,
        );
        let plant = Plant {
            omega0_sq: params.gravity / ell,
            ell,
            amplitude: params.amplitude,
            second,
            damping: params.damping,
            coulomb: params.coulomb,
            theta_d: math::to_rad(servo0 + params.servo_offset_deg),
            motor: params.motor,
            duty: 0.0,
            jammed: params.stalled,
        };
        let mut s = Self {
            rig: RigLoop::new(cfg, origin, Angle::from_deg(servo0), 0, firmware),
            plant,
            y: [params.theta0, 0.0, 0.0, 0.0],
            noise: Noise::new(params.seed),
            k: 0,
            servo_target_deg: servo0,
            servo_deg: servo0,
            estop: false,
            bridge: Bridge::default(),
            chip: Chip::default(),
            driver: As5047::new(),
            held: 0,
            stats: Stats::default(),
            hand: params.hand.map(Hand::new),
            params,
        };
        s.chip.line = params.sensor_line;
        if let Some(body) = &params.body {
            body.contact(&mut s.y, s.plant.theta_d, 0.0);
        }
        // Prime the sensor's pipeline as the firmware does at power-up: the first answer
        // belongs to no command.
        s.chip.angle = s.sensor_code();
        let chip = &mut s.chip;
        s.driver.sample(0, |w| Ok::<u16, ()>(chip.frame(w)));
        s
    }

    /// The same rig speaking link protocol `version`: for tests of version skew
    /// ([`RigLoop::speaking`]).
    pub fn speaking(mut self, version: u8) -> Self {
        self.rig = self.rig.speaking(version);
        self
    }

    /// The same rig booted after a reset of `reset` (a crash's cause and PC, say), reported in
    /// its status as the firmware reports its own ([`RigLoop::after_reset`]).
    pub fn after_reset(mut self, reset: crate::link::message::ResetInfo) -> Self {
        self.rig = self.rig.after_reset(reset);
        self
    }

    /// Seconds since power-up.
    pub fn seconds(&self) -> f64 {
        self.k as f64 / f64::from(self.rig.sample_hz())
    }

    /// The rig's µs clock (wrapping).
    pub fn t_us(&self) -> u32 {
        (self.k * 1_000_000 / u64::from(self.rig.sample_hz())) as u32
    }

    /// One sample period. `link_us` is the link's clock; `None`: the rig's own.
    pub fn step(&mut self, link_us: Option<u32>) {
        let t_us = self.t_us();
        self.chip.angle = self.sensor_code();
        let chip = &mut self.chip;
        let read = self.driver.sample(t_us, |w| Ok::<u16, ()>(chip.frame(w)));
        if let Ok(count) = read.count {
            self.held = count;
        }
        let s = Sample {
            t_us: read.t_us,
            count: self.held,
            failed: read.count.is_err(),
            late: false,
            sensor_failed: self.driver.health().failed(),
            diagnostics: self.driver.health().diagnostics,
        };
        self.bridge.update(self.estop);
        if self.rig.sample(s) {
            let mut hw = Hardware {
                plant: &mut self.plant,
                y: &self.y,
                crank_sign: self.params.crank_sign,
                current_offset: self.params.current_offset,
                bridge: &mut self.bridge,
            };
            let tick = self
                .rig
                .control(link_us.unwrap_or(t_us), &mut hw, Some(self.estop));
            self.bridge.set_awake(tick.bridge);
            if let Some(us) = tick.servo_us {
                self.servo_target_deg = ServoMap::REFERENCE.deg_of_pulse(us);
            }
            if let Some(req) = tick.store {
                // The simulated flash always takes the write.
                self.rig.config_saved(req.tag, true);
            }
        }
        if !self.bridge.driving() {
            self.plant.duty = 0.0;
        }
        let h = 1.0 / f64::from(self.rig.sample_hz());
        let theta_d_before = self.plant.theta_d;
        self.slew_servo(h);
        self.y = rk4_step(&self.plant, self.seconds(), &self.y, h, &mut self.stats);
        if let Some(body) = &self.params.body {
            let rate = (self.plant.theta_d - theta_d_before) / h;
            body.contact(&mut self.y, self.plant.theta_d, rate);
        }
        self.lend_a_hand();
        self.k += 1;
    }

    /// The lab hand, if there is one: armed while the rig is in bring-up mode with the motor
    /// off (where calibration asks for a release), it holds the pendulum while it lifts it.
    fn lend_a_hand(&mut self) {
        let t = self.seconds();
        let Some(hand) = &mut self.hand else {
            return;
        };
        let armed = matches!(
            self.rig.server().activity,
            Activity::BringUp { duty } if duty == Duty::ZERO
        );
        if let Some(theta) = hand.step(t, armed, self.y[0]) {
            self.y[0] = theta;
            self.y[1] = 0.0;
        }
    }

    /// Runs `secs` of rig time with the link's clock the rig's own.
    pub fn run(&mut self, secs: f64) {
        let n = libm::round(secs * f64::from(self.rig.sample_hz())) as u64;
        for _ in 0..n {
            self.step(None);
        }
    }

    /// Bytes from the laptop (`link_us`: the link's clock; `None`: the rig's own).
    pub fn receive(&mut self, bytes: &[u8], link_us: Option<u32>) {
        let t = self.t_us();
        self.rig.receive(bytes, link_us.unwrap_or(t));
    }

    /// Bytes for the laptop: as many queued frame bytes as fit in `out`.
    pub fn transmit(&mut self, out: &mut [u8]) -> usize {
        self.rig.transmit(out)
    }

    pub fn rig(&self) -> &RigLoop {
        &self.rig
    }

    /// The pendulum's true angle (rad from hanging) and the mount's true drive angle (rad): what
    /// the sensor and the servo map only approximate, for tests that judge the rig's read-out.
    pub fn truth(&self) -> (f64, f64) {
        (self.y[0], self.plant.theta_d)
    }

    pub fn counters(&self) -> &Counters {
        self.rig.counters()
    }

    /// The pendulum sensor's chip and its line, to break them.
    pub fn sensor(&mut self) -> &mut Chip {
        &mut self.chip
    }

    /// The pendulum sensor's angle register: its own zero and direction, noise, 14 bits.
    fn sensor_code(&mut self) -> u16 {
        let p = &self.params;
        let seen =
            p.sensor_sign * (self.y[0] - p.sensor_zero) + p.sensor_noise * self.noise.gaussian();
        let counts = f64::from(1u32 << SENSOR_BITS);
        let code = libm::round(seen / math::TAU * counts) as i64;
        code.rem_euclid(1 << SENSOR_BITS) as u16
    }

    /// The servo moves the mount toward its commanded position at its own rate.
    fn slew_servo(&mut self, h: f64) {
        let step = self.params.servo_rate_deg * h;
        let d = self.servo_target_deg - self.servo_deg;
        self.servo_deg += d.clamp(-step, step);
        self.plant.theta_d = math::to_rad(self.servo_deg + self.params.servo_offset_deg);
    }
}

/// The drive hardware as the rig loop sees it.
struct Hardware<'a> {
    plant: &'a mut Plant,
    y: &'a [f64; 4],
    crank_sign: f64,
    current_offset: f64,
    bridge: &'a mut Bridge,
}

impl Drive for Hardware<'_> {
    fn crank_raw(&mut self) -> Angle {
        let counts = libm::floor(self.crank_sign * self.y[2] / math::TAU * f64::from(CRANK_COUNTS));
        let count = (counts as i64).rem_euclid(i64::from(CRANK_COUNTS)) as u32;
        Angle::from_turns_u32(count * (u32::MAX / CRANK_COUNTS + 1))
    }
    /// The DRV8874's current mirror gives the magnitude; the ADC adds the offset.
    fn current_counts(&mut self) -> u16 {
        let i = libm::fabs(self.plant.motor.current(self.plant.duty, self.y[3]));
        Calibration::DEFAULT
            .current_sense()
            .counts(i + self.current_offset)
    }
    fn set_duty(&mut self, duty: Duty) {
        self.plant.duty = duty.to_num();
    }
    fn bridge_lines(&mut self) -> Lines {
        Lines {
            nfault_low: self.bridge.nfault_low(),
            break_flag: self.bridge.break_flag(),
        }
    }
    fn rearm(&mut self) {
        self.bridge.rearm();
    }
}
