//! Rigid bodies and rigid links (DESIGN §6: wet nodes move with `v + ω × r`, loads reduce to
//! a force and a moment). A body is a set of slave nodes tied to a master (reference) node by
//! finite rotations, `x_s = x_m + R_m X_s`, `R_s = R_m R̄_s` (`X_s`, `R̄_s` the slave's offset
//! and rotation in the master's frame when the body was made), so `δu_s = δu_m + δθ_m × r_s`,
//! `δθ_s = δθ_m` with `r_s = x_s - x_m`: the transformation `T` of the model's reduction
//! `K_r = Tᵀ K T`, `f_r = Tᵀ f` (`assembly::FeModel` applies it). A rigid link is a body of
//! two nodes.
//!
//! The master carries the body's mass `M`, the offset `c` of its mass centre and the inertia
//! tensor `J_c` about that centre, both fixed in the body and rotated with it: the 6x6 block
//! `[[M I, -M[c]×], [M[c]×, J_c - M[c]×²]]` in `(v_m, ω)`. Explicit steps kick momenta with
//! that block and drift with the free rigid-body flow (`RigidBody::drift`): the centre moves
//! uniformly and the rotation follows Euler's equations at constant spatial angular momentum,
//! integrated by the symmetric splitting into rotations about the principal axes (McLachlan
//! 1993, Phys. Rev. Lett. 71:3043; Dullweber, Leimkuhler & McLachlan 1997, J. Chem. Phys.
//! 107:5840): explicit, angular momentum kept to round-off, energy to `O(Δt²)` without drift.

use nalgebra::{Matrix3, Matrix6, SymmetricEigen, Vector3, Vector6};

use crate::elements::rotation::{exp, spin};

/// Where the master (reference) node of a rigid body is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RigidReference {
    /// An existing node; one outside the set joins the body with its own mass.
    Node(usize),
    /// A new node at this point (appended after the mesh nodes).
    Point([f64; 3]),
    /// A new node at the body's mass centre (nodal masses and the extra mass).
    MassCentre,
}

/// Mass a user adds to a body (a part not meshed: an engine, a ballast).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExtraMass {
    pub mass: f64,
    /// Centre of the extra mass; `None`: at the master node.
    pub centre: Option<[f64; 3]>,
    /// Inertia tensor about `centre`, in the global axes of the configuration the body is
    /// made in.
    pub inertia: [[f64; 3]; 3],
}

#[derive(Debug, PartialEq, thiserror::Error)]
pub enum RigidError {
    #[error("rigid body: the node set is empty")]
    Empty,
    #[error("rigid body: node {node} out of range ({n} nodes)")]
    NodeRange { node: usize, n: usize },
    #[error("rigid body: node {node} already belongs to rigid body {body}")]
    TwoBodies { node: usize, body: usize },
    #[error("rigid body: slave node {node} has its dof {dof} fixed or prescribed (only the reference node of a body may be constrained)")]
    ConstrainedSlave { node: usize, dof: usize },
    #[error("rigid body: node {node} lies on a skew symmetry plane")]
    SymmetryPlane { node: usize },
    #[error("rigid body: the extra mass and inertia must be finite, the mass >= 0 and the inertia symmetric positive semi-definite")]
    BadExtra,
    #[error("rigid body: the body has no mass, so no mass centre for its reference node")]
    NoMass,
    #[error("rigid body: its inertia about the mass centre is singular (principal moments {moments:?}): nodes without rotary inertia on a line; give an `ExtraMass` inertia")]
    SingularInertia { moments: [f64; 3] },
}

/// Principal moments and axes (columns, a proper rotation) of a symmetric tensor.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Principal {
    axes: Matrix3<f64>,
    moments: Vector3<f64>,
}

impl Principal {
    fn of(j: &Matrix3<f64>) -> Self {
        let e = SymmetricEigen::new(*j);
        let mut axes = e.eigenvectors;
        if axes.determinant() < 0.0 {
            axes.column_mut(2).neg_mut();
        }
        Principal { axes, moments: e.eigenvalues }
    }

    /// `J⁻¹ π` in the frame `r` (body axes `r · axes`).
    fn solve(&self, r: &Matrix3<f64>, pi: &Vector3<f64>) -> Vector3<f64> {
        let b = r * self.axes;
        let body = b.transpose() * pi;
        b * body.component_div(&self.moments)
    }
}

/// Mass, centre and inertia of a body, in the master's frame of the configuration it was made
/// in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct MassProperties {
    pub mass: f64,
    /// Mass centre offset from the master.
    pub centre: Vector3<f64>,
    /// Inertia about the mass centre.
    pub inertia: Matrix3<f64>,
    about_centre: Principal,
    about_master: Principal,
}

