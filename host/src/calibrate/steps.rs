//! The steps. Each says what it asks of the person, records, hands the record to
//! `kapitza_core::calib`, refuses (with the measurement's own reason) when that is implausible,
//! and otherwise changes the configuration it carries; [`Calibrator::write`] stores it.

use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Result};
use kapitza_core::calib::{current, direction, plumb, ringdown, servo_fit, stroke, CalibError};
use kapitza_core::link::convert::from_q16;
use kapitza_core::link::message::Mode;
use kapitza_core::math;
use kapitza_core::model::Geometry;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::rig::fixed::Angle;

use super::operator::Operator;
use super::record;
use super::watch::Watch;
use super::{Step, StepReport};
use crate::rig::session::Session;
use crate::rig::{Exit, Failure};

/// Sensor counts per turn (AS5047P, 14 bits) and crank encoder counts per turn.
const SENSOR_COUNTS: f64 = 16_384.0;
const CRANK_COUNTS: u32 = 4096;
/// A ring-down's length (rig seconds) after the release: 12 periods of the demo rod.
const RING_S: f64 = 25.0;
/// The crank pulse: duty and length (s), and the counts it must move (≈ 4.4°).
const PULSE_DUTY: f64 = 0.15;
const PULSE_S: f64 = 0.3;
const PULSE_COUNTS: i64 = 50;
/// Current readings at rest (s), and what a healthy sense reads with the bridge off: within
/// 10 % of the 12-bit scale of zero, scattered by a few counts.
const REST_S: f64 = 1.0;
/// How long (rig seconds) a crank still coasting from the crank step may take to stop: the
/// bridge is awake in bring-up mode, so a turning motor drives current through it.
const SPIN_DOWN_S: f64 = 3.0;
const CURRENT_LIMITS: current::Limits = current::Limits {
    min: 0.0,
    max: 410.0,
    max_spread: 20.0,
};
/// The stroke's drive: R < 1 hanging, across the pendulum; settled this long before reading.
const STROKE_R: f64 = 0.5;
const STROKE_DEG: f64 = 90.0;
const STROKE_QUIET_S: f64 = 3.0;
const STROKE_TIMEOUT_S: f64 = 90.0;
/// Waiting for a typed line: the signals and the socket looked at this often, and the link
/// kept alive (well inside the rig's link timeout).
const LINE_POLL: Duration = Duration::from_millis(20);
const LINE_KEEP_ALIVE: Duration = Duration::from_millis(200);
/// The marks a person jogs the mount to (degrees), those inside the travel.
const MARKS: [f64; 3] = [0.0, 90.0, 180.0];

/// A calibration in progress: the connection, the person, the configuration being built.
pub struct Calibrator<'a> {
    pub s: Session,
    pub op: Operator<'a>,
    pub cfg: RigConfig,
    /// Signals, stops from elsewhere, and the control socket while this command owns the port.
    pub watch: Watch,
    /// The ring-down of this run (the sensor step's serves the ringdown step: ℓ, Q and μ do
    /// not depend on the sensor's zero or direction).
    ring: Option<ringdown::RingDown>,
    /// The servo map came from marks in this run: the stroke step then only checks it.
    marked: bool,
}

fn refused(step: Step, e: CalibError) -> anyhow::Error {
    Failure::new(
        Exit::Refused,
        format!(
            "{} step: {e}; nothing from this step was written",
            step.label()
        ),
    )
    .into()
}

impl<'a> Calibrator<'a> {
    pub fn new(s: Session, op: Operator<'a>, watch: Watch) -> Self {
        let cfg = s.config;
        Self {
            s,
            op,
            cfg,
            watch,
            ring: None,
            marked: false,
        }
    }

    pub fn run(&mut self, step: Step) -> Result<StepReport> {
        let mut r = StepReport::new(step);
        match step {
            Step::Sensor => self.sensor(&mut r)?,
            Step::Crank => self.crank(&mut r)?,
            Step::Servo => self.servo(&mut r)?,
            Step::Ringdown => self.ringdown(&mut r)?,
            Step::Stroke => self.stroke(&mut r)?,
        }
        Ok(r)
    }

