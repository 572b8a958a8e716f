//! Canonical cases with known answers.