/// A rigid body: a master node and its slaves.
#[derive(Debug, Clone)]
pub struct RigidBody {
    pub master: usize,
    pub slaves: Vec<usize>,
    /// Slave offsets `X_s` and rotations `R̄_s` in the master's frame.
    offsets: Vec<Vector3<f64>>,
    relative: Vec<Matrix3<f64>>,
    /// Master rotation when the body was made (maps the body frame to global).
    frame0: Matrix3<f64>,
    /// Extra mass, its centre offset and inertia in the body frame.
    extra: (f64, Vector3<f64>, Matrix3<f64>),
    pub(crate) props: MassProperties,
}

impl RigidBody {
    /// A body of `slaves` on `master` in the configuration `(x, r)`; `extra` in global axes.
    pub(crate) fn new(
        master: usize,
        slaves: Vec<usize>,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        extra: &ExtraMass,
        node_mass: &[f64],
    ) -> Result<Self, RigidError> {
        let ji = Matrix3::from_fn(|i, j| extra.inertia[i][j]);
        let finite = extra.mass.is_finite() && ji.iter().all(|v| v.is_finite());
        let symmetric = (ji - ji.transpose()).abs().max() <= 1e-12 * ji.abs().max();
        if !finite || extra.mass < 0.0 || !symmetric || Principal::of(&ji).moments.min() < 0.0 {
            return Err(RigidError::BadExtra);
        }
        let (xm, rm) = (x[master], r[master]);
        let offsets = slaves.iter().map(|&s| rm.transpose() * (x[s] - xm)).collect();
        let relative = slaves.iter().map(|&s| rm.transpose() * r[s]).collect();
        let centre = extra.centre.map_or(Vector3::zeros(), |c| Vector3::from(c) - xm);
        let extra = (extra.mass, rm.transpose() * centre, rm.transpose() * ji * rm);
        let mut body = RigidBody {
            master,
            slaves,
            offsets,
            relative,
            frame0: rm,
            extra,
            props: MassProperties {
                mass: 0.0,
                centre: Vector3::zeros(),
                inertia: Matrix3::zeros(),
                about_centre: Principal::of(&Matrix3::identity()),
                about_master: Principal::of(&Matrix3::identity()),
            },
        };
        body.set_mass(node_mass);
        let p = &body.props;
        let moments = p.about_centre.moments;
        if p.mass > 0.0 && moments.min() <= 1e-12 * moments.max() {
            return Err(RigidError::SingularInertia { moments: [moments.x, moments.y, moments.z] });
        }
        Ok(body)
    }

    /// The body's mass centre in the configuration it is made in, from the nodal masses and
    /// the extra mass (before `new`: a reference at the mass centre).
    pub(crate) fn centre_of(
        nodes: &[usize],
        x: &[Vector3<f64>],
        extra: &ExtraMass,
        node_mass: &[f64],
    ) -> Option<Vector3<f64>> {
        let mut m = 0.0;
        let mut s = Vector3::zeros();
        for &n in nodes {
            m += node_mass[6 * n];
            s += node_mass[6 * n] * x[n];
        }
        if let Some(c) = extra.centre {
            m += extra.mass;
            s += extra.mass * Vector3::from(c);
        }
        (m > 0.0).then(|| s / m)
    }

    /// The body's total mass.
    pub fn mass(&self) -> f64 {
        self.props.mass
    }

    /// Recomputes the mass properties from the nodal lumped masses (translational mass and
    /// diagonal rotary inertia per node, global axes at creation).
    pub(crate) fn set_mass(&mut self, node_mass: &[f64]) {
        let q = self.frame0;
        let parts = std::iter::once((self.master, Vector3::zeros()))
            .chain(self.slaves.iter().copied().zip(self.offsets.iter().copied()));
        let mut nodes: Vec<(f64, Vector3<f64>, Matrix3<f64>)> = parts
            .map(|(n, p)| {
                let d =
                    Vector3::new(node_mass[6 * n + 3], node_mass[6 * n + 4], node_mass[6 * n + 5]);
                (node_mass[6 * n], p, q.transpose() * Matrix3::from_diagonal(&d) * q)
            })
            .collect();
        nodes.push(self.extra);
        let mass: f64 = nodes.iter().map(|n| n.0).sum();
        let centre = if mass > 0.0 {
            nodes.iter().map(|n| n.0 * n.1).sum::<Vector3<f64>>() / mass
        } else {
            Vector3::zeros()
        };
        let mut inertia = Matrix3::zeros();
        for (m, p, j) in &nodes {
            let d = p - centre;
            inertia += j + *m * (Matrix3::identity() * d.norm_squared() - d * d.transpose());
        }
        let sc = spin(&centre);
        let about_master = inertia - mass * sc * sc;
        self.props = MassProperties {
            mass,
            centre,
            inertia,
            about_centre: Principal::of(&inertia),
            about_master: Principal::of(&about_master),
        };
    }

    /// Slave `k`'s position and rotation for the master at `(xm, rm)`.
    pub(crate) fn slave(
        &self,
        k: usize,
        xm: &Vector3<f64>,
        rm: &Matrix3<f64>,
    ) -> (Vector3<f64>, Matrix3<f64>) {
        (xm + rm * self.offsets[k], rm * self.relative[k])
    }

