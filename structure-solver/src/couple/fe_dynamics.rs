//! The finite-element structure as the staggered schemes' [`Dynamics`]: central differences for
//! CSS and C0, the implicit midpoint rule for A6 (DESIGN §4), the integrator created at START from
//! the load `F^0`. The model keeps every history the internal force needs (rotations, plastic
//! strains), so [`interface_protocol::coupling::Staggered`] sequences it as it does a rigid body.

use interface_protocol::case::Scheme;
use interface_protocol::coupling::Dynamics;

use crate::assembly::FeModel;
use crate::time::{CentralDifference, Implicit, ImplicitScheme};

/// The integrator of the scheme, created at START.
pub enum Stepper {
    Explicit(CentralDifference),
    Midpoint(Implicit),
}

/// The model, its integrator once started, and the initial velocity before.
pub struct FeDynamics {
    pub model: FeModel,
    pub stepper: Option<Stepper>,
    scheme: Scheme,
    v0: Vec<f64>,
    /// a = 0 before START.
    zero: Vec<f64>,
}

impl FeDynamics {
    pub fn new(model: FeModel, scheme: Scheme, v0: Vec<f64>) -> FeDynamics {
        let zero = vec![0.0; v0.len()];
        FeDynamics { model, stepper: None, scheme, v0, zero }
    }

    /// The integrator of a checkpoint's state (`state`, central differences' `v_half` when the
    /// checkpoint holds it), as if START and the steps before it had run: the model holds the
    /// checkpoint's configuration already (`restart::restore_state`).
    pub fn resume(&mut self, state: crate::time::Dynamics, v_half: Option<&[f64]>) {
        self.stepper = Some(match self.scheme {
            Scheme::A6 => {
                Stepper::Midpoint(Implicit::resume(&self.model, ImplicitScheme::Midpoint, state))
            }
            Scheme::Css | Scheme::C0 => {
                let mut cd = CentralDifference::resume(&self.model, state);
                if let Some(v) = v_half.filter(|v| v.len() == cd.v_half.len()) {
                    cd.v_half.copy_from_slice(v);
                }
                Stepper::Explicit(cd)
            }
        });
    }

    /// Drops the midpoint rule's kept factor at a checkpoint, so that the next step starts as
    /// a resumed integrator's does and a restart from there continues bitwise.
    pub fn forget_factor(&mut self) {
        if let Some(Stepper::Midpoint(im)) = self.stepper.as_mut() {
            im.forget_factor();
        }
    }

    /// Central differences' `v^{n+1/2}` of the last step (None for the midpoint rule).
    pub fn v_half(&self) -> Option<&[f64]> {
        match &self.stepper {
            Some(Stepper::Explicit(cd)) => Some(&cd.v_half),
            _ => None,
        }
    }

    /// The dynamic state (`t`, `v`, `a`) of the integrator, once started.
    pub fn state(&self) -> Option<&crate::time::Dynamics> {
        match &self.stepper {
            Some(Stepper::Explicit(cd)) => Some(&cd.state),
            Some(Stepper::Midpoint(im)) => Some(&im.state),
            None => None,
        }
    }

    /// The internal force of central differences (None for the midpoint rule).
    pub fn internal_force(&self) -> Option<&[f64]> {
        match &self.stepper {
            Some(Stepper::Explicit(cd)) => Some(cd.internal_force()),
            _ => None,
        }
    }
}

impl Dynamics for FeDynamics {
    type Error = String;

    fn displacement(&self, out: &mut [f64]) {
        self.model.displacement_dofs(out);
    }

    fn velocity(&self) -> &[f64] {
        self.state().map_or(&self.v0, |s| &s.v)
    }

    fn acceleration(&self) -> &[f64] {
        self.state().map_or(&self.zero, |s| &s.a)
    }

    fn half_velocity(&self) -> &[f64] {
        match &self.stepper {
            Some(Stepper::Explicit(cd)) => &cd.v_half,
            _ => self.velocity(),
        }
    }

    fn start(&mut self, f0: &[f64]) -> Result<(), String> {
        let v0 = self.v0.clone();
        self.stepper = Some(match self.scheme {
            Scheme::A6 => Stepper::Midpoint(Implicit::new(
                &mut self.model,
                ImplicitScheme::Midpoint,
                0.0,
                v0,
                Some(f0),
            )),
            Scheme::Css | Scheme::C0 => {
                Stepper::Explicit(CentralDifference::new(&mut self.model, 0.0, v0, Some(f0)))
            }
        });
        Ok(())
    }

    /// Central differences only: the midpoint rule has no half step (A6 never asks for one).
    fn advance_positions(&mut self, dt: f64) {
        if let Some(Stepper::Explicit(cd)) = self.stepper.as_mut() {
            cd.advance_positions(&mut self.model, dt);
        }
    }

    fn complete(&mut self, f: &[f64], dt: f64) -> Result<(), String> {
        match self.stepper.as_mut() {
            Some(Stepper::Explicit(cd)) => {
                cd.complete(&mut self.model, dt, Some(f));
                Ok(())
            }
            _ => Err(format!(
                "the {:?} scheme's structure has no central-difference step",
                self.scheme
            )),
        }
    }

    fn implicit_midpoint(&mut self, f: &[f64], dt: f64) -> Result<(), String> {
        match self.stepper.as_mut() {
            Some(Stepper::Midpoint(im)) => {
                im.step(&mut self.model, dt, Some(f)).map(|_| ()).map_err(|e| e.to_string())
            }
            _ => Err(format!("the {:?} scheme's structure has no midpoint step", self.scheme)),
        }
    }
}
