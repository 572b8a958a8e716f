//! Knowing a repeat: the host sends a request again, with the same sequence number, when its
//! answer did not arrive in time or arrived damaged. The rig may have carried it out already, so
//! it answers a repeat of the last request it answered from the answer it gave, without carrying
//! it out twice (the idea of Klipper's serial link: a sequence number per request, and the
//! receiver acknowledging a retransmission without acting on it again).
//!
//! ```text
//! request seq n, bytes B   → carried out, answered; remembered: (n, |B|, CRC-32C of B), answer
//! the same n and B again   → the remembered answer, nothing carried out
//! anything else            → carried out as usual, and remembered instead
//! ```
//! Only the last request is remembered (a few bytes of RAM): the host waits for each answer
//! before it sends the next request, so a repeat always follows its original. A new connection
//! opens with `GetVersion`, so a request left over from an earlier connection is never taken for
//! a repeat. Queries (`GetVersion`, `GetStatus`, `GetConfig`) change nothing and are answered
//! afresh every time. A bad frame in between (the damaged copy that made the host resend) does
//! not forget the last request.
//!
//! The bytes are compared by length and CRC-32C, the check that already tells a frame from noise
//! (a different payload of the same length and seq passes it with probability 2^-32).

use crate::checksum::CRC;
use crate::link::{Reason, Request, Response};

/// What tells one request frame from another: its seq, and its payload's length and CRC-32C.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameId {
    pub seq: u8,
    pub len: u16,
    pub crc: u32,
}

impl FrameId {
    /// The id of a frame with this `seq` and `payload` (the bytes after the header).
    pub fn of(seq: u8, payload: &[u8]) -> Self {
        Self {
            seq,
            len: payload.len().min(usize::from(u16::MAX)) as u16,
            crc: CRC.checksum(payload),
        }
    }
}

/// The last request answered, and the answer a command got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LastAnswer {
    id: FrameId,
    /// `None` for a query, answered afresh.
    outcome: Option<Result<(), Reason>>,
}

impl LastAnswer {
    /// Remembers the answer `resp` to the request `req` that arrived as `id`.
    pub fn new(id: FrameId, req: &Request, resp: &Response) -> Self {
        let outcome = match (req, resp) {
            (Request::GetVersion | Request::GetStatus | Request::GetConfig, _) => None,
            (_, Response::Refused(r)) => Some(Err(*r)),
            _ => Some(Ok(())),
        };
        Self { id, outcome }
    }

