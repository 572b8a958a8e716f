//! HC06: equilibria where they merge — on and next to the saddle-node curve R_sn(θd) (physics §3),
//! at the cusps R = 1, θd = 0°/90°/180° where three roots meet, and at and next to the special
//! drive angles. The finder isolates the roots of a trigonometric polynomial by derivative
//! recursion (no sampling) and merges roots closer than `MERGE_RAD`; the risk is an equilibrium
//! lost or duplicated, or "marginal" missing where two roots meet.

use kapitza_core::math;
use kapitza_core::model::equilibria::saddle_node_r;
use kapitza_core::model::{equilibria, DriveAngle, Stability};

fn drive(deg: f64) -> DriveAngle {
    DriveAngle::from_deg(deg).unwrap()
}

#[test]
fn hc06_marginal_at_r2_theta135() {
    // physics §4.5: at R = 2, θd = 135° the reachable equilibrium is marginal (on R_sn).
    let eqs = equilibria(2.0, drive(135.0)).unwrap();
    let reach: Vec<_> = eqs.as_slice().filter(|e| e.within_90_of_drive).collect();
    assert!(
        reach.iter().any(|e| e.stability == Stability::Marginal),
        "{reach:?}"
    );
}

#[test]
fn hc06_special_angles_and_neighbours_keep_their_equilibria() {
    // At and next to θd = 0°, 90°, 180° (±1e-9°, ±1e-3°), away from R_sn, the count is 2 or 4 as
    // the saddle-node curve says and the stable angles move continuously (< 0.01° for 1e-3°).
    for base in [0.0, 90.0, 180.0, -90.0] {
        for r in [0.5, 1.5, 3.0] {
            let reference: Vec<f64> = equilibria(r, drive(base))
                .unwrap()
                .stable()
                .map(|e| e.angle)
                .collect();
            for off in [-1e-3, -1e-9, 1e-9, 1e-3] {
                let d = drive(base + off);
                let eqs = equilibria(r, d).unwrap();
                assert_eq!(
                    eqs.len(),
                    if r < saddle_node_r(d) { 2 } else { 4 },
                    "θd {} R {r}",
                    base + off
                );
                let got: Vec<f64> = eqs.stable().map(|e| e.angle).collect();
                assert_eq!(got.len(), reference.len(), "θd {} R {r}", base + off);
                // Matched cyclically: a root at π may come back as −π + ε.
                for w in &reference {
                    assert!(
                        got.iter()
                            .any(|g| math::wrap_pi(g - w).abs() < math::to_rad(0.01)),
                        "θd {} R {r}: {got:?} vs {reference:?}",
                        base + off
                    );
                }
            }
        }
    }
}

#[test]
fn hc06_three_roots_meet_at_the_cusps() {
    // R = 1 at θd = 0°, 90°, 180° (physics §3: three roots meet): one marginal equilibrium where
    // they meet, and one other equilibrium — two in all, none duplicated.
    for (deg, meet) in [(0.0, math::PI), (90.0, 0.0), (180.0, math::PI)] {
        let eqs = equilibria(1.0, drive(deg)).unwrap();
        assert_eq!(
            eqs.len(),
            2,
            "θd {deg}: {:?}",
            eqs.as_slice().collect::<Vec<_>>()
        );
        let m = eqs
            .as_slice()
            .find(|e| math::wrap_pi(e.angle - meet).abs() < 1e-6)
            .unwrap();
        assert_eq!(m.stability, Stability::Marginal, "θd {deg}");
    }
    // Just above the cusp the three separate: at θd = 180°, R = 1 + 1e-6 the inverted position
    // is stable and two unstable equilibria flank it at cos φ = −1/R (closed form, physics §3).
    let eqs = equilibria(1.0 + 1e-6, drive(180.0)).unwrap();
    assert_eq!(eqs.len(), 4);
    let inv = eqs
        .as_slice()
        .find(|e| (e.angle - math::PI).abs() < 1e-9)
        .unwrap();
    assert_eq!(inv.stability, Stability::Stable);
    let flank = math::acos(-1.0 / (1.0 + 1e-6));
    assert!(eqs.as_slice().any(|e| (e.angle - flank).abs() < 1e-9));
}
