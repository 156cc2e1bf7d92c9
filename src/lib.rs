//! primm: PR-IMM multi-object tracking for automotive radar.

pub mod association;
pub mod cli;
pub mod config;
pub mod eval;
pub mod gaussian;
pub mod imm;
pub mod io;
pub mod kernels;
pub mod measurement;
pub mod mode;
pub mod motion;
pub mod offline;
pub mod predictor;
pub mod scenario;
pub mod service;
pub mod stage_timing;
pub mod track;
pub mod track_table;
pub mod tracker;
pub mod validation;
pub mod wire;
