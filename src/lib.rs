//! primm: PR-IMM multi-object tracking for automotive radar.

pub mod cli;
pub mod io;
pub mod measurement;
pub mod scenario;
