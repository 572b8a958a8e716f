//! Time of a 400×400 stability map in the (k, m) plane, k ∈ [−2, 2], m ∈ [0, 3]: undamped
//! (Sturm counts only) and damped (Q = 10, and Q = 2: tr M integrated where the shifted
//! undamped problem is unstable). Run: `cargo bench -p kapitza --bench stability_map`.

use kapitza::chart::map::{samples, stability_map, Damping};
use std::time::Instant;

fn main() {
    let ks = samples(-2.0, 2.0, 400);
    let ms = samples(0.0, 3.0, 400);
    println!(
        "400×400 stability map, k ∈ [−2, 2], m ∈ [0, 3], {} threads",
        rayon::current_num_threads()
    );
    for (name, damping) in [
        ("undamped", Damping::None),
        ("damped Q = 10", Damping::Quality(10.0)),
        ("damped Q = 2", Damping::Quality(2.0)),
    ] {
        let mut best = f64::INFINITY;
        let mut stable = 0;
        let mut traces = 0;
        for _ in 0..3 {
            let t = Instant::now();
            let map = stability_map(&ks, &ms, damping).expect("map");
            best = best.min(t.elapsed().as_secs_f64());
            stable = map.stable.iter().flatten().filter(|&&s| s).count();
            traces = map.traces;
        }
        println!(
            "{name:>14}: {best:.3} s (best of 3), {stable} stable cells, {traces} tr M integrations"
        );
    }
}