    /// The answer to give again if `id` is a repeat of this command.
    pub fn recall(&self, id: FrameId) -> Option<Response> {
        if id != self.id {
            return None;
        }
        self.outcome.map(|o| match o {
            Ok(()) => Response::Ok,
            Err(r) => Response::Refused(r),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::convert::to_q16;
    use crate::link::frame::{encode, open, Header};
    use crate::link::message::{Check, Mode};
    use crate::link::{WireConfig, MAX_REQUEST_FRAME};
    use crate::persist::{ConfigOrigin, Fallback};
    use crate::rig::config::RigConfig;
    use crate::rig::fixed::{Amps, Angle, Duty};
    use crate::rig::phase_lock::Motor;
    use crate::rig::safety;
    use crate::station::serve::{Clock, Effect, RigServer};

    const CFG: RigConfig = RigConfig::REFERENCE;

    fn server() -> RigServer {
        RigServer::new(
            CFG,
            ConfigOrigin::Defaults(Fallback::Missing),
            Angle::ZERO,
            Clock::single(0, 0),
            [1, 2, 3],
        )
    }

    /// The id of `req` as framed with `seq`, read back the way the rig loop reads it.
    fn id(seq: u8, req: &Request) -> FrameId {
        let mut buf = [0u8; MAX_REQUEST_FRAME];
        let n = encode(Header::new(seq), req, &mut buf).unwrap();
        let f = open(&mut buf[..n - 1]).unwrap();
        FrameId::of(f.header.seq, f.payload)
    }

    fn send(s: &mut RigServer, seq: u8, req: Request, t_us: u32) -> (Response, Effect) {
        s.respond_once(id(seq, &req), req, Clock::single(t_us, 0), false)
    }

    fn drive(r: f64, deg: f64) -> Request {
        Request::SetDrive {
            r: to_q16(r),
            theta_d_deg: to_q16(deg),
        }
    }

    struct Still;
    impl Motor for Still {
        fn crank_angle(&mut self) -> Angle {
            Angle::ZERO
        }
        fn current(&mut self) -> Amps {
            Amps::ZERO
        }
        fn set_duty(&mut self, _duty: Duty) {}
    }

    #[test]
    fn a_repeated_start_is_answered_from_its_answer_and_not_carried_out_again() {
        let set = drive(2.0, 45.0);
        // Carried out again, the start would be refused (its pre-run check is running), and the
        // host would report a refusal for a command the rig took.
        let mut plain = server();
        plain.respond(set, Clock::single(10, 0), false);
        assert_eq!(
            plain.respond(set, Clock::single(20, 0), false).0,
            Response::Refused(Reason::CheckRunning)
        );
        assert_eq!(plain.counters.commands, 1);

        let mut s = server();
        assert_eq!(send(&mut s, 5, set, 10), (Response::Ok, Effect::None));
        assert_eq!(s.check, Some(Check::Running));
        let checking = s.activity;
        // The repeats: the first answer, the same check still running, counted once.
        assert_eq!(send(&mut s, 5, set, 20), (Response::Ok, Effect::None));
        assert_eq!(send(&mut s, 5, set, 30), (Response::Ok, Effect::None));
        assert_eq!((s.counters.commands, s.activity), (1, checking));
        // A repeat still counts as the link being alive.
        assert_eq!(s.heard_us, 30);
        // The same bytes under a new seq are a new request, carried out (refused: the check
        // runs); so is another request under the old seq.
        assert_eq!(
            send(&mut s, 6, set, 40).0,
            Response::Refused(Reason::CheckRunning)
        );
        assert_eq!(send(&mut s, 6, Request::Stop, 50).0, Response::Ok);
        assert_eq!(s.status(false, 0).mode, Mode::Idle);
    }

    #[test]
    fn a_repeated_change_of_a_running_drive_is_counted_once() {
        let mut s = server();
        crate::station::serve::apply(
            &mut s.rig,
            &CFG,
            crate::station::serve::Command::SetDrive {
                r: to_q16(1.0),
                theta_d_deg: to_q16(0.0),
            },
        )
        .unwrap();
        assert_eq!(s.rig.supervisor().mode(), safety::Mode::Running);
        let set = drive(3.0, 30.0);
        assert_eq!(send(&mut s, 9, set, 10).0, Response::Ok);
        let after = *s.rig.supervisor();
        assert_eq!(send(&mut s, 9, set, 20).0, Response::Ok);
        assert_eq!(s.counters.commands, 1);
        assert_eq!(
            (
                s.rig.supervisor().target_word(),
                s.rig.supervisor().theta_d_target()
            ),
            (after.target_word(), after.theta_d_target())
        );
        // Refused the first time: refused again from the answer, not decided anew.
        let too_much = drive(9.0, 30.0);
        let no = send(&mut s, 10, too_much, 30).0;
        assert!(
            matches!(no, Response::Refused(Reason::OmegaAboveLimit { .. })),
            "{no:?}"
        );
        assert_eq!(send(&mut s, 10, too_much, 40).0, no);
        assert_eq!(s.counters.commands, 1);
    }

    #[test]
    fn a_repeated_clear_fault_is_decided_once() {
        let mut s = server();
        // E-stop pressed: faulted; a clear while it is still pressed is refused.
        s.rig.control(1000, &mut Still, true);
        assert_eq!(
            s.rig.supervisor().mode(),
            safety::Mode::Faulted(safety::Fault::EStop)
        );
        let no = send(&mut s, 3, Request::ClearFault, 10).0;
        assert_eq!(no, Response::Refused(Reason::EStopStillActive));
        // Released meanwhile: a late repeat of that clear still gets the answer it got, and
        // leaves the fault latched (the user's one clear was refused; a new one clears it).
        s.rig.control(2000, &mut Still, false);
        assert_eq!(send(&mut s, 3, Request::ClearFault, 20).0, no);
        assert!(matches!(
            s.rig.supervisor().mode(),
            safety::Mode::Faulted(_)
        ));
        assert_eq!(send(&mut s, 4, Request::ClearFault, 30).0, Response::Ok);
        assert_eq!(s.rig.supervisor().mode(), safety::Mode::Idle);
        assert_eq!(send(&mut s, 4, Request::ClearFault, 40).0, Response::Ok);
        assert_eq!(s.counters.commands, 1);
    }

    #[test]
    fn a_repeated_configuration_is_stored_once() {
        let mut s = server();
        let mut new = CFG;
        new.amplitude = 0.012;
        let set = Request::SetConfig(WireConfig::from(new));
        assert_eq!(
            send(&mut s, 7, set, 10),
            (Response::Ok, Effect::StoreConfig(new))
        );
        // Before the flash write is done, a repeat would restart the rig on it and store it
        // again; answered from the first answer, it does neither.
        assert_eq!(s.origin, ConfigOrigin::Received { saved: false });
        assert_eq!(send(&mut s, 7, set, 20), (Response::Ok, Effect::None));
        assert_eq!(s.counters.commands, 1);
    }

    #[test]
    fn queries_are_answered_afresh_and_a_request_between_forgets_the_last() {
        let mut s = server();
        let set = drive(1.0, 0.0);
        assert_eq!(send(&mut s, 1, set, 10).0, Response::Ok);
        assert_eq!(send(&mut s, 1, Request::Stop, 20).0, Response::Ok);
        // The same seq and bytes as a request before the last one: a new request (as from a
        // new connection), carried out.
        assert_eq!(send(&mut s, 1, set, 30).0, Response::Ok);
        assert_eq!(s.counters.commands, 3);
        // A status asked twice under one seq is the status now, both times.
        let at = |ms| Clock::single(40, ms);
        let q = Request::GetStatus;
        let uptime = |r: Response| match r {
            Response::Status(st) => st.uptime_ms,
            r => panic!("{r:?}"),
        };
        assert_eq!(uptime(s.respond_once(id(2, &q), q, at(100), false).0), 100);
        assert_eq!(uptime(s.respond_once(id(2, &q), q, at(200), false).0), 200);
    }
}
