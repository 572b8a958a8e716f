//! Small real polynomials.
