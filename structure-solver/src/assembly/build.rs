//! A model from mesh cells: each cell becomes the element its `Part` says (explicit shells
//! gathered into one blocked BT4 part of the quadrilaterals and one BLT3 part of the
//! triangles, each element with its material), the dofs without stiffness are constrained,
//! and the lumped mass and element bound of the critical step follow the chosen rotary
//! inertia.

use nalgebra::{Matrix3, Vector3};

use super::explicit_shells::ExplicitShells;
use super::stable_step::{characteristic_length, ElementBound};
use super::{gather, AssemblyError, FeModel, Part, State};
use crate::elements::blt3::{Blt3, Blt3Settings};
use crate::elements::bt4::{Bt4, Bt4Settings};
use crate::elements::{Element, ElementKind, RotaryInertia};
use crate::material::{Elastic, ThicknessRule, J2};
use crate::mesh::{CellKind, Mesh};

impl FeModel {
    /// Builds the model of `mesh`, every cell becoming the element `part(cell index)` says.
    pub fn new(mesh: &Mesh, part: impl Fn(usize) -> Part) -> Result<Self, AssemblyError> {
        let nn = mesh.nodes.len();
        let x0: Vec<Vector3<f64>> = mesh.nodes.iter().map(|p| Vector3::from(*p)).collect();
        let mut elements = Vec::with_capacity(mesh.cells.len());
        let mut element_cell = Vec::with_capacity(mesh.cells.len());
        let mut shells = ShellCells::default();
        for (ci, cell) in mesh.cells.iter().enumerate() {
            if let Some(&bad) = cell.nodes.iter().find(|&&n| n >= nn) {
                return Err(AssemblyError::NodeRange { node: bad, n: nn });
            }
            if let (CellKind::Quad4 | CellKind::Tri3, Part::Bt4(s, y)) = (cell.kind, part(ci)) {
                shells.push(ci, &cell.nodes, s, y)?;
                continue;
            }
            let p = gather(&x0, &cell.nodes);
            let nd = &cell.nodes;
            let (shell, yield_) = match part(ci) {
                Part::Shell(s) => (Some(s), None),
                Part::ShellJ2(s, y) => (Some(s), Some(y)),
                _ => (None, None),
            };
            let el = match (cell.kind, part(ci)) {
                (CellKind::Quad4, Part::Shell(_) | Part::ShellJ2(..)) => {
                    let s = shell.expect("a shell part");
                    let x = [p[0], p[1], p[2], p[3]];
                    Element::quad4([nd[0], nd[1], nd[2], nd[3]], &x, &s, yield_)
                }
                (CellKind::Tri3, Part::Shell(_) | Part::ShellJ2(..)) => {
                    let s = shell.expect("a shell part");
                    Element::tri3([nd[0], nd[1], nd[2]], &[p[0], p[1], p[2]], &s, yield_)
                }
                (CellKind::Line2, Part::Beam(s, up)) => {
                    Element::beam2([nd[0], nd[1]], &[p[0], p[1]], Vector3::from(up), &s)
                }
                (CellKind::Line2, Part::BeamJ2(s, up, y)) => {
                    Element::beam2_j2([nd[0], nd[1]], &[p[0], p[1]], Vector3::from(up), &s, y)
                }
                (CellKind::Tet4, Part::Solid(mat)) => {
                    Element::tet4([nd[0], nd[1], nd[2], nd[3]], &[p[0], p[1], p[2], p[3]], mat)
                }
                (kind, p) => {
                    let part = match p {
                        Part::Shell(_) | Part::ShellJ2(..) => "a shell section",
                        Part::Bt4(..) => "an explicit shell (triangles or quadrilaterals)",
                        Part::Beam(..) | Part::BeamJ2(..) => "a beam section",
                        Part::Solid(_) => "a solid material",
                    };
                    return Err(AssemblyError::Mismatch { cell: ci, kind, part });
                }
            };
            elements.push(el);
            element_cell.push(ci);
        }
        // dofs without stiffness: unused nodes, rotations of solid-only nodes
        let mut constrained = vec![true; 6 * nn];
        for e in &elements {
            for &n in &e.nodes {
                let k = if e.has_rotations() { 6 } else { 3 };
                constrained[6 * n..6 * n + k].fill(false);
            }
        }
        for n in shells.quads.conn.iter().flatten().chain(shells.triangles.conn.iter().flatten()) {
            constrained[6 * *n as usize..6 * *n as usize + 6].fill(false);
        }
        let explicit = shells.build(&x0);
        let mut state_offsets = vec![0];
        for e in &elements {
            state_offsets.push(state_offsets[state_offsets.len() - 1] + e.n_state());
        }
        let state = State {
            x: x0.clone(),
            r: vec![Matrix3::identity(); nn],
            spin_sum: vec![Vector3::zeros(); nn],
            material: vec![0.0; state_offsets[elements.len()]],
        };
        let topology = super::topology::Topology::built(
            nn,
            &mesh.cells.iter().map(|c| c.nodes.len()).collect::<Vec<_>>(),
            &element_cell,
        );
        let mut m = FeModel {
            x0,
            trial: state.clone(),
            committed: state,
            elements,
            state_offsets,
            cells: mesh.cells.iter().map(|c| c.nodes.clone()).collect(),
            element_cell,
            explicit,
            rotary: RotaryInertia::Physical,
            mass: vec![],
            node_mass: vec![],
            constrained,
            user_fixed: vec![false; 6 * nn],
            rigid: vec![],
            springs: vec![],
            skew: vec![],
            skew_of: vec![None; nn],
            body_of: vec![None; nn],
            slave: vec![false; nn],
            fint_full: vec![],
            fint_valid: false,
            prescribed: vec![],
            point_loads: vec![],
            pressures: vec![],
            face_pressures: vec![],
            gravity: None,
            external: vec![0.0; 6 * nn],
            held_extra: vec![],
            scratch: vec![],
            element_bound: vec![],
            topology,
        };
        m.set_rotary_inertia(RotaryInertia::Physical);
        Ok(m)
    }

