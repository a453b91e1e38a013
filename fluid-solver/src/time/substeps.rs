//! Fixed substeps of a coupled run (`fluid.time.substeps = M`): the fluid crosses each coupling
//! interval `[t_from, t_to]` in exactly `M` equal RK2 steps `h = (t_to - t_from) / M` instead of
//! its CFL steps, so that its own temporal error, O(h²) for RK2, shrinks with the coupling step
//! as a temporal order study of the coupling schemes (thesis §3.2) needs.
//! A step longer than the stable step is refused: the explicit scheme would be unstable.

/// The `M` equal steps over one coupling interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixedSteps {
    pub substeps: u64,
    pub t_from: f64,
    pub t_to: f64,
}

impl FixedSteps {
    /// Where step `k` (from 0) ends: `t_from + (k + 1) h`, the last one exactly on `t_to`
    /// (computed from the interval's start, so round-off does not accumulate over the steps).
    pub fn stop(&self, k: u64) -> f64 {
        if k + 1 >= self.substeps {
            return self.t_to;
        }
        let s = (k + 1) as f64 / self.substeps as f64;
        self.t_from + s * (self.t_to - self.t_from)
    }

    /// Checks the step `dt` the stepper took towards `stop` from `t`: shorter than `stop - t`
    /// (beyond round-off), the stable step limited it and the fixed step is refused, saying by
    /// how much it exceeds the stable step and how many substeps it would need.
    pub fn check(&self, t: f64, stop: f64, dt: f64) -> Result<(), String> {
        let h = stop - t;
        if dt >= h * (1.0 - 1e-9) {
            return Ok(());
        }
        let interval = self.t_to - self.t_from;
        let needed = (interval / dt).ceil() as u64;
        Err(format!(
            "fluid.time.substeps = {m}: the fixed step {h:.4e} s (the coupling interval [{a:e}, \
             {b:e}] in {m} steps) exceeds the stable step {dt:.4e} s at t = {t:e} (fluid.numerics.cfl \
             times the CFL step, and the embedded surface's half-edge limit) by {pct:.1}%; give \
             at least {needed} substeps, or a shorter coupling.dt",
            m = self.substeps,
            a = self.t_from,
            b = self.t_to,
            pct = 100.0 * (h / dt - 1.0),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_end_on_equal_fractions_and_the_last_on_the_interval_end() {
        let f = FixedSteps { substeps: 3, t_from: 0.1, t_to: 0.4 };
        let stops: Vec<f64> = (0..3).map(|k| f.stop(k)).collect();
        assert!((stops[0] - 0.2).abs() < 1e-15 && (stops[1] - 0.3).abs() < 1e-15, "{stops:?}");
        assert_eq!(stops[2], 0.4);
    }

    #[test]
    fn a_step_cut_by_the_stable_step_is_refused_with_the_substeps_needed() {
        let f = FixedSteps { substeps: 4, t_from: 0.0, t_to: 1.0 };
        assert!(f.check(0.25, 0.5, 0.25).is_ok());
        // Round-off in `stop - t` is not a cut.
        assert!(f.check(0.25, 0.5, 0.25 * (1.0 - 1e-12)).is_ok());
        let err = f.check(0.25, 0.5, 0.2).unwrap_err();
        for part in ["fluid.time.substeps = 4", "exceeds the stable step", "by 25.0%", "at least 5"]
        {
            assert!(err.contains(part), "`{part}` not in: {err}");
        }
    }
}
