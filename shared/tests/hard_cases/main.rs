//! The hard-case suite (physics §6, docs/hard-cases.md): each case states what could go wrong, the
//! guard the code uses against it and a criterion that catches the failure. Test names carry the
//! case's id (`hcNN_…`), the same as in the document.
//!
//! Run it: `cargo test -p kapitza-core --test hard_cases` (CI runs it with the whole workspace);
//! the long variants: `cargo test -p kapitza-core --test hard_cases -- --ignored`.

mod bad_parameters;
mod energy;
mod floquet_det;
mod large_r;
mod merging;
mod narrow_window;
mod rig;
mod rotation;
mod singular_r;
mod stick_slip;
mod support;
