//! The field's charts: what `kapitza chart` computes and draws.
//!
//! | module | concept |
//! |---|---|
//! | [`map`] | the stability map over a (k, m) grid, in parallel |
//! | [`draw`] | one figure drawn to PNG and SVG with the bundled font, a title, a legend |

pub mod draw;
pub mod map;
