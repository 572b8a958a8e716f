//! The `kapitza` host tool as a library, so end-to-end tests can run its commands in-process.
