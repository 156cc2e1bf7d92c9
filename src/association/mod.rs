//! Data association: matching predicted tracks to measurements.

pub mod assignment;
