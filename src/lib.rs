//! primm: PR-IMM multi-object tracking for automotive radar.

pub mod association;
pub mod cli;
pub mod eval;
pub mod io;
pub mod measurement;
pub mod gaussian;
pub mod mode;
pub mod config;
pub mod motion;
pub mod predictor;
pub mod scenario;
pub mod service;
pub mod imm;
pub mod track;
pub mod track_table;
pub mod stage_timing;
pub mod tracker;
pub mod validation;
pub mod wire;