    /// carry the element's translational mass).
    pub(super) fn element_mass(&self, e: &Element) -> Vec<f64> {
        let mut m = e.mass.clone();
        if matches!(e.kind, ElementKind::Quad4 | ElementKind::Tri3) {
            // The element mass holds the physical `m h²/12`.
            for i in 0..e.nodes.len() {
                let extra = m[6 * i] * self.rotary.added_area(e.measure) / 12.0;
                for c in 3..6 {
                    m[6 * i + c] += extra;
                }
            }
        }
        m
    }

    /// Chooses the rotary inertia and recomputes the lumped mass and critical step.
    pub fn set_rotary_inertia(&mut self, rotary: RotaryInertia) {
        self.rotary = rotary;
        let mut mass = vec![0.0; self.x0.len() * 6];
        let mut bound = Vec::with_capacity(self.elements.len());
        for e in &self.elements {
            let me = self.element_mass(e);
            for (i, &n) in e.nodes.iter().enumerate() {
                for c in 0..6 {
                    mass[6 * n + c] += me[6 * i + c];
                }
            }
            let x = gather(&self.x0, &e.nodes);
            let w2 = e.max_frequency_squared(&x, &me);
            let dt = if w2 > 0.0 { 2.0 / w2.sqrt() } else { f64::INFINITY };
            bound.push(ElementBound { dt, length: characteristic_length(e.kind, &x) });
        }
        self.element_bound = bound;
        if let Some(b) = &mut self.explicit {
            b.set_rotary_inertia(rotary, &self.x0, &mut mass);
        }
        self.node_mass = mass;
        self.reduce_mass();
    }

