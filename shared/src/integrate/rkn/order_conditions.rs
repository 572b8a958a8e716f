//! The RKN 8(6) and 12(10) tables checked against every Nyström order condition, generated from
//! the trees.
//!
//! For y'' = f(y) (time enters as a component with t'' = 0) the Taylor terms of y are the
//! elementary differentials of *Nyström trees*: a fat vertex f^(m) whose m arguments are each
//! either y' (a meagre leaf, order 1) or another Nyström tree (reached through y' → y'' = f);
//! |u| = 2 + Σ |arguments|. With Y_i − y0 = c_i h y0' + h² Σ_j a_ij f(Y_j), a stage's weight of u
//! is, and the exact solution's (stage at τ: Y(τ) − y0 = τ h y0' + h² ∫_0^τ (τ − s) f ds) is
//!
//! ```text
//! Φ_i(u) = Π_args φ_i,     φ_i(y') = c_i,   φ_i(v) = Σ_j a_ij Φ_j(v)
//! Φ(u)(τ) = Π_args φ(τ),   φ(y')(τ) = τ,    φ(v)(τ) = ∫_0^τ (τ − s) Φ(v)(s) ds
//! ```
//! so Φ(u)(τ) = κ(u) τ^(|u|−2), and the symmetry factors are the same on both sides. Order p
//! needs, for every tree,
//!
//! ```text
//! position  Σ_i bbar_i Φ_i(u) = ∫_0^1 (1 − s) Φ(u)(s) ds = κ/((|u|−1)|u|)     for |u| ≤ p
//! velocity  Σ_i b_i Φ_i(u)    = ∫_0^1 Φ(u)(s) ds        = κ/(|u|−1)            for |u| ≤ p + 1
//! ```
//! (HNW I §II.14: the same conditions, indexed by special Nyström trees.)

use super::{Pair, RKN1210, RKN86};

/// An argument of a fat vertex.
#[derive(Clone, Copy)]
enum Arg {
    /// y', order 1.
    Rate,
    /// The Nyström tree with this index.
    Tree(usize),
}

/// A Nyström tree: its order and its arguments (a multiset, listed by non-decreasing key).
struct NTree {
    order: usize,
    args: Vec<Arg>,
}

/// Every Nyström tree up to `max_order`, each once, by increasing order.
fn nystrom_trees(max_order: usize) -> Vec<NTree> {
    let mut all: Vec<NTree> = Vec::new();
    for n in 2..=max_order {
        // Candidate arguments: y' (key 0) and every smaller tree (key index + 1).
        let kinds: Vec<(Arg, usize)> = core::iter::once((Arg::Rate, 1))
            .chain(all.iter().enumerate().map(|(i, t)| (Arg::Tree(i), t.order)))
            .collect();
        let mut stack: Vec<(usize, usize, Vec<Arg>)> = vec![(0, n - 2, Vec::new())];
        while let Some((from, left, args)) = stack.pop() {
            if left == 0 {
                all.push(NTree { order: n, args });
                continue;
            }
            for (k, &(arg, order)) in kinds.iter().enumerate().skip(from) {
                if order <= left {
                    let mut more = args.clone();
                    more.push(arg);
                    stack.push((k, left - order, more));
                }
            }
        }
    }
    all
}

/// Per tree: Φ_i over the stages, and κ of the exact solution's Φ(τ) = κ τ^(|u|−2).
fn weights<const S: usize>(pair: &Pair<S>, trees: &[NTree]) -> Vec<([f64; S], f64)> {
    let mut out: Vec<([f64; S], f64)> = Vec::new();
    for t in trees {
        let (mut phi, mut kappa) = ([1.0; S], 1.0);
        for arg in &t.args {
            match *arg {
                Arg::Rate => {
                    for (p, c) in phi.iter_mut().zip(pair.c) {
                        *p *= c;
                    }
                }
                Arg::Tree(j) => {
                    let (inner, k) = &out[j];
                    for (i, p) in phi.iter_mut().enumerate() {
                        *p *= (0..S).map(|m| pair.a[i][m] * inner[m]).sum::<f64>();
                    }
                    // ∫_0^τ (τ − s) k s^n ds = k τ^(n+2) / ((n + 1)(n + 2)), n = |v| − 2.
                    let n = trees[j].order as f64 - 2.0;
                    kappa *= k / ((n + 1.0) * (n + 2.0));
                }
            }
        }
        out.push((phi, kappa));
    }
    out
}

