//! MUSCL reconstruction of primitive variables at edge midpoints (thesis §2.3).

pub mod gradient;
pub mod limiter;
pub mod muscl;
