//! Finite rotations: the exponential and logarithm of SO(3) and the tangent map between a
//! rotation vector and the spatial (left) spin, as used by element-independent corotation
//! (Felippa & Haugen 2005, CMAME 194:2285, §4-5).

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Skew matrix `[v]×` with `[v]× w = v × w`.
pub fn spin(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `exp([θ]×)`, the rotation by the rotation vector `θ` (Rodrigues).
pub fn exp(theta: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::new(*theta).into_inner()
}

/// The rotation vector of `r`, `|θ| <= π`, through the quaternion (Shepperd's extraction and
/// `atan2`, accurate for small angles where `acos` of the trace is not).
pub fn log(r: &Matrix3<f64>) -> Vector3<f64> {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    let (mut w, mut v) = (q.w, q.imag());
    if w < 0.0 {
        w = -w;
        v = -v;
    }
    let s = v.norm();
    if s < 1e-300 {
        return Vector3::zeros();
    }
    v * (2.0 * s.atan2(w) / s)
}

/// `T(θ)⁻¹`: maps a spatial spin `δω` (with `δR = [δω]× R`) to the variation of the rotation
/// vector, `δθ = T⁻¹ δω`, `T⁻¹ = I - ½[θ]× + η [θ]×²`, `η = (1 - (φ/2) cot(φ/2)) / φ²`
/// (Felippa & Haugen 2005, eq. 4.10; series for small `φ = |θ|`).
pub fn tangent_inverse(theta: &Vector3<f64>) -> Matrix3<f64> {
    let phi2 = theta.norm_squared();
    let phi = phi2.sqrt();
    let eta = if phi < 1e-3 {
        1.0 / 12.0 + phi2 / 720.0
    } else {
        let half = 0.5 * phi;
        (1.0 - half / half.tan()) / phi2
    };
    let s = spin(theta);
    Matrix3::identity() - 0.5 * s + eta * s * s
}

/// `∂(T⁻ᵀ(θ) f)/∂θ` at fixed `f`: with `T⁻ᵀ f = f + ½ θ×f + η θ×(θ×f)`,
/// `-½[f]× - η([θ×f]× + [θ]×[f]×) + μ (θ×(θ×f)) θᵀ`, `μ = η'(φ)/φ` (the `K_GM` term of
/// Felippa & Haugen 2005, eq. 4.17; series for small `φ`).
pub fn tangent_inverse_transpose_derivative(
    theta: &Vector3<f64>,
    f: &Vector3<f64>,
) -> Matrix3<f64> {
    let phi2 = theta.norm_squared();
    let phi = phi2.sqrt();
    let (eta, mu) = if phi < 0.05 {
        (
            1.0 / 12.0 + phi2 / 720.0 + phi2 * phi2 / 30240.0,
            1.0 / 360.0 + phi2 / 7560.0 + phi2 * phi2 / 201600.0,
        )
    } else {
        let half = 0.5 * phi;
        let c = half / half.tan();
        let dc = 0.5 / half.tan() - 0.25 * phi / (half.sin() * half.sin());
        ((1.0 - c) / phi2, -dc / (phi2 * phi) - 2.0 * (1.0 - c) / (phi2 * phi2))
    };
    let tf = theta.cross(f);
    -0.5 * spin(f) - eta * (spin(&tf) + spin(theta) * spin(f))
        + mu * theta.cross(&tf) * theta.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `δθ = T⁻¹ δω` agrees with a finite difference of `log(exp(h δω) R(θ))`.
    #[test]
    fn tangent_inverse_matches_finite_difference() {
        let theta = Vector3::new(0.7, -1.1, 0.4);
        let r = exp(&theta);
        let tinv = tangent_inverse(&theta);
        let h = 1e-6;
        for k in 0..3 {
            let mut w = Vector3::zeros();
            w[k] = h;
            let tp = log(&(exp(&w) * r));
            let tm = log(&(exp(&(-w)) * r));
            let fd = (tp - tm) / (2.0 * h);
            let an = tinv.column(k);
            assert!((fd - an).norm() < 1e-8, "column {k}: fd {fd:?} analytic {an:?}");
        }
        // ∂(T⁻ᵀ f)/∂θ, both branches
        let f = Vector3::new(0.3, 1.2, -0.7);
        for theta in [Vector3::new(0.7, -1.1, 0.4), Vector3::new(0.01, -0.02, 0.03)] {
            let an = tangent_inverse_transpose_derivative(&theta, &f);
            for k in 0..3 {
                let mut d = Vector3::zeros();
                d[k] = h;
                let fd = (tangent_inverse(&(theta + d)).transpose() * f
                    - tangent_inverse(&(theta - d)).transpose() * f)
                    / (2.0 * h);
                assert!(
                    (fd - an.column(k)).norm() < 1e-8,
                    "∂T⁻ᵀf/∂θ column {k}: {fd:?} vs {:?}",
                    an.column(k)
                );
            }
        }
        // small-angle branch
        let theta = Vector3::new(1e-4, 2e-4, -3e-4);
        let r = exp(&theta);
        let tinv = tangent_inverse(&theta);
        for k in 0..3 {
            let mut w = Vector3::zeros();
            w[k] = h;
            let fd = (log(&(exp(&w) * r)) - log(&(exp(&(-w)) * r))) / (2.0 * h);
            assert!((fd - tinv.column(k)).norm() < 1e-8);
        }
    }
}