/// The largest residual of the position conditions up to order `p` and of the velocity
/// conditions up to order `p + 1`, for weights `bbar`, `b`.
fn worst_residual<const S: usize>(pair: &Pair<S>, bbar: &[f64; S], b: &[f64; S], p: usize) -> f64 {
    let trees = nystrom_trees(p + 1);
    let w = weights(pair, &trees);
    let mut worst: f64 = 0.0;
    for (t, (phi, kappa)) in trees.iter().zip(&w) {
        let q = t.order as f64;
        let dot = |x: &[f64; S]| x.iter().zip(phi).map(|(a, b)| a * b).sum::<f64>();
        if t.order <= p {
            worst = worst.max((dot(bbar) - kappa / ((q - 1.0) * q)).abs());
        }
        worst = worst.max((dot(b) - kappa / (q - 1.0)).abs());
    }
    worst
}

#[test]
fn tree_counts() {
    // Nyström trees by order 2..=6: 1, 1, 2, 3, 6 (f; f'y'; f''(y',y'), f'f; …), counted by hand
    // from the recursion |u| = 2 + Σ |args|, and the total the order-8 check uses.
    let trees = nystrom_trees(9);
    let count = |n| trees.iter().filter(|t| t.order == n).count();
    assert_eq!([2, 3, 4, 5, 6].map(count), [1, 1, 2, 3, 6]);
    assert!(trees.len() > 40, "{} trees", trees.len());
}

#[test]
fn order_8_solution_meets_every_condition() {
    // Exact rationals in f64: residuals at rounding, 1e-14 (the largest coefficients are ~10).
    let p = &RKN86;
    let r = worst_residual(p, &p.bbar, &p.b, 8);
    assert!(r < 1e-14, "order 8: worst residual {r:e}");
    // And not order 9: the check can tell the difference.
    assert!(worst_residual(p, &p.bbar, &p.b, 9) > 1e-8);
}

#[test]
fn order_6_solution_meets_every_condition() {
    let p = &RKN86;
    let r = worst_residual(p, &p.bbar_low, &p.b_low, 6);
    assert!(r < 1e-14, "order 6: worst residual {r:e}");
    assert!(worst_residual(p, &p.bbar_low, &p.b_low, 7) > 1e-8);
}

#[test]
fn a_mistyped_coefficient_is_caught() {
    // One weight off in its fifth digit breaks an order condition far above rounding.
    let mut b = RKN86.b;
    b[4] *= 1.0 + 1e-5;
    assert!(worst_residual(&RKN86, &RKN86.bbar, &b, 8) > 1e-7);
    let mut a = RKN1210.a;
    // In the 12(10) table, one of the largest coefficients off in its tenth digit.
    a[14][5] *= 1.0 + 1e-9;
    let typo = Pair { a, ..RKN1210 };
    assert!(worst_residual(&typo, &typo.bbar, &typo.b, 12) > 1e-11);
}

#[test]
fn order_12_solution_meets_every_condition() {
    // The nearest f64 to each published rational: residuals at rounding (coefficients reach
    // ~20 in magnitude, with cancellation), bounded by 1e-13; order 13 fails by 1.8e-8.
    let p = &RKN1210;
    let r = worst_residual(p, &p.bbar, &p.b, 12);
    assert!(r < 1e-13, "order 12: worst residual {r:e}");
    assert!(worst_residual(p, &p.bbar, &p.b, 13) > 1e-9);
}

#[test]
fn order_10_solution_meets_every_condition() {
    let p = &RKN1210;
    let r = worst_residual(p, &p.bbar_low, &p.b_low, 10);
    assert!(r < 1e-13, "order 10: worst residual {r:e}");
    assert!(worst_residual(p, &p.bbar_low, &p.b_low, 11) > 1e-9);
}
