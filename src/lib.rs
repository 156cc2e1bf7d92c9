//! primm: PR-IMM multi-object tracking for automotive radar.

pub mod association;
pub mod measurement;