    /// Stores the configuration built so far (the rig must be idle).
    pub fn write(&mut self) -> Result<()> {
        let cfg = self
            .cfg
            .validate()
            .map_err(|e| anyhow!("the calibrated configuration is invalid: {e}"))?;
        self.idle()?;
        self.s.call(|c| c.set_config(&cfg))?;
        self.s.config = cfg;
        Ok(())
    }

    /// Stops the drive or bring-up mode and waits until the rig is idle.
    fn idle(&mut self) -> Result<()> {
        self.s.call(|c| c.stop())?;
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            self.watch.tick(&mut self.s)?;
            let st = self.s.call(|c| c.status())?;
            match st.mode {
                Mode::Idle if st.bring_up.is_none() => return Ok(()),
                Mode::Faulted(f) => bail!(
                    "the rig is faulted ({}): `kapitza clear` once its cause is gone",
                    crate::rig::names::fault_name(&f)
                ),
                _ => {}
            }
            if Instant::now() >= deadline {
                bail!("the rig did not come to idle within 30 s");
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Says what to do and, unless `--yes`, waits for Enter (`q` stops the calibration).
    fn ask(&mut self, what: &str) -> Result<()> {
        if !self.op.ask(what)? {
            return Ok(());
        }
        if self.line()?.trim() == "q" {
            bail!("calibration stopped at the prompt; nothing more was changed");
        }
        Ok(())
    }

    /// A line typed by the person (empty at end of input), the link kept alive and the
    /// [`Watch`] asked meanwhile.
    fn line(&mut self) -> Result<String> {
        let mut alive = Instant::now();
        loop {
            if let Some(l) = self.op.poll_line(LINE_POLL)? {
                return Ok(l);
            }
            self.watch.tick(&mut self.s)?;
            if alive.elapsed() >= LINE_KEEP_ALIVE {
                self.s.call(|c| c.status())?;
                alive = Instant::now();
            }
        }
    }

    fn theta_d_now(&mut self) -> Result<f64> {
        Ok(from_q16(self.s.call(|c| c.status())?.theta_d_deg))
    }

    /// A ring-down in bring-up mode with the motor off: (t, raw sensor angle unwrapped, rad)
    /// from the release on, and the angle it was held at.
    fn record_ring_down(&mut self) -> Result<(Vec<f64>, Vec<f64>)> {
        self.idle()?;
        self.ask(
            "hold the pendulum still about 20° counter-clockwise (seen from the front); \
             after you confirm, let go and keep clear for 25 s",
        )?;
        let deg = self.theta_d_now()?;
        self.s.call(|c| c.stream_telemetry(20))?;
        self.s.call(|c| c.bring_up(0.0, deg))?;
        let frames = record::raw(&mut self.s, &mut self.watch, RING_S + 2.0)?;
        self.idle()?;
        let mut t = Vec::with_capacity(frames.len());
        let mut x = Vec::with_capacity(frames.len());
        let mut last: Option<f64> = None;
        for (ti, f) in &frames {
            let Some(count) = f.pendulum else { continue };
            let a = f64::from(count) / SENSOR_COUNTS * math::TAU;
            let a = match last {
                Some(p) => p + math::wrap_pi(a - p),
                None => math::wrap_pi(a),
            };
            last = Some(a);
            t.push(*ti);
            x.push(a);
        }
        Ok((t, x))
    }

    fn limits(&self) -> Result<ringdown::Limits> {
        ringdown::Limits::for_pendulum(self.cfg.ell(), self.cfg.gravity)
            .map_err(|e| anyhow!("the configured pendulum: {e}"))
    }

    fn analyse_ring_down(&mut self, step: Step) -> Result<(ringdown::RingDown, f64)> {
        let lim = self.limits()?;
        let (t, x) = self.record_ring_down()?;
        let k = ringdown::release_index(&x, lim.hysteresis);
        let rd = ringdown::identify(&t[k..], &x[k..], self.cfg.gravity, &lim)
            .map_err(|e| refused(step, e))?;
        self.ring = Some(rd);
        Ok((rd, x[k]))
    }

    fn sensor(&mut self, r: &mut StepReport) -> Result<()> {
        self.op
            .say("sensor: the pendulum sensor's direction and zero, from a ring-down")?;
        let (rd, held) = self.analyse_ring_down(Step::Sensor)?;
        let sign = direction::sensor_sign(held, rd.zero).map_err(|e| refused(Step::Sensor, e))?;
        let zero = (math::wrap_pi(rd.zero) / math::TAU * SENSOR_COUNTS).round() as i64;
        let zero = zero.rem_euclid(SENSOR_COUNTS as i64) as u16;
        r.measured("released_from_deg", math::to_deg(held - rd.zero));
        r.measured("centre_deg", math::to_deg(math::wrap_pi(rd.zero)));
        r.measured("half_swings", rd.half_swings);
        let c = &mut self.cfg.calibration;
        c.pendulum_zero = zero;
        c.pendulum_sign = sign as i8;
        r.wrote("pendulum_zero", zero);
        r.wrote("pendulum_sign", sign as i8);
        Ok(())
    }

    fn crank(&mut self, r: &mut StepReport) -> Result<()> {
        self.op
            .say("crank: the crank encoder's direction, from a short pulse")?;
        self.idle()?;
        self.ask("the crank will turn for 0.3 s at low duty: keep clear of it")?;
        let deg = self.theta_d_now()?;
        self.s.call(|c| c.stream_telemetry(20))?;
        self.s.call(|c| c.bring_up(PULSE_DUTY, deg))?;
        let frames = record::raw(&mut self.s, &mut self.watch, PULSE_S)?;
        self.idle()?;
        let counts: Vec<u32> = frames
            .iter()
            .map(|(_, f)| f.crank >> (32 - CRANK_COUNTS.trailing_zeros()))
            .collect();
        let sign = direction::crank_sign(&counts, CRANK_COUNTS, PULSE_COUNTS)
            .map_err(|e| refused(Step::Crank, e))?;
        let moved = counts
            .windows(2)
            .map(|w| {
                let d = (i64::from(w[1]) - i64::from(w[0])).rem_euclid(i64::from(CRANK_COUNTS));
                if d > i64::from(CRANK_COUNTS / 2) {
                    d - i64::from(CRANK_COUNTS)
                } else {
                    d
                }
            })
            .sum::<i64>();
        r.measured("pulse_counts", moved);
        self.cfg.calibration.crank_sign = sign as i8;
        r.wrote("crank_sign", sign as i8);
        Ok(())
    }

    fn servo(&mut self, r: &mut StepReport) -> Result<()> {
        self.op.say(
            "servo: the current sense's offset at rest, and the servo's map from marked angles",
        )?;
        self.idle()?;
        let deg = self.theta_d_now()?;
        self.s.call(|c| c.stream_telemetry(20))?;
        self.s.call(|c| c.bring_up(0.0, deg))?;
        // At rest: from the first frame after which the crank encoder stood still for REST_S.
        let mut still: Option<(u32, f64)> = None;
        let (frames, _) = record::raw_until(
            &mut self.s,
            &mut self.watch,
            REST_S + SPIN_DOWN_S,
            |f, t| match still {
                Some((crank, since)) if crank == f.crank => t - since >= REST_S,
                _ => {
                    still = Some((f.crank, t));
                    false
                }
            },
        )?;
        let since = still.map_or(0.0, |(_, since)| since);
        let readings: Vec<f64> = frames
            .iter()
            .filter(|(t, _)| *t >= since)
            .map(|(_, f)| f64::from(f.current))
            .collect();
        let off = current::offset(&readings, &CURRENT_LIMITS).map_err(|e| {
            let _ = self.s.call(|c| c.stop());
            refused(Step::Servo, e)
        })?;
        r.measured("current_spread_counts", off.spread);
        self.cfg.calibration.current_offset = off.counts;
        r.wrote("current_offset", off.counts);
        if !self.op.present() {
            self.idle()?;
            self.op.say(
                "  servo map kept: nobody at the marks (--yes, or no terminal); the stroke step \
                 corrects its centre from the pendulum's lean",
            )?;
            return Ok(());
        }
        let lim = self.cfg.limits;
        let map = self.cfg.calibration.servo;
        let mut marks = Vec::new();
        for mark in MARKS {
            if mark < lim.drive_angle_min_deg || mark > lim.drive_angle_max_deg {
                continue;
            }
            let mut at = mark;
            loop {
                self.s.call(|c| c.bring_up(0.0, at))?;
                self.op.say(&format!(
                    "  jog the mount's blade onto the {mark}° mark: type a drive angle in \
                     degrees to move there (now {at:.2}°), Enter alone when it is on the mark"
                ))?;
                let line = self.line()?;
                let line = line.trim();
                if line.is_empty() {
                    break;
                }
                match line.parse::<f64>() {
                    Ok(v) if (lim.drive_angle_min_deg..=lim.drive_angle_max_deg).contains(&v) => {
                        at = v
                    }
                    _ => self.op.say(&format!(
                        "  not an angle in {}..{}°",
                        lim.drive_angle_min_deg, lim.drive_angle_max_deg
                    ))?,
                }
            }
            marks.push(servo_fit::Mark {
                pulse_us: f64::from(map.pulse_us(at)),
                deg: mark,
            });
        }
        self.idle()?;
        let fitted = servo_fit::fit(
            &marks,
            map.min_us,
            map.max_us,
            (lim.drive_angle_min_deg, lim.drive_angle_max_deg),
        )
        .map_err(|e| refused(Step::Servo, e))?;
        self.cfg.calibration.servo = fitted;
        self.marked = true;
        r.measured("marks", marks.len());
        r.wrote("servo_range_deg", fitted.range_deg);
        r.wrote("servo_centre_deg", fitted.centre_deg);
        Ok(())
    }

    fn ringdown(&mut self, r: &mut StepReport) -> Result<()> {
        self.op.say(
            "ringdown: the pendulum's length and damping from a ring-down with the drive off",
        )?;
        let rd = match self.ring {
            Some(rd) => {
                self.op.say("  (the sensor step's ring-down)")?;
                rd
            }
            None => self.analyse_ring_down(Step::Ringdown)?.0,
        };
        r.measured("omega0", rd.omega0);
        r.measured("omega_d", rd.omega_d);
        r.measured("ell", rd.ell);
        r.measured("decay", rd.decay.model.label());
        if let Some(q) = rd.q {
            r.measured("q", q);
        }
        if let Some(mu) = rd.coulomb {
            r.measured("coulomb", mu);
        }
        r.measured("half_swings", rd.half_swings);
        r.measured("first_swing_deg", math::to_deg(rd.amplitude));
        let g = &mut self.cfg.geometry;
        *g = match *g {
            Geometry::Rod { .. } => {
                r.wrote("pendulum.length", 1.5 * rd.ell);
                Geometry::Rod {
                    length: 1.5 * rd.ell,
                }
            }
            Geometry::PointMass { .. } => {
                r.wrote("pendulum.length", rd.ell);
                Geometry::PointMass { length: rd.ell }
            }
            Geometry::General { mass, com, .. } => {
                r.wrote("pendulum.inertia", rd.ell * mass * com);
                Geometry::General {
                    inertia: rd.ell * mass * com,
                    mass,
                    com,
                }
            }
        };
        Ok(())
    }

    fn stroke(&mut self, r: &mut StepReport) -> Result<()> {
        self.op.say(&format!(
            "stroke: the stroke from the fast wobble, hanging at R = {STROKE_R} across the drive"
        ))?;
        let rod = self.cfg.connecting_rod;
        self.op.say(&if rod > 0.0 {
            format!(
                "  the plumb line allows for the configured connecting rod, {:.1} mm (measure it \
                 and `kapitza config set` it if it is not)",
                rod * 1e3
            )
        } else {
            "  no connecting rod configured: the stroke is taken as a pure sine (set \
             `connecting_rod` first if the crank drives the carriage through a rod)"
                .to_string()
        })?;
        self.idle()?;
        self.ask(&format!(
            "the drive will run at R = {STROKE_R}, θd = {STROKE_DEG}° for about 20 s with the \
             pendulum hanging: keep clear"
        ))?;
        self.s.call(|c| c.stream_telemetry(20))?;
        self.s.call(|c| c.set_drive(STROKE_R, STROKE_DEG))?;
        let mut quiet_since: Option<f64> = None;
        let (frames, settled) =
            record::telemetry(&mut self.s, &mut self.watch, STROKE_TIMEOUT_S, |t, now| {
                if t.settled && t.steady && t.equilibrium.is_some() {
                    now - *quiet_since.get_or_insert(now) >= STROKE_QUIET_S
                } else {
                    quiet_since = None;
                    false
                }
            })?;
        self.idle()?;
        if !settled {
            bail!(
                "stroke step: the pendulum did not settle within {STROKE_TIMEOUT_S} s of rig \
                 time; nothing from this step was written"
            );
        }
        let quiet: Vec<_> = frames
            .iter()
            .rev()
            .map(|(_, t)| t)
            .take_while(|t| t.settled && t.equilibrium.is_some())
            .collect();
        let n = quiet.len() as f64;
        let wobble = quiet.iter().map(|t| from_q16(t.wobble)).sum::<f64>() / n;
        let omega = quiet.iter().map(|t| from_q16(t.omega)).sum::<f64>() / n;
        let phi0 = quiet
            .iter()
            .map(|t| Angle::from_bits(t.equilibrium.unwrap_or(0)).to_rad())
            .sum::<f64>()
            / n;
        let ell = self.cfg.ell();
        let g = self.cfg.gravity;
        let omega0 = (g / ell).sqrt();
        let pendulum = stroke::Pendulum {
            ell,
            omega0,
            damping: self.ring.and_then(|rd| rd.q).map_or(0.0, |q| omega0 / q),
        };
        let measure = |theta_d: f64| {
            stroke::stroke(
                &stroke::Wobble {
                    amplitude: wobble,
                    omega,
                    from_drive: phi0 - theta_d,
                    phi0,
                },
                &pendulum,
            )
            .map_err(|e| refused(Step::Stroke, e))
        };
        let first = measure(math::to_rad(STROKE_DEG))?;
        let r_true = first * first * omega * omega / (2.0 * g * ell);
        // The configuration's slider-crank with the stroke measured here.
        let crank = |amplitude: f64| {
            RigConfig {
                amplitude,
                ..self.cfg
            }
            .slider_crank()
        };
        let theta_d = plumb::drive_angle(phi0, r_true, crank(first).as_ref())
            .map_err(|e| refused(Step::Stroke, e))?;
        let a = measure(theta_d)?;
        let mount = math::to_deg(theta_d);
        let gain = crank(a).map_or(1.0, |c| c.strength_gain());
        r.measured("wobble_rad", wobble);
        r.measured("omega", omega);
        r.measured("lean_deg", math::to_deg(phi0));
        r.measured("r_in_situ", gain * a * a * omega * omega / (2.0 * g * ell));
        r.measured("mount_deg", mount);
        self.cfg.amplitude = a;
        r.wrote("amplitude", a);
        if !self.marked {
            let servo = &mut self.cfg.calibration.servo;
            servo.centre_deg += mount - STROKE_DEG;
            r.wrote("servo_centre_deg", servo.centre_deg);
        }
        Ok(())
    }
}
