//! The closed-loop harness: the rig logic (`kapitza_core::rig::controller::Rig`) stepped in
//! virtual time against the simulated rig's physics (`kapitza_core::simrig::plant`), with the
//! test's own hand on the pendulum (`hold`) and its own schedule of link messages, which the
//! product's `SimRig` (behind the full rig loop) does not offer. Sensors: the pendulum encoder
//! quantises to 14 bits after Gaussian noise (`kapitza_core::sim::noise`, seeded); the crank
//! encoder to 4096 counts per turn.

use kapitza_core::integrate::{rk4_step, Stats};
use kapitza_core::math;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::controller::{ControlReport, Rig};
use kapitza_core::rig::estimator::Tuning;
use kapitza_core::rig::fixed::{Amps, Angle, Duty};
use kapitza_core::rig::phase_lock::Motor;
use kapitza_core::sim::noise::Noise;
use kapitza_core::simrig::plant::{MotorModel, Plant};

/// Quantises an angle to `bits` per turn and returns it as an [`Angle`].
pub fn quantise(theta: f64, bits: u32) -> Angle {
    let code = (theta / math::TAU * f64::from(1u32 << bits)).round() as i64;
    Angle::from_bits(((code as u64) << (32 - bits)) as u32 as i32)
}

/// The simulated hardware seen through the `Motor` trait.
pub struct SimMotor<'a> {
    pub plant: &'a mut Plant,
    pub state: &'a [f64; 4],
}

impl Motor for SimMotor<'_> {
    fn crank_angle(&mut self) -> Angle {
        quantise(self.state[2], 12)
    }
    fn current(&mut self) -> Amps {
        Amps::saturating_from_num(self.plant.motor.current(self.plant.duty, self.state[3]))
    }
    fn set_duty(&mut self, duty: Duty) {
        self.plant.duty = duty.to_num();
    }
}

/// A whole simulated rig: plant, sensors, the rig logic, virtual time.
pub struct Sim {
    pub cfg: RigConfig,
    pub rig: Rig,
    pub plant: Plant,
    pub y: [f64; 4],
    pub noise: Noise,
    pub noise_rad: f64,
    pub sensor_bits: u32,
    /// Samples since the start; virtual time t = k / fs.
    pub k: u64,
    pub t0_us: u32,
    /// While set, the pendulum is held at this angle (the lecturer's hand).
    pub hold: Option<f64>,
    pub estop: bool,
    /// Send a link message every this many control ticks (None: the laptop is silent).
    pub heartbeat_every: Option<u64>,
    pub last: Option<ControlReport>,
    pub stats: Stats,
}

impl Sim {
    pub fn new(cfg: RigConfig, theta_d_deg: f64, damping: f64, theta0: f64, t0_us: u32) -> Self {
        let cfg = cfg.validate().unwrap();
        let theta_d = Angle::from_deg(theta_d_deg);
        let rig = Rig::new(&cfg, &Tuning::DEFAULT, theta_d, t0_us);
        let plant = Plant {
            omega0_sq: cfg.gravity / cfg.ell(),
            ell: cfg.ell(),
            amplitude: cfg.amplitude,
            second: 0.0,
            damping,
            coulomb: 0.0,
            theta_d: theta_d.to_rad(),
            motor: MotorModel::DEFAULT,
            duty: 0.0,
            jammed: false,
        };
        Self {
            cfg,
            rig,
            plant,
            y: [theta0, 0.0, 1.0, 0.0],
            noise: Noise::new(0x5EED_1234 ^ theta_d_deg.to_bits()),
            noise_rad: 2e-4,
            sensor_bits: 14,
            k: 0,
            t0_us,
            hold: Some(theta0),
            estop: false,
            heartbeat_every: Some(100),
            last: None,
            stats: Stats::default(),
        }
    }

    pub fn t_us(&self) -> u32 {
        let per = 1_000_000 / u64::from(self.cfg.sample_hz);
        self.t0_us.wrapping_add((self.k * per) as u32)
    }

    pub fn seconds(&self) -> f64 {
        self.k as f64 / f64::from(self.cfg.sample_hz)
    }

    /// One sample period: control tick when due, sensor sample, plant step.
    pub fn step(&mut self) {
        let t = self.t_us();
        let per_ctrl = u64::from(self.cfg.sample_hz / self.cfg.control_hz);
        if self.k.is_multiple_of(per_ctrl) {
            let tick = self.k / per_ctrl;
            if let Some(every) = self.heartbeat_every {
                if tick.is_multiple_of(every) {
                    self.rig.link_message(t);
                }
            }
            let y = self.y;
            let mut m = SimMotor {
                plant: &mut self.plant,
                state: &y,
            };
            let rep = self.rig.control(t, &mut m, self.estop);
            self.plant.theta_d = rep.theta_d.to_rad();
            self.last = Some(rep);
        }
        let meas = self.y[0] + self.noise_rad * self.noise.gaussian();
        self.rig.sample(t, quantise(meas, self.sensor_bits));
        let h = 1.0 / f64::from(self.cfg.sample_hz);
        let y = rk4_step(&self.plant, self.seconds(), &self.y, h, &mut self.stats);
        self.y = y;
        if self.plant.jammed {
            self.y[3] = 0.0;
        }
        if let Some(th) = self.hold {
            // The hand holds the slow angle and lets the fast wobble happen (first-order wobble
            // ξ = (A/ℓ) sin(φ − θd) cos ψ, physics §3), so letting go does not kick the pendulum.
            let k = self.plant.amplitude / self.plant.ell * math::sin(th - self.plant.theta_d);
            let (sp, cp) = math::sin_cos(self.y[2]);
            self.y[0] = th + k * cp;
            self.y[1] = -k * self.y[3] * sp;
        }
        self.k += 1;
    }

    /// Runs for `secs` of virtual time.
    pub fn run(&mut self, secs: f64) {
        let n = (secs * f64::from(self.cfg.sample_hz)).round() as u64;
        for _ in 0..n {
            self.step();
        }
    }

    /// Runs until `pred` holds (checked every control tick) or `secs` pass; returns whether it held.
    pub fn run_until(&mut self, secs: f64, mut pred: impl FnMut(&Sim) -> bool) -> bool {
        let n = (secs * f64::from(self.cfg.sample_hz)).round() as u64;
        for i in 0..n {
            self.step();
            if i % 10 == 0 && pred(self) {
                return true;
            }
        }
        false
    }
}
