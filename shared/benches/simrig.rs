//! What the simulated rig costs at real time: CPU seconds per rig second, with the rig loop at
//! 10 kHz sampling, the drive running (R = 1.75 at θd = 90° on the demo rod), telemetry
//! streaming every 20 ms and the line read. At real time that is the fraction of one core
//! `kapitza rig serve` needs for its physics and rig loop (the goal is ≤ 5 %, so that
//! `--speed 20` fits on one core); the pty's system calls come on top (`rig serve` prints its
//! whole share when it exits).
//!
//! Run: `cargo bench -p kapitza-core --bench simrig`.

use criterion::{criterion_group, criterion_main, Criterion};
use kapitza_core::link::frame::{encode, Header};
use kapitza_core::link::{Request, MAX_REQUEST_FRAME};
use kapitza_core::persist::ConfigOrigin;
use kapitza_core::simrig::{Params, SimRig};
use std::time::Instant;

fn running_rig() -> SimRig {
    let mut rig = SimRig::new(
        Params::DEMO,
        Params::DEMO.configured(),
        ConfigOrigin::Stored,
        [0, 1, 0],
    );
    let mut f = [0u8; MAX_REQUEST_FRAME];
    for (seq, req) in [
        Request::SetDrive {
            r: (1.75 * 65_536.0) as i32,
            theta_d_deg: 90 << 16,
        },
        Request::Telemetry { period_ms: 20 },
    ]
    .iter()
    .enumerate()
    {
        let n = encode(Header::new(seq as u8 + 1), req, &mut f).unwrap();
        rig.receive(&f[..n], None);
    }
    // Past the ramp, so the bench measures the steady drive.
    for _ in 0..10 {
        keep_alive_second(&mut rig);
    }
    rig
}

/// One rig second, the link kept alive every 250 ms and the line read every 1 ms.
fn keep_alive_second(rig: &mut SimRig) {
    let mut f = [0u8; MAX_REQUEST_FRAME];
    let n = encode(Header::new(9), &Request::GetStatus, &mut f).unwrap();
    let mut out = [0u8; 256];
    for ms in 0..1000 {
        if ms % 250 == 0 {
            rig.receive(&f[..n], None);
        }
        for _ in 0..10 {
            rig.step(None);
        }
        while rig.transmit(&mut out) > 0 {}
    }
}

fn bench(c: &mut Criterion) {
    let mut rig = running_rig();
    c.bench_function("simrig/one_rig_second", |b| {
        b.iter(|| keep_alive_second(&mut rig))
    });
    // The same as a plain figure: CPU share at real time, median of 7.
    let mut v: Vec<f64> = (0..7)
        .map(|_| {
            let t = Instant::now();
            keep_alive_second(&mut rig);
            t.elapsed().as_secs_f64()
        })
        .collect();
    v.sort_by(f64::total_cmp);
    println!(
        "simulated rig at real time (10 kHz sampling): {:.2} % of one core; --speed 20 needs {:.0} %",
        100.0 * v[3],
        2000.0 * v[3]
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
