//! The root package of the workspace: re-exports both crates, owns the top-level examples
//! and integration tests, and compiles the README's code as a doctest.
#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub use tetpbd;
pub use tetpbd_rapier;
