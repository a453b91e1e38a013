//! The rigid body of `[structure.rigid]`: its free DOFs as uncoupled oscillators about the
//! reference point, the motion of its wet nodes (v + ω × r) and the reduction of nodal loads to a
//! force and a moment.
//!
//! Rotations use the rotation vector θ of the free rotational DOFs, R(θ) by Rodrigues' formula
//! and ω = dθ/dt with I dω/dt = M about the principal axes: exact for a rotation about one
//! principal axis (the gyroscopic term ω × Iω vanishes), linearized for several.

use interface_protocol::case::{PrescribedMotion, RigidBody, RIGID_DOFS};
use interface_protocol::coupling::Diagonal;
use interface_protocol::messages::{NodeLoad, NodeState, SurfaceElement};

/// A rigid body with its free DOFs resolved.
#[derive(Debug, Clone)]
pub struct Body {
    /// Index into `RIGID_DOFS` of each free DOF.
    pub dofs: Vec<usize>,
    pub dynamics: Diagonal,
    pub u0: Vec<f64>,
    pub v0: Vec<f64>,
    pub reference: [f64; 3],
    pub wet_nodes: Vec<[f64; 3]>,
    pub elements: Vec<SurfaceElement>,
    /// Prescribed motion per free DOF, if any.
    pub prescribed: Vec<Option<PrescribedMotion>>,
    pub probe: String,
}

impl Body {
    /// The body of a validated case section.
    pub fn new(r: &RigidBody) -> Body {
        let dofs = r.dof_indices();
        let n = dofs.len();
        let values = |v: &interface_protocol::case::PerDof| {
            v.values(n).expect("validated by the case parser")
        };
        let m = dofs.iter().map(|&d| if d < 3 { r.mass } else { r.inertia[d - 3] }).collect();
        let elements = r
            .wet_elements
            .iter()
            .map(|e| {
                let mut nodes = [0u32; 4];
                nodes[..e.len()].copy_from_slice(e);
                SurfaceElement { nodes, n_nodes: e.len() as u8, ..SurfaceElement::default() }
            })
            .collect();
        let prescribed = dofs
            .iter()
            .map(|&d| r.prescribed.iter().find(|p| p.dof == RIGID_DOFS[d]).cloned())
            .collect();
        Body {
            dynamics: Diagonal { m, k: values(&r.stiffness), c: values(&r.damping) },
            u0: values(&r.u0),
            v0: values(&r.v0),
            dofs,
            reference: r.reference,
            wet_nodes: r.wet_nodes.clone(),
            elements,
            prescribed,
            probe: r.probe.clone(),
        }
    }

    /// The six rigid-body coordinates (translation, rotation vector) of the free-DOF values `q`.
    pub fn full(&self, q: &[f64]) -> [f64; 6] {
        let mut out = [0.0; 6];
        for (&d, &x) in self.dofs.iter().zip(q) {
            out[d] = x;
        }
        out
    }

    /// Positions and velocities of the wet nodes for DOF displacements `u` and velocities `v`:
    /// x = X_ref + u_t + R(θ) r, v = v_t + ω × R(θ) r.
    pub fn node_states(&self, u: &[f64], v: &[f64], out: &mut [NodeState]) {
        let (u, v) = (self.full(u), self.full(v));
        let rot = rotation([u[3], u[4], u[5]]);
        let omega = [v[3], v[4], v[5]];
        for (o, r) in out.iter_mut().zip(&self.wet_nodes) {
            let rr = mat_vec(&rot, r);
            let w = cross(omega, rr);
            o.x = std::array::from_fn(|i| self.reference[i] + u[i] + rr[i]);
            o.v = std::array::from_fn(|i| v[i] + w[i]);
        }
    }

    /// The generalized load on the free DOFs: the resultant force and its moment about the current
    /// reference point, Σ R(θ) r_i × f_i.
    pub fn reduce(&self, u: &[f64], loads: &[NodeLoad], out: &mut [f64]) {
        let u = self.full(u);
        let rot = rotation([u[3], u[4], u[5]]);
        let mut g = [0.0; 6];
        for (l, r) in loads.iter().zip(&self.wet_nodes) {
            let m = cross(mat_vec(&rot, r), l.f);
            for i in 0..3 {
                g[i] += l.f[i];
                g[3 + i] += m[i];
            }
        }
        for (o, &d) in out.iter_mut().zip(&self.dofs) {
            *o = g[d];
        }
    }

