//! The pendulum model: geometry, drive, dimensionless groups, equations of motion, equilibria.
