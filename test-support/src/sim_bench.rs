//! The simulated rig behind its link, for tests that talk to it as the host does.

use kapitza_core::link::frame::{encode, receive_response, Header};
use kapitza_core::link::message::Check;
use kapitza_core::link::{FrameReader, Request, Response, Status, MAX_RESPONSE_FRAME};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::rig::config::RigConfig;
use kapitza_core::simrig::{Params, SimRig};

pub struct Bench {
    pub sim: SimRig,
    seq: u8,
    pub streamed: Vec<Response>,
}

impl Bench {
    pub fn new(params: Params, cfg: RigConfig) -> Self {
        let mut sim = SimRig::new(params, cfg, ConfigOrigin::Stored, [0, 1, 0]);
        sim.run(0.05);
        Self {
            sim,
            seq: 0,
            streamed: Vec::new(),
        }
    }

    pub fn healthy(params: Params) -> Self {
        Self::new(params, params.configured())
    }

    /// Sends `req` and returns the rig's answer to it; streamed frames queued meanwhile go to
    /// `self.streamed`.
    pub fn ask(&mut self, req: Request) -> Response {
        self.seq = self.seq.wrapping_add(1);
        let mut f = [0u8; 512];
        let n = encode(Header::new(self.seq), &req, &mut f).unwrap();
        self.sim.receive(&f[..n], None);
        let mut answer = None;
        for (seq, r) in self.drain() {
            if matches!(r, Response::Telemetry(_) | Response::Raw(_)) {
                self.streamed.push(r);
            } else if seq == self.seq {
                answer = Some(r);
            }
        }
        answer.expect("an answer")
    }

    /// Every frame the rig has queued, decoded, with its seq.
    fn drain(&mut self) -> Vec<(u8, Response)> {
        let mut reader = FrameReader::<MAX_RESPONSE_FRAME>::new();
        let mut out = [0u8; 64];
        let mut got = Vec::new();
        loop {
            let k = self.sim.transmit(&mut out);
            if k == 0 {
                return got;
            }
            for &b in &out[..k] {
                if let Some(Ok(stuffed)) = reader.push(b) {
                    let (h, r) = receive_response(stuffed).unwrap();
                    got.push((h.seq, r));
                }
            }
        }
    }

    pub fn status(&mut self) -> Status {
        match self.ask(Request::GetStatus) {
            Response::Status(s) => s,
            r => panic!("{r:?}"),
        }
    }

    /// Runs `secs` of rig time in 10 ms steps, collecting what the rig streams.
    pub fn run(&mut self, secs: f64) {
        let n = (secs / 0.01).round() as usize;
        for _ in 0..n {
            self.sim.run(0.01);
            self.collect();
        }
    }

    fn collect(&mut self) {
        let got = self.drain();
        self.streamed.extend(got.into_iter().map(|(_, r)| r));
    }

    /// Asks for R = 2 at θd = 0 and runs until the check's verdict (at most 1 s).
    pub fn start(&mut self) -> Status {
        let r = self.ask(Request::SetDrive {
            r: 2 << 16,
            theta_d_deg: 0,
        });
        assert_eq!(r, Response::Ok);
        assert_eq!(self.status().check, Some(Check::Running));
        for _ in 0..100 {
            self.sim.run(0.01);
            let s = self.status();
            if s.check != Some(Check::Running) {
                return s;
            }
        }
        panic!("no verdict within 1 s");
    }
}