    /// The lumped mass of the free dofs: rigid slaves carry nothing, masters the diagonal of
    /// their body's mass block in the current orientation (the full block acts through the
    /// `Model` mass hooks).
    pub(super) fn reduce_mass(&mut self) {
        self.mass.clone_from(&self.node_mass);
        for b in &mut self.rigid {
            b.set_mass(&self.node_mass);
            let m6 = b.mass6(&self.trial.r[b.master]);
            for c in 0..6 {
                self.mass[6 * b.master + c] = m6[(c, c)];
            }
            for &s in &b.slaves {
                self.mass[6 * s..6 * s + 6].fill(0.0);
            }
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let m = k.mass(&self.node_mass[d..d + 6]);
            for c in 0..6 {
                self.mass[d + c] = m[(c, c)];
            }
        }
    }
}

/// The cells of one family of explicit shells: connectivity, thickness, material index.
#[derive(Debug, Default)]
struct Family<const K: usize> {
    conn: Vec<[u32; K]>,
    h: Vec<f64>,
    material_of: Vec<u16>,
}

/// The explicit shell cells of a model as they are met: the two families, their materials
/// (distinct, in order of appearance) and the thickness points of the first J2 cell.
#[derive(Debug, Default)]
struct ShellCells {
    quads: Family<4>,
    triangles: Family<3>,
    materials: Vec<J2>,
    points: Option<(usize, usize)>,
}

impl ShellCells {
    fn push(
        &mut self,
        cell: usize,
        nodes: &[usize],
        s: crate::elements::ShellSection,
        y: Option<crate::elements::ShellYield>,
    ) -> Result<(), AssemblyError> {
        let j2 = J2 {
            elastic: Elastic { e: s.e, nu: s.nu, rho: s.rho },
            sigma_y: y.map_or(f64::INFINITY, |y| y.sigma_y),
            h: y.map_or(0.0, |y| y.hardening),
        };
        if !(s.h.is_finite() && s.h > 0.0) {
            return Err(AssemblyError::ShellThickness { cell, h: s.h });
        }
        if let Some(y) = y {
            let (first, first_points) = *self.points.get_or_insert((cell, y.points));
            if y.points != first_points {
                return Err(AssemblyError::ShellPoints {
                    cell,
                    points: y.points,
                    first,
                    first_points,
                });
            }
        }
        let m = match self.materials.iter().position(|m| *m == j2) {
            Some(m) => m,
            None => {
                self.materials.push(j2);
                self.materials.len() - 1
            }
        };
        let m = u16::try_from(m).map_err(|_| AssemblyError::ShellMaterials { cell })?;
        let n = |i: usize| nodes[i] as u32;
        if nodes.len() == 4 {
            self.quads.conn.push([n(0), n(1), n(2), n(3)]);
            self.quads.h.push(s.h);
            self.quads.material_of.push(m);
        } else {
            self.triangles.conn.push([n(0), n(1), n(2)]);
            self.triangles.h.push(s.h);
            self.triangles.material_of.push(m);
        }
        Ok(())
    }

    /// The BT4 and BLT3 parts (physical rotary inertia until the model sets its own).
    fn build(self, x0: &[Vector3<f64>]) -> Option<ExplicitShells> {
        let rule = ThicknessRule::gauss(self.points.map_or(5, |p| p.1));
        let (q, t, mats) = (self.quads, self.triangles, self.materials);
        let rotary = RotaryInertia::Physical;
        let quads = (!q.conn.is_empty()).then(|| {
            let settings = Bt4Settings { rule: rule.clone(), rotary, ..Default::default() };
            Bt4::with_materials(q.conn, q.h, mats.clone(), q.material_of, settings)
                .expect("one thickness and a listed material per element")
        });
        let triangles = (!t.conn.is_empty()).then(|| {
            let settings = Blt3Settings { rule, rotary, ..Default::default() };
            Blt3::with_materials(t.conn, t.h, mats, t.material_of, settings)
                .expect("one positive thickness and a listed material per element")
        });
        ExplicitShells::new(quads, triangles, x0)
    }
}
