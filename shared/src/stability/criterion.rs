//! The four stability criteria and the two positions, named once for every table, file and
//! legend that lists them.

use serde::Serialize;

/// A stability criterion, cheapest first (the levels of the module table in [`super`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    Averaging,
    Mathieu,
    HarmonicBalance,
    Floquet,
}

impl Criterion {
    /// The three criteria measured against Floquet.
    pub const CHEAPER: [Criterion; 3] = [
        Criterion::Averaging,
        Criterion::Mathieu,
        Criterion::HarmonicBalance,
    ];

    /// The key in files: `averaging`, `mathieu`, `harmonic_balance`, `floquet`.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::Averaging => "averaging",
            Criterion::Mathieu => "mathieu",
            Criterion::HarmonicBalance => "harmonic_balance",
            Criterion::Floquet => "floquet",
        }
    }

    /// How people read it in tables and legends.
    pub fn label(self) -> &'static str {
        match self {
            Criterion::Averaging => "averaging",
            Criterion::Mathieu => "Mathieu series",
            Criterion::HarmonicBalance => "harmonic balance",
            Criterion::Floquet => "Floquet",
        }
    }
}

impl core::fmt::Display for Criterion {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which position the linearised equation is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Position {
    Inverted,
    Hanging,
}

impl Position {
    /// The position of a signed k: inverted below zero, hanging otherwise.
    pub fn of_k(k: f64) -> Position {
        if k < 0.0 {
            Position::Inverted
        } else {
            Position::Hanging
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Position::Inverted => "inverted",
            Position::Hanging => "hanging",
        }
    }
}

impl core::fmt::Display for Position {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}
