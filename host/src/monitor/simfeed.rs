//! The simulated demo rig in this process, as a byte port paced against the wall clock, behind
//! the same [`LinkFeed`] a serial port uses: the monitor and the demo cannot tell them apart.
//!
//! Each read lets the rig catch up with `speed` × the wall time since it started (speed 0: as
//! fast as the machine goes), stopping as soon as the rig has bytes for the laptop.

use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use kapitza_core::persist::ConfigOrigin;
use kapitza_core::simrig::{Params, SimRig};

use super::link_feed::LinkFeed;

/// The firmware version the simulated rig reports.
pub const SIM_FIRMWARE: [u16; 3] = [0, 1, 0];
/// The most rig time one read may run before it returns (s): keeps a rig that cannot keep up
/// with its speed answering.
const MAX_RUN_S: f64 = 0.02;

/// The demo rod (SPEC §3 reference: L = 0.25 m, A = 12.7 mm), configured as a careful user
/// would, hanging at rest.
pub fn demo_rig() -> SimRig {
    SimRig::new(
        Params::DEMO,
        Params::DEMO.configured(),
        ConfigOrigin::Stored,
        SIM_FIRMWARE,
    )
}

/// A simulated rig on the other end of a line.
pub struct SimPort {
    rig: SimRig,
    partial: Vec<u8>,
    start: Instant,
    speed: f64,
}

impl SimPort {
    /// `rig` at `speed` × real time (0: unpaced).
    pub fn new(rig: SimRig, speed: f64) -> Self {
        Self {
            rig,
            partial: Vec::new(),
            start: Instant::now(),
            speed,
        }
    }
}

impl Write for SimPort {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        for &b in buf {
            self.partial.push(b);
            if b == 0 {
                let frame = std::mem::take(&mut self.partial);
                self.rig.receive(&frame, None);
            }
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Read for SimPort {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.rig.rig().pending() == 0 {
            let due = if self.speed > 0.0 {
                self.start.elapsed().as_secs_f64() * self.speed
            } else {
                f64::INFINITY
            };
            let limit = self.rig.seconds() + MAX_RUN_S;
            while self.rig.seconds() < due.min(limit) && self.rig.rig().pending() == 0 {
                self.rig.step(None);
            }
        }
        match self.rig.transmit(buf) {
            0 => {
                if self.speed > 0.0 {
                    std::thread::sleep(Duration::from_millis(1));
                }
                Err(io::ErrorKind::TimedOut.into())
            }
            n => Ok(n),
        }
    }
}

/// The demo rig at `speed` × real time, as a feed.
pub fn sim_feed(speed: f64) -> LinkFeed {
    let mut port = Some(SimPort::new(demo_rig(), speed));
    LinkFeed::spawn(Box::new(move || {
        port.take()
            .ok_or_else(|| "the simulated rig is gone".to_string())
    }))
}