    /// The extra mass and its centre's offset from the master for the master rotation `rm`.
    pub(crate) fn extra_weight(&self, rm: &Matrix3<f64>) -> (f64, Vector3<f64>) {
        (self.extra.0, rm * self.frame0.transpose() * self.extra.1)
    }

    /// The master's 6x6 mass block in `(v_m, ω)` for the master rotation `rm`.
    pub(crate) fn mass6(&self, rm: &Matrix3<f64>) -> Matrix6<f64> {
        let p = &self.props;
        let q = rm * self.frame0.transpose();
        let c = q * p.centre;
        let sc = spin(&c);
        let jc = q * p.inertia * q.transpose();
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&(Matrix3::identity() * p.mass));
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-p.mass * sc));
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(p.mass * sc));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&(jc - p.mass * sc * sc));
        m
    }

    /// `M₆⁻¹ f` for the master rotation `rm`, with the master's constrained dofs held (zero
    /// acceleration there).
    pub(crate) fn inverse_mass(
        &self,
        rm: &Matrix3<f64>,
        constrained: &[bool],
        f: &[f64],
    ) -> Vector6<f64> {
        let mut m = self.mass6(rm);
        let mut rhs = Vector6::from_column_slice(f);
        for (i, &c) in constrained.iter().enumerate() {
            if c {
                m.row_mut(i).fill(0.0);
                m.column_mut(i).fill(0.0);
                m[(i, i)] = 1.0;
                rhs[i] = 0.0;
            }
        }
        m.cholesky().map_or(Vector6::zeros(), |ch| ch.solve(&rhs))
    }

    /// The explicit drift of the master over `dt` from the rotation `rm`: with all six dofs free,
    /// the free flow about the mass centre; with the translations held, the free flow about
    /// the master as a pivot; otherwise `du` as given (`du = dt v_half` rotated by the plain
    /// exponential). `v` (`[v_m, ω]` after the kick) is replaced by the velocity of the same
    /// momentum at the end. Returns the master's translation increment and end rotation.
    pub(crate) fn drift(
        &self,
        rm: &Matrix3<f64>,
        constrained: &[bool],
        dt: f64,
        v: &mut [f64],
        du: &[f64],
    ) -> (Vector3<f64>, Matrix3<f64>) {
        let p = &self.props;
        let q = rm * self.frame0.transpose();
        let vm = Vector3::new(v[0], v[1], v[2]);
        let w = Vector3::new(v[3], v[4], v[5]);
        let dx = Vector3::new(du[0], du[1], du[2]);
        let rot_free = !constrained[3..].iter().any(|&c| c);
        if p.mass <= 0.0 || !rot_free {
            return (dx, exp(&Vector3::new(du[3], du[4], du[5])) * rm);
        }
        if !constrained[..3].iter().any(|&c| c) {
            let c = q * p.centre;
            let vc = vm + w.cross(&c);
            let jc = q * p.inertia * q.transpose();
            let pi = jc * w;
            let r1 = free_rotation(&p.about_centre, &q, &pi, dt) * self.frame0;
            let q1 = r1 * self.frame0.transpose();
            let c1 = q1 * p.centre;
            let w1 = p.about_centre.solve(&q1, &pi);
            let v1 = vc - w1.cross(&c1);
            v[..3].copy_from_slice(v1.as_slice());
            v[3..].copy_from_slice(w1.as_slice());
            (c + dt * vc - c1, r1)
        } else if constrained[..3].iter().all(|&c| c) {
            let jm = self.mass6(rm).fixed_view::<3, 3>(3, 3).into_owned();
            let pi = jm * w;
            let r1 = free_rotation(&p.about_master, &q, &pi, dt) * self.frame0;
            let q1 = r1 * self.frame0.transpose();
            let w1 = p.about_master.solve(&q1, &pi);
            v[3..].copy_from_slice(w1.as_slice());
            (dx, r1)
        } else {
            (dx, exp(&Vector3::new(du[3], du[4], du[5])) * rm)
        }
    }
}

/// Free rotation over `h` at constant spatial angular momentum `pi` about a fixed point with
/// principal inertia `pr` (body frame), from the body orientation `q` (body to global); returns
/// the end orientation. Strang splitting `1(h/2) 2(h/2) 3(h) 2(h/2) 1(h/2)` of the kinetic
/// energy `Σ Π_k²/2I_k` into exact rotations about the principal axes.
fn free_rotation(pr: &Principal, q: &Matrix3<f64>, pi: &Vector3<f64>, h: f64) -> Matrix3<f64> {
    let mut b = q * pr.axes;
    for (k, f) in [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
        let body = b.transpose() * pi;
        let mut phi = Vector3::zeros();
        phi[k] = f * h * body[k] / pr.moments[k];
        b *= exp(&phi);
    }
    b * pr.axes.transpose()
}
