//! Time integration of `|C_i| dW_i/dt = -R_i(W)`: the explicit TVD Runge-Kutta 2 ([`rk2`]) with
//! a global or local CFL time step ([`cfl`]).

pub mod cfl;
pub mod rk2;

pub use cfl::TimeStepping;
pub use rk2::rk2_step;
