//! Time integration of `|C_i| dW_i/dt = -R_i(W)`: the explicit TVD Runge-Kutta 2 ([`rk2`]) with
//! a global or local CFL time step ([`cfl`]), or, coupled, a fixed number of equal steps per
//! coupling interval ([`substeps`]).

pub mod cfl;
pub mod rk2;
pub mod substeps;

pub use cfl::TimeStepping;
pub use rk2::rk2_step;
pub use substeps::FixedSteps;

/// Relative slack within which a time counts as reached.
const REACHED: f64 = 1e-12;

/// Whether the time `t` has reached `target` (to a relative `1e-12`, so that round-off in a sum
/// of steps does not leave a step of zero length to take).
pub fn reached(t: f64, target: f64) -> bool {
    t >= target - REACHED * target.abs()
}
