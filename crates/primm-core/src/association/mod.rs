//! Data association: matching predicted tracks to measurements.

pub mod assignment;
pub mod associator;
pub mod cost;
pub mod reflection_memo;
