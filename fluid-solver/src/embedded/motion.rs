//! Prescribed rigid motion of an embedded surface (`[fluid.embedded] motion`):
//! `x(t) = c + R(t)(X - c) + d(t)`, `v(t) = ω(t) × (x(t) - c - d(t)) + d'(t)`, evaluated exactly
//! at any time so that the surface can be sampled at the ends of every step and the fluid's
//! Hermite path (DESIGN §4) interpolates between exact states.

use interface_protocol::case::{HarmonicForm, Motion};

/// A motion law, ready to evaluate.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidMotion {
    law: Motion,
}

impl RigidMotion {
    pub fn new(law: Motion) -> RigidMotion {
        RigidMotion { law }
    }

    /// Position and velocity at time `t` of the point whose reference position is `x0`.
    pub fn at(&self, x0: [f64; 3], t: f64) -> ([f64; 3], [f64; 3]) {
        match &self.law {
            Motion::Translation { velocity } => {
                ([0, 1, 2].map(|k| x0[k] + velocity[k] * t), *velocity)
            }
            Motion::Harmonic { amplitude, frequency, form } => {
                let w = std::f64::consts::TAU * frequency;
                let (d, dd) = match form {
                    HarmonicForm::OneMinusCos => (1.0 - (w * t).cos(), w * (w * t).sin()),
                    HarmonicForm::Sine => ((w * t).sin(), w * (w * t).cos()),
                };
                ([0, 1, 2].map(|k| x0[k] + amplitude[k] * d), amplitude.map(|a| a * dd))
            }
            Motion::Rotation { center, axis, omega } => {
                let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                let a = axis.map(|c| c / n);
                let r = [0, 1, 2].map(|k| x0[k] - center[k]);
                // Rodrigues: R r = r cos θ + (a × r) sin θ + a (a · r)(1 - cos θ).
                let (s, c) = (omega * t).sin_cos();
                let axr = cross(a, r);
                let ar = a[0] * r[0] + a[1] * r[1] + a[2] * r[2];
                let rr = [0, 1, 2].map(|k| r[k] * c + axr[k] * s + a[k] * ar * (1.0 - c));
                let w = a.map(|x| x * omega);
                ([0, 1, 2].map(|k| center[k] + rr[k]), cross(w, rr))
            }
            Motion::Tabulated { times, displacements } => {
                let k = times.partition_point(|&s| s <= t);
                if k == 0 {
                    return (add(x0, displacements[0]), [0.0; 3]);
                }
                if k == times.len() {
                    return (add(x0, displacements[k - 1]), [0.0; 3]);
                }
                let (t0, t1) = (times[k - 1], times[k]);
                let (d0, d1) = (displacements[k - 1], displacements[k]);
                let f = (t - t0) / (t1 - t0);
                let d = [0, 1, 2].map(|m| d0[m] + f * (d1[m] - d0[m]));
                (add(x0, d), [0, 1, 2].map(|m| (d1[m] - d0[m]) / (t1 - t0)))
            }
        }
    }

    /// Positions and velocities of all reference points `x0` at `t`, into `x` and `v`.
    pub fn sample(&self, x0: &[[f64; 3]], t: f64, x: &mut [[f64; 3]], v: &mut [[f64; 3]]) {
        for ((p, q), r) in x0.iter().zip(x.iter_mut()).zip(v.iter_mut()) {
            (*q, *r) = self.at(*p, t);
        }
    }
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The velocity of every law is the time derivative of its position (central difference),
    /// and each law starts at the reference position where it says it does.
    #[test]
    fn velocities_are_derivatives_of_positions() {
        let laws = [
            Motion::Translation { velocity: [10.0, -2.0, 0.5] },
            Motion::Harmonic {
                amplitude: [0.08, 0.0, 0.01],
                frequency: 100.0,
                form: HarmonicForm::OneMinusCos,
            },
            Motion::Harmonic {
                amplitude: [0.0, 0.3, 0.0],
                frequency: 3.0,
                form: HarmonicForm::Sine,
            },
            Motion::Rotation { center: [1.0, 0.0, 0.0], axis: [1.0, 1.0, 2.0], omega: 7.0 },
            Motion::Tabulated {
                times: vec![0.0, 1e-3, 3e-3],
                displacements: vec![[0.0; 3], [1e-3, 0.0, 0.0], [1e-3, 2e-3, 0.0]],
            },
        ];
        let x0 = [0.3, -0.2, 0.9];
        for law in laws {
            let m = RigidMotion::new(law.clone());
            assert_eq!(
                m.at(x0, 0.0).0.map(|c| (c * 1e12).round()),
                x0.map(|c| (c * 1e12).round()),
                "{law:?}"
            );
            for t in [4e-4, 1.7e-3, 2.2e-3] {
                let h = 1e-8;
                let (p, q) = (m.at(x0, t + h).0, m.at(x0, t - h).0);
                let v = m.at(x0, t).1;
                for k in 0..3 {
                    let d = (p[k] - q[k]) / (2.0 * h);
                    assert!(
                        (d - v[k]).abs() < 1e-5 * (1.0 + v[k].abs()),
                        "{law:?} t {t}: {d} vs {}",
                        v[k]
                    );
                }
            }
        }
    }

    #[test]
    fn rotation_keeps_distances_to_the_axis() {
        let m = RigidMotion::new(Motion::Rotation {
            center: [0.0; 3],
            axis: [0.0, 0.0, 2.0],
            omega: 1.0,
        });
        let (x, v) = m.at([1.0, 0.0, 0.5], std::f64::consts::FRAC_PI_2);
        assert!((x[0]).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15 && (x[2] - 0.5).abs() < 1e-15);
        assert!((v[0] + 1.0).abs() < 1e-15 && v[1].abs() < 1e-15 && v[2] == 0.0);
    }
}
