//! Slope limiters.