    /// Overwrites the prescribed DOFs of (u, v, a) with their motion at `t`.
    pub fn impose(&self, t: f64, u: &mut [f64], v: &mut [f64], a: Option<&mut [f64]>) {
        let mut a = a;
        for (i, p) in self.prescribed.iter().enumerate() {
            if let Some(p) = p {
                let [pu, pv, pa] = p.at(t);
                u[i] = pu;
                v[i] = pv;
                if let Some(a) = a.as_deref_mut() {
                    a[i] = pa;
                }
            }
        }
    }

    /// The case's name of free DOF `i` (`"x"`, `"rz"`, ...).
    pub fn dof_name(&self, i: usize) -> &'static str {
        RIGID_DOFS[self.dofs[i]]
    }

    /// The highest undamped natural frequency ω_max = max sqrt(k/m) [rad/s] over the free,
    /// unprescribed DOFs (0 without springs).
    pub fn omega_max(&self) -> f64 {
        let d = &self.dynamics;
        (0..self.dofs.len())
            .filter(|&i| self.prescribed[i].is_none() && d.k[i] > 0.0)
            .map(|i| (d.k[i] / d.m[i]).sqrt())
            .fold(0.0, f64::max)
    }

    /// Largest stable central-difference step, 2 / ω_max over the free, unprescribed DOFs
    /// (`inf` without springs).
    pub fn dt_stable_explicit(&self) -> f64 {
        match self.omega_max() {
            w if w > 0.0 => 2.0 / w,
            _ => f64::INFINITY,
        }
    }
}

/// R(θ) for the rotation vector θ (Rodrigues).
pub fn rotation(theta: [f64; 3]) -> [[f64; 3]; 3] {
    let angle = (theta[0] * theta[0] + theta[1] * theta[1] + theta[2] * theta[2]).sqrt();
    let mut r = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if angle == 0.0 {
        return r;
    }
    let k = theta.map(|t| t / angle);
    let (s, c) = angle.sin_cos();
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = c * r[i][j] + s * kx[i][j] + (1.0 - c) * k[i] * k[j];
        }
    }
    r
}

fn mat_vec(m: &[[f64; 3]; 3], x: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn body(dofs: &[&str], wet: Vec<[f64; 3]>) -> Body {
        let toml = format!(
            "mass = 2.0\ninertia = [1.0, 1.0, 1.0]\ndofs = {dofs:?}\nreference = [1.0, 2.0, 3.0]\nwet_nodes = {wet:?}"
        );
        let r: RigidBody = toml::from_str(&toml).unwrap();
        Body::new(&r)
    }

    #[test]
    fn wet_nodes_move_with_v_plus_omega_cross_r() {
        let b = body(&["x", "rz"], vec![[1.0, 0.0, 0.0]]);
        let theta = 0.3;
        let mut out = [NodeState::default()];
        b.node_states(&[0.5, theta], &[2.0, 4.0], &mut out);
        let (s, c) = theta.sin_cos();
        assert_relative_eq!(out[0].x[0], 1.0 + 0.5 + c, epsilon = 1e-14);
        assert_relative_eq!(out[0].x[1], 2.0 + s, epsilon = 1e-14);
        // v = v_t + ω ẑ × (cos θ, sin θ, 0) = (2 - 4 sin θ, 4 cos θ, 0)
        assert_relative_eq!(out[0].v[0], 2.0 - 4.0 * s, epsilon = 1e-14);
        assert_relative_eq!(out[0].v[1], 4.0 * c, epsilon = 1e-14);
        assert_eq!(out[0].v[2], 0.0);
    }

    #[test]
    fn loads_reduce_to_force_and_moment() {
        let b = body(&["x", "y", "z", "rx", "ry", "rz"], vec![[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]);
        let loads = [NodeLoad { f: [3.0, 0.0, 0.0] }, NodeLoad { f: [1.0, 0.0, 1.0] }];
        let mut g = [0.0; 6];
        b.reduce(&[0.0; 6], &loads, &mut g);
        // Σ f = (4, 0, 1); Σ r × f = (0,1,0)×(3,0,0) + (0,-1,0)×(1,0,1) = (0,0,-3) + (-1,0,1)
        assert_eq!(g, [4.0, 0.0, 1.0, -1.0, 0.0, -2.0]);
    }

    #[test]
    fn rotation_is_orthogonal_and_about_its_axis() {
        let r = rotation([0.2, -0.4, 0.7]);
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
                assert_relative_eq!(dot, if i == j { 1.0 } else { 0.0 }, epsilon = 1e-14);
            }
        }
        let axis = mat_vec(&r, &[0.2, -0.4, 0.7]);
        assert_relative_eq!(axis[1], -0.4, epsilon = 1e-14);
    }
}
