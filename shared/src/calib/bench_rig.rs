//! The calibration tests' bench: a simulated rig in-process, spoken to over the link as the
//! host does, with the telemetry it streams collected.

use crate::link::convert::{from_q16, to_q16};
use crate::link::frame::{encode, receive_response, Header};
use crate::link::{
    FrameReader, Request, Response, Telemetry, MAX_REQUEST_FRAME, MAX_RESPONSE_FRAME,
};
use crate::persist::ConfigOrigin;
use crate::rig::config::RigConfig;
use crate::rig::fixed::Angle;
use crate::simrig::{Params, SimRig};

pub struct Bench {
    pub sim: SimRig,
    reader: FrameReader<MAX_RESPONSE_FRAME>,
    seq: u8,
    answer: Option<Response>,
    /// Telemetry collected since the last [`Bench::take`].
    pub log: Vec<Telemetry>,
}

impl Bench {
    pub fn new(params: Params, cfg: RigConfig) -> Self {
        let cfg = cfg.validate().unwrap();
        Self {
            sim: SimRig::new(params, cfg, ConfigOrigin::Stored, [0, 1, 0]),
            reader: FrameReader::new(),
            seq: 0,
            answer: None,
            log: Vec::new(),
        }
    }

    /// Sends `req` and steps the rig until it answers.
    pub fn ask(&mut self, req: Request) -> Response {
        self.seq = self.seq.wrapping_add(1).max(1);
        let mut buf = [0u8; MAX_REQUEST_FRAME];
        let n = encode(Header::new(self.seq), &req, &mut buf).unwrap();
        self.sim.receive(&buf[..n], None);
        for _ in 0..100 {
            self.step();
            if let Some(r) = self.answer.take() {
                return r;
            }
        }
        panic!("no answer to {req:?}");
    }

    /// `SetDrive` with R and θd (degrees along the travel).
    pub fn drive(&mut self, r: f64, deg: f64) {
        let resp = self.ask(Request::SetDrive {
            r: to_q16(r),
            theta_d_deg: to_q16(deg),
        });
        assert_eq!(resp, Response::Ok);
    }

    fn step(&mut self) {
        self.sim.step(None);
        let mut out = [0u8; 256];
        let n = self.sim.transmit(&mut out);
        for &b in &out[..n] {
            if let Some(Ok(stuffed)) = self.reader.push(b) {
                match receive_response(stuffed) {
                    Ok((_, Response::Telemetry(t))) => self.log.push(t),
                    Ok((_, r)) => self.answer = Some(r),
                    Err(e) => panic!("bad frame from the rig: {e:?}"),
                }
            }
        }
    }

    /// Runs `secs` of rig time; keeps answering so the link never goes silent.
    pub fn run(&mut self, secs: f64) {
        let n = (secs * f64::from(self.sim.rig().sample_hz())).round() as u64;
        for i in 0..n {
            self.step();
            // A keep-alive every 0.2 s, as the host's session sends.
            if i % 2000 == 1999 {
                self.ask(Request::GetStatus);
            }
        }
    }

    /// The collected (t, θ) pairs (s, rad, θ in (−π, π]), and forgets them.
    pub fn take_theta(&mut self) -> (Vec<f64>, Vec<f64>) {
        let t0 = self.log.first().map_or(0, |t| t.t_us);
        let out = self
            .log
            .iter()
            .map(|t| {
                (
                    f64::from(t.t_us.wrapping_sub(t0)) * 1e-6,
                    Angle::from_bits(t.theta).to_rad(),
                )
            })
            .unzip();
        self.log.clear();
        out
    }

    /// The last telemetry's ω (rad/s).
    pub fn omega(&self) -> f64 {
        from_q16(self.log.last().unwrap().omega)
    }
}
