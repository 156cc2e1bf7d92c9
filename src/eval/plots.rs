//! Figures (placeholder replaced below).
