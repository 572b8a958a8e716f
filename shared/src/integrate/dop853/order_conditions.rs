//! The DOP853 table checked against the Runge–Kutta order conditions (Butcher): for every rooted
//! tree t with |t| ≤ p,
//!
//! ```text
//! Σ_i b_i Φ_i(t) = 1/γ(t),   Φ(•) = 1,  Φ([t1 … tm]) = Π_k (A Φ(t_k)),  γ([t1 … tm]) = |t| Π_k γ(t_k)
//! ```
//! (HNW I §II.2, Theorem 2.13). There are 200 trees up to order 8. The same conditions with
//! b_i(θ) and θ^|t|/γ(t) check the dense output to order 7 (HNW I §II.6).

use super::tableau::{A, B, BHH1, BHH2, BHH3, C, D, ER, STAGES};

/// A rooted tree: its order and its subtrees (indices into the list, non-decreasing).
struct Tree {
    order: usize,
    children: Vec<usize>,
}

/// All rooted trees up to `max_order`, each once, ordered by order.
fn trees(max_order: usize) -> Vec<Tree> {
    let mut all = vec![Tree {
        order: 1,
        children: vec![],
    }];
    for n in 2..=max_order {
        let smaller = all.len();
        let mut found = Vec::new();
        // Multisets of smaller trees (indices non-decreasing) whose orders sum to n − 1.
        fn pick(
            all: &[Tree],
            from: usize,
            left: usize,
            cur: &mut Vec<usize>,
            out: &mut Vec<Vec<usize>>,
        ) {
            if left == 0 {
                out.push(cur.clone());
                return;
            }
            for i in from..all.len() {
                if all[i].order <= left {
                    cur.push(i);
                    pick(all, i, left - all[i].order, cur, out);
                    cur.pop();
                }
            }
        }
        pick(&all[..smaller], 0, n - 1, &mut Vec::new(), &mut found);
        all.extend(
            found
                .into_iter()
                .map(|children| Tree { order: n, children }),
        );
    }
    all
}

/// Φ(t) (a vector over stages) and γ(t) for every tree, with the first `s` stages of A.
fn weights(trees: &[Tree], s: usize) -> Vec<(Vec<f64>, f64)> {
    let mut out: Vec<(Vec<f64>, f64)> = Vec::new();
    for t in trees {
        let mut phi = vec![1.0; s];
        let mut gamma = t.order as f64;
        for &c in &t.children {
            let (child, g) = &out[c];
            gamma *= g;
            for i in 0..s {
                phi[i] *= (0..i).map(|j| A[i][j] * child[j]).sum::<f64>();
            }
        }
        out.push((phi, gamma));
    }
    out
}

/// Largest |Σ b_i Φ_i(t) − θ^|t|/γ(t)| over the trees up to order p.
fn worst(trees: &[Tree], w: &[(Vec<f64>, f64)], b: &[f64], p: usize, theta: f64) -> f64 {
    trees
        .iter()
        .zip(w)
        .filter(|(t, _)| t.order <= p)
        .map(|(t, (phi, gamma))| {
            let lhs: f64 = b.iter().zip(phi).map(|(b, f)| b * f).sum();
            (lhs - theta.powi(t.order as i32) / gamma).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn tree_count_is_butcher_s() {
    // Number of rooted trees of order 1..8: 1, 1, 2, 4, 9, 20, 48, 115 (OEIS A000081).
    let t = trees(8);
    let count = |n| t.iter().filter(|x| x.order == n).count();
    assert_eq!(
        (1..=8).map(count).collect::<Vec<_>>(),
        [1, 1, 2, 4, 9, 20, 48, 115]
    );
}

#[test]
fn stage_times_are_row_sums() {
    for i in 0..STAGES {
        let sum: f64 = A[i].iter().sum();
        assert!(
            (sum - C[i]).abs() < 1e-14,
            "c{} = {} but Σ a = {sum}",
            i + 1,
            C[i]
        );
    }
}

#[test]
fn order_8_5_3() {
    let t = trees(8);
    let w = weights(&t, 12);
    // Exact rationals typed to 30 digits: residuals at f64 rounding, ~1e-15.
    let e8 = worst(&t, &w, &B, 8, 1.0);
    assert!(e8 < 1e-13, "order 8: worst residual {e8:e}");
    let b5: Vec<f64> = B.iter().zip(ER).map(|(b, e)| b - e).collect();
    assert!(worst(&t, &w, &b5, 5, 1.0) < 1e-13);
    assert!(
        worst(&t, &w, &b5, 6, 1.0) > 1e-6,
        "the 5th-order weights are not of order 6"
    );
    let mut b3 = [0.0; 12];
    (b3[0], b3[8], b3[11]) = (BHH1, BHH2, BHH3);
    assert!(worst(&t, &w, &b3, 3, 1.0) < 1e-13);
    assert!(worst(&t, &w, &b3, 4, 1.0) > 1e-6);
}

#[test]
fn dense_output_order_7() {
    let t = trees(7);
    let w = weights(&t, STAGES);
    for theta in [0.1, 0.3, 0.5, 0.77, 1.0] {
        // The interpolant's weights b_i(θ), read off from the formula in `dense`.
        let s1 = 1.0 - theta;
        let mut bt = [0.0; STAGES];
        for j in 0..STAGES {
            let b = if j < 12 { B[j] } else { 0.0 };
            let e1 = if j == 0 { 1.0 } else { 0.0 };
            let e13 = if j == 12 { 1.0 } else { 0.0 };
            let (r2, r3) = (b, e1 - b);
            let r4 = r2 - e13 - r3;
            let tail = D[0][j] + theta * (D[1][j] + s1 * (D[2][j] + theta * D[3][j]));
            bt[j] = theta * (r2 + s1 * (r3 + theta * (r4 + s1 * tail)));
        }
        let e = worst(&t, &w, &bt, 7, theta);
        assert!(e < 1e-12, "θ = {theta}: worst residual {e:e}");
    }
}
