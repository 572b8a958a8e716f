//! One module per task; each owns its share of the board (`board::Board`) and talks to the
//! others only through `channels`.
//!
//! | task | executor | owns | does |
//! |---|---|---|---|
//! | [`pendulum`] | control (interrupt) | the pendulum encoder's SPI bus | samples θ at the sample rate |
//! | [`control`] | control (interrupt) | H-bridge, crank encoder, current sense | the rig logic per sample: drive phase (DDS), estimator; per control tick: safety, phase lock, motor; applies the link's commands |
//! | [`tilt`] | thread | the tilt servo's PWM | points the drive at the slewed θd |
//! | [`safety`] | thread | e-stop input, independent watchdog | publishes the e-stop line; feeds the watchdog while the control loop ticks |
//! | [`link`] | thread | USART2 | frames in, requests decoded and answered, telemetry out |
//! | [`persist`] | thread | flash | loads the configuration at power-up, stores accepted ones |

pub mod control;
pub mod link;
pub mod pendulum;
pub mod persist;
pub mod safety;
pub mod tilt;
