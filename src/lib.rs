//! primm: PR-IMM multi-object tracking for automotive radar.

pub mod eval;
pub mod measurement;
