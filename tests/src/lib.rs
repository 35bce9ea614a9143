//! Shared code of the system tests: the Rust-model reference cases (see [`reference`]).

pub mod reference;
