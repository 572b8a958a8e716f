//! The coefficients of the Runge–Kutta–Nyström pair 8(6) of Dormand, El-Mikkawy & Prince:
//! nine stages, the ninth evaluated at the new position (first stage of the next step, FSAL),
//! so eight evaluations of the acceleration per step.
//!
//! Source: J. R. Dormand, M. E. A. El-Mikkawy, P. J. Prince, "High-order embedded
//! Runge–Kutta–Nyström formulae", *IMA J. Numer. Anal.* 7 (1987) 423–430, the 8(6) pair, as
//! published in exact rationals. `order_conditions` (a unit test) checks every Nyström order
//! condition of both orders on exactly these arrays.
//!
//! ```text
//! Y_i  = y0 + c_i h y0' + h² Σ_j a_ij g(t0 + c_i h, Y_j)
//! y1   = y0 + h y0' + h² Σ_i bbar_i g_i,     y1' = y0' + h Σ_i b_i g_i        (order 8)
//! ŷ1   = y0 + h y0' + h² Σ_i bbar6_i g_i,    ŷ1' = y0' + h Σ_i b6_i g_i      (order 6)
//! ```
//! Stage 9's row of `A` is `BBAR`, so its position is y1 itself.

/// Number of stages (the FSAL stage included).
pub const STAGES: usize = 9;

/// Nodes c_i.
pub const C: [f64; STAGES] = [
    0.0,
    1.0 / 20.0,
    1.0 / 10.0,
    3.0 / 10.0,
    1.0 / 2.0,
    7.0 / 10.0,
    9.0 / 10.0,
    1.0,
    1.0,
];

/// a_ij (strictly lower triangular; row i lists j < i).
pub const A: [[f64; STAGES]; STAGES] = [
    [0.0; STAGES],
    [1.0 / 800.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 600.0, 1.0 / 300.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        9.0 / 200.0,
        -9.0 / 100.0,
        9.0 / 100.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -66701.0 / 197352.0,
        28325.0 / 32892.0,
        -2665.0 / 5482.0,
        2170.0 / 24669.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        227015747.0 / 304251000.0,
        -54897451.0 / 30425100.0,
        12942349.0 / 10141700.0,
        -9499.0 / 304251.0,
        539.0 / 9250.0,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -1131891597.0 / 901789000.0,
        41964921.0 / 12882700.0,
        -6663147.0 / 3220675.0,
        270954.0 / 644135.0,
        -108.0 / 5875.0,
        114.0 / 1645.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        13836959.0 / 3667458.0,
        -17731450.0 / 1833729.0,
        1063919505.0 / 156478208.0,
        -33213845.0 / 39119552.0,
        13335.0 / 28544.0,
        -705.0 / 14272.0,
        1645.0 / 57088.0,
        0.0,
        0.0,
    ],
    BBAR,
];

/// Position weights of order 8.
pub const BBAR: [f64; STAGES] = [
    223.0 / 7938.0,
    0.0,
    1175.0 / 8064.0,
    925.0 / 6048.0,
    41.0 / 448.0,
    925.0 / 14112.0,
    1175.0 / 72576.0,
    0.0,
    0.0,
];

/// Velocity weights of order 8.
pub const B: [f64; STAGES] = [
    223.0 / 7938.0,
    0.0,
    5875.0 / 36288.0,
    4625.0 / 21168.0,
    41.0 / 224.0,
    4625.0 / 21168.0,
    5875.0 / 36288.0,
    223.0 / 7938.0,
    0.0,
];

/// Position weights of the embedded order-6 solution.
pub const BBAR6: [f64; STAGES] = [
    7987313.0 / 109941300.0,
    0.0,
    1610737.0 / 44674560.0,
    10023263.0 / 33505920.0,
    -497221.0 / 12409600.0,
    10023263.0 / 78180480.0,
    1610737.0 / 402071040.0,
    0.0,
    0.0,
];

/// Velocity weights of the embedded order-6 solution.
pub const B6: [f64; STAGES] = [
    7987313.0 / 109941300.0,
    0.0,
    1610737.0 / 40207104.0,
    10023263.0 / 23454144.0,
    -497221.0 / 6204800.0,
    10023263.0 / 23454144.0,
    1610737.0 / 40207104.0,
    -4251941.0 / 54970650.0,
    3.0 / 20.0,
];
