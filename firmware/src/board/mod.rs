//! The board map: which board the firmware is built for. One module per board, chosen by a
//! Cargo feature; each exports the same names (`chip_config`, `split`, `Board` and its driver
//! structs, `Irqs`, `CONTROL_IRQ`, the calibration constants). To add a board, copy
//! `nucleo_g474re.rs`, change its pins and constants, and add a feature that selects it.

#[cfg(feature = "nucleo-g474re")]
mod nucleo_g474re;
#[cfg(feature = "nucleo-g474re")]
pub use nucleo_g474re::*;

#[cfg(not(feature = "nucleo-g474re"))]
compile_error!("choose a board feature (the default is `nucleo-g474re`)");
