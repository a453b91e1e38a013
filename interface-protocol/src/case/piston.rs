//! `[fluid.piston]`: an acoustic column closed by a piston face, F = -A (p0 + ρ0 c0 v·n) n (linear
//! acoustics: a face moving into the column with normal velocity v·n raises the pressure by the
//! impedance ρ0 c0 times it; no reflection comes back from the column, which is semi-infinite).

use serde::Deserialize;

/// `[fluid.piston]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PistonFluid {
    /// Face area A [m²].
    pub area: f64,
    /// Ambient pressure p0 [Pa].
    pub p0: f64,
    /// Ambient density ρ0 [kg/m³].
    pub rho0: f64,
    /// Sound speed c0 [m/s].
    pub c0: f64,
    /// Unit normal of the face pointing from the piston into the fluid column; default +x.
    #[serde(default = "default_normal")]
    pub normal: [f64; 3],
    /// Name of the face in `probes.csv`.
    #[serde(default = "default_probe")]
    pub probe: String,
}

fn default_probe() -> String {
    "face".to_string()
}

fn default_normal() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

impl PistonFluid {
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        super::require_positive("fluid.piston.area", self.area)?;
        super::require_positive("fluid.piston.rho0", self.rho0)?;
        super::require_positive("fluid.piston.c0", self.c0)?;
        if !self.p0.is_finite() {
            return Err(("fluid.piston.p0".into(), "expected a finite pressure".into()));
        }
        let n = (self.normal.iter().map(|c| c * c).sum::<f64>()).sqrt();
        if (n - 1.0).abs() > 1e-9 {
            return Err((
                "fluid.piston.normal".into(),
                format!("expected a unit vector, its length is {n}"),
            ));
        }
        Ok(())
    }
}
