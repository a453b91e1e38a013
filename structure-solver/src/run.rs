//! `structure-solver run CASE`: a structure alone, from the `[structure]` section of a case
//! (DESIGN §7; the schema is documented in `interface_protocol::case::structure`): mesh and
//! sets, materials and parts, boundary conditions, loads with time curves, initial velocity,
//! and the analysis: central differences, Newmark, the implicit midpoint rule, or statics
//! (load steps or displacement control). Probes go to `structure_probes.csv` (static runs: the
//! time column holds the load factor), fields to `structure.xdmf`, the final cell fields to
//! `structure_cells.csv`.
//!
//! Every structure is one `assembly::FeModel`; BT4 shells are its explicit-only part. Central
//! differences scale the shells' rotary inertia (`RotaryInertia::Scaled`), implicit and static
//! runs keep the physical one. Coincident nodes of generated meshes are merged (the seams of
//! closed surfaces; quadrilaterals collapsed at a pole become triangles).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use anyhow::{anyhow, bail, Context};
use interface_protocol::case::{
    BeamSectionSpec, Case, CurveName, CurveSpec, ElementType, Integrator, LoadKind,
    StructureMaterial, StructureMesh, StructureSection, Symmetry,
};
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{bucket, case_echo, versions, RunReport, Timers};

use crate::assembly::{AssemblyError, Curve, FeModel, Part, RotaryInertia};
use crate::elements::{BeamSection, ShellSection, ShellYield};
use crate::material::{Elastic, Material, J2};
use crate::mesh::{generate, gmsh, Cell, CellKind, Mesh};
use crate::model::Model;
use crate::output::{gather_nodal, write_cell_table, CellMap, FieldOutput};
use crate::restart::{load_dynamics, restore_state, save_dynamics, save_state, PART};
use crate::rigid::{ExtraMass, RigidReference};
use crate::statics::{
    arc_length, displacement_control, load_steps, ArcLengthSettings, Converged, NewtonSettings,
};
use crate::time::{critical_dt, CentralDifference, Dynamics, Implicit, ImplicitScheme};

/// Options of `run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub case: PathBuf,
    pub out: Option<PathBuf>,
    pub set: Vec<String>,
    pub quiet: bool,
    /// Resume from the newest checkpoint in this run folder.
    pub restart: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub steps: u64,
    pub t: f64,
    pub dt: f64,
    pub out: PathBuf,
}

pub(crate) fn need<'a, T>(v: &'a Option<T>, field: &str, file: &Path) -> anyhow::Result<&'a T> {
    v.as_ref().ok_or_else(|| {
        anyhow!("{}: field `structure.{field}` is required to run structure-solver", file.display())
    })
}

/// An error naming the case file and the field.
fn field_error(file: &Path, field: &str, message: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("{}: field `{field}`: {message}", file.display())
}

/// The generated or read mesh, with the box sets, the node set `all` and the cell set `all`.
fn build_mesh(s: &StructureSection, case: &Case) -> anyhow::Result<Mesh> {
    let file = &case.source.path;
    let rad = |a: [f64; 2]| [a[0].to_radians(), a[1].to_radians()];
    let (mesh, triangles) = match need(&s.mesh, "mesh", file)? {
        StructureMesh::Rectangle { lx, ly, nx, ny, triangles } => {
            (generate::rectangle(*lx, *ly, *nx, *ny), *triangles)
        }
        StructureMesh::Cylinder { radius, length, n_theta, n_axial, theta_deg, triangles } => {
            (generate::cylinder(*radius, *length, rad(*theta_deg), *n_theta, *n_axial), *triangles)
        }
        StructureMesh::Sphere { radius, n_theta, n_phi, theta_deg, phi_deg, triangles } => (
            generate::sphere(*radius, rad(*theta_deg), rad(*phi_deg), *n_theta, *n_phi),
            *triangles,
        ),
        StructureMesh::Annulus { r_inner, r_outer, n_theta, n_r, theta_deg, triangles } => {
            (generate::annulus(*r_inner, *r_outer, rad(*theta_deg), *n_theta, *n_r), *triangles)
        }
        StructureMesh::Line { from, to, n } => (generate::line(*from, *to, *n), false),
        StructureMesh::Gmsh { file: path } => {
            let p = case.dir().join(path);
            let m = gmsh::read(&p)
                .with_context(|| format!("{}: field `structure.mesh.file`", file.display()))?;
            (m, false)
        }
    };
    let mut mesh = if matches!(s.mesh, Some(StructureMesh::Gmsh { .. })) {
        mesh
    } else {
        merge_coincident(mesh).map_err(|m| field_error(file, "structure.mesh", m))?
    };
    if triangles {
        mesh = mesh.to_triangles();
    }
    for (name, b) in &s.sets {
        let nodes = mesh.nodes_where(|p| (0..3).all(|k| p[k] >= b.min[k] && p[k] <= b.max[k]));
        if nodes.is_empty() {
            bail!("{}: field `structure.sets.{name}`: no node inside the box", file.display());
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    mesh.node_sets.insert("all".into(), (0..mesh.nodes.len()).collect());
    mesh.cell_sets.insert("all".into(), (0..mesh.cells.len()).collect());
    Ok(mesh)
}

/// Merges nodes closer than 1e-9 of the mesh size (the seams of closed generated surfaces)
/// and turns quadrilaterals collapsed at a pole into triangles; node sets follow.
fn merge_coincident(mesh: Mesh) -> Result<Mesh, String> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let tol = 1e-9 * size.max(f64::MIN_POSITIVE);
    let key = |p: &[f64; 3]| p.map(|c| (c / tol).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut new_id = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        let k = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let q = [k[0] + dx, k[1] + dy, k[2] + dz];
                    for &j in grid.get(&q).into_iter().flatten() {
                        let d2: f64 = (0..3).map(|c| (mesh.nodes[j][c] - p[c]).powi(2)).sum();
                        if d2 <= tol * tol {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        new_id[i] = match found {
            Some(j) => new_id[j],
            None => {
                grid.entry(k).or_default().push(i);
                nodes.push(*p);
                nodes.len() - 1
            }
        };
    }
    let mut cells = Vec::with_capacity(mesh.cells.len());
    for (c, cell) in mesh.cells.iter().enumerate() {
        let mut ids: Vec<usize> = Vec::with_capacity(cell.nodes.len());
        for &n in &cell.nodes {
            if !ids.contains(&new_id[n]) {
                ids.push(new_id[n]);
            }
        }
        let kind = match (cell.kind, ids.len()) {
            (k, n) if n == k.n_nodes() => k,
            (CellKind::Quad4, 3) => CellKind::Tri3,
            (k, _) => return Err(format!("cell {c} ({k:?}) collapses to {} nodes", ids.len())),
        };
        cells.push(Cell { kind, nodes: ids });
    }
    let node_sets = mesh
        .node_sets
        .into_iter()
        .map(|(name, v)| {
            let mut out: Vec<usize> = Vec::with_capacity(v.len());
            for n in v {
                if !out.contains(&new_id[n]) {
                    out.push(new_id[n]);
                }
            }
            (name, out)
        })
        .collect();
    Ok(Mesh { nodes, cells, node_sets, cell_sets: mesh.cell_sets })
}

/// The names of the mesh's sets, for error messages.
fn known_sets(mesh: &Mesh) -> String {
    let mut names: Vec<&str> =
        mesh.node_sets.keys().chain(mesh.cell_sets.keys()).map(String::as_str).collect();
    names.sort_unstable();
    names.dedup();
    names.join(", ")
}

/// The nodes of set `name` (a node set, else the nodes of a cell set).
fn node_set(mesh: &Mesh, name: &str, field: &str, file: &Path) -> anyhow::Result<Vec<usize>> {
    if let Ok(n) = mesh.node_set(name) {
        return Ok(n.to_vec());
    }
    if let Ok(c) = mesh.cell_set(name) {
        let mut seen = vec![false; mesh.nodes.len()];
        let mut out = Vec::new();
        for &ci in c {
            for &n in &mesh.cells[ci].nodes {
                if !seen[n] {
                    seen[n] = true;
                    out.push(n);
                }
            }
        }
        return Ok(out);
    }
    Err(field_error(file, field, format!("no set \"{name}\"; known sets: {}", known_sets(mesh))))
}

/// The cells of set `name` (a cell set, else the cells whose nodes all lie in the node set).
fn cell_set(mesh: &Mesh, name: &str, field: &str, file: &Path) -> anyhow::Result<Vec<usize>> {
    if let Ok(c) = mesh.cell_set(name) {
        return Ok(c.to_vec());
    }
    if let Ok(nodes) = mesh.node_set(name) {
        let mut inside = vec![false; mesh.nodes.len()];
        nodes.iter().for_each(|&n| inside[n] = true);
        let cells: Vec<usize> = (0..mesh.cells.len())
            .filter(|&c| mesh.cells[c].nodes.iter().all(|&n| inside[n]))
            .collect();
        if cells.is_empty() {
            return Err(field_error(file, field, format!("node set \"{name}\" holds no cell")));
        }
        return Ok(cells);
    }
    Err(field_error(file, field, format!("no set \"{name}\"; known sets: {}", known_sets(mesh))))
}

/// A case curve as the model's.
fn curve(c: Option<&CurveSpec>, default: Curve) -> Curve {
    match c {
        None => default,
        Some(CurveSpec::Named(CurveName::Constant)) => Curve::Constant,
        Some(CurveSpec::Named(CurveName::Linear)) => Curve::Linear,
        Some(CurveSpec::Ramp(r)) => Curve::Table(vec![(0.0, 0.0), (r.ramp, 1.0)]),
        Some(CurveSpec::Table(t)) => Curve::Table(t.table.iter().map(|p| (p[0], p[1])).collect()),
    }
}

/// The shell section and yield of a material.
fn shell(
    m: &StructureMaterial,
    h: f64,
    points: Option<usize>,
) -> (ShellSection, Option<ShellYield>) {
    let section = ShellSection { e: m.e, nu: m.nu, rho: m.rho, h };
    let yield_ = m.sigma_y.map(|sigma_y| ShellYield {
        sigma_y,
        hardening: m.hardening,
        points: points.unwrap_or(5),
    });
    (section, yield_)
}

fn beam_section(m: &StructureMaterial, s: &BeamSectionSpec) -> BeamSection {
    match s.rectangle {
        Some([b, h]) => BeamSection::rectangle(m.e, m.nu, m.rho, b, h),
        None => BeamSection {
            e: m.e,
            nu: m.nu,
            rho: m.rho,
            area: s.area.unwrap_or_default(),
            iy: s.iy.unwrap_or_default(),
            iz: s.iz.unwrap_or_default(),
            j: s.j.unwrap_or_default(),
        },
    }
}

/// Dimension of a cell kind.
fn dimension(k: CellKind) -> usize {
    match k {
        CellKind::Line2 => 1,
        CellKind::Tri3 | CellKind::Quad4 => 2,
        CellKind::Tet4 => 3,
    }
}

/// The element part of every cell, from `[[structure.parts]]` or the single top-level part. A
/// part without a set takes every cell of the mesh's highest dimension; cells of a lower
/// dimension in no part (the boundary lines and faces of a gmsh file) only define sets.
fn cell_parts(s: &StructureSection, mesh: &Mesh, file: &Path) -> anyhow::Result<Vec<Option<Part>>> {
    let materials = s.all_materials();
    let single;
    let parts = if s.parts.is_empty() {
        let element = s.element.unwrap_or(ElementType::Bt4);
        let thickness = match element {
            ElementType::Beam => {
                return Err(field_error(
                    file,
                    "structure.element",
                    "beams need a section and an `up` vector: give them in [[structure.parts]]",
                ))
            }
            ElementType::Tet4 => None,
            _ => Some(*need(&s.thickness, "thickness", file)?),
        };
        single = [interface_protocol::case::StructurePart {
            set: None,
            element,
            material: None,
            thickness,
            points: None,
            section: None,
            up: None,
        }];
        if materials.len() != 1 {
            need(&s.material, "material", file)?;
        }
        &single[..]
    } else {
        &s.parts[..]
    };
    let top = s.parts.is_empty();
    let top_dim = mesh.cells.iter().map(|c| dimension(c.kind)).max().unwrap_or(0);
    let mut out: Vec<Option<(usize, Part)>> = vec![None; mesh.cells.len()];
    for (k, p) in parts.iter().enumerate() {
        let f = |key: &str| {
            if top {
                format!("structure.{key}")
            } else {
                format!("structure.parts[{k}].{key}")
            }
        };
        let m = match &p.material {
            Some(name) => &materials[name],
            None => materials.values().next().ok_or_else(|| {
                anyhow!(
                    "{}: field `structure.material` is required to run structure-solver",
                    file.display()
                )
            })?,
        };
        let cells = match &p.set {
            Some(name) => cell_set(mesh, name, &f("set"), file)?,
            None => (0..mesh.cells.len())
                .filter(|&c| dimension(mesh.cells[c].kind) == top_dim)
                .collect(),
        };
        let h = p.thickness.unwrap_or_default();
        let (section, yield_) = shell(m, h, p.points);
        for c in cells {
            let kind = mesh.cells[c].kind;
            let part = match (p.element, kind) {
                (ElementType::Bt4, CellKind::Quad4) => Part::Bt4(section, yield_),
                (ElementType::Mitc4, CellKind::Quad4)
                | (ElementType::Dkt, CellKind::Tri3)
                | (ElementType::Shell, CellKind::Quad4 | CellKind::Tri3) => match yield_ {
                    Some(y) => Part::ShellJ2(section, y),
                    None => Part::Shell(section),
                },
                (ElementType::Beam, CellKind::Line2) => {
                    if m.sigma_y.is_some() {
                        return Err(field_error(
                            file,
                            &f("material"),
                            "beams are elastic; give a material without sigma_y",
                        ));
                    }
                    let sec = p.section.as_ref().expect("validated: beams have a section");
                    Part::Beam(beam_section(m, sec), p.up.expect("validated: beams have up"))
                }
                (ElementType::Tet4, CellKind::Tet4) => {
                    let elastic = Elastic { e: m.e, nu: m.nu, rho: m.rho };
                    Part::Solid(match m.sigma_y {
                        Some(sigma_y) => Material::J2(J2 { elastic, sigma_y, h: m.hardening }),
                        None => Material::Elastic(elastic),
                    })
                }
                (e, kind) => {
                    let needs = match e {
                        ElementType::Bt4 | ElementType::Mitc4 => "quadrilaterals",
                        ElementType::Dkt => "triangles",
                        ElementType::Shell => "triangles or quadrilaterals",
                        ElementType::Beam => "2-node lines",
                        ElementType::Tet4 => "tetrahedra",
                    };
                    let set = p.set.as_deref().unwrap_or("all");
                    return Err(field_error(
                        file,
                        &f("element"),
                        format!("{e:?} needs {needs}; cell {c} of set \"{set}\" is a {kind:?}")
                            .to_lowercase(),
                    ));
                }
            };
            if let Some((other, _)) = out[c] {
                return Err(field_error(
                    file,
                    &f("set"),
                    format!("cell {c} already belongs to structure.parts[{other}]"),
                ));
            }
            out[c] = Some((k, part));
        }
    }
    if let Some(c) =
        (0..out.len()).find(|&c| out[c].is_none() && dimension(mesh.cells[c].kind) == top_dim)
    {
        return Err(field_error(
            file,
            "structure.parts",
            format!("cell {c} (a {:?}) belongs to no part; add a part over it", mesh.cells[c].kind),
        ));
    }
    Ok(out.into_iter().map(|p| p.map(|(_, part)| part)).collect())
}

/// The structure of a case, ready to integrate.
pub struct Structure {
    pub mesh: Mesh,
    pub model: FeModel,
    /// Initial velocity per dof (zero on constrained dofs).
    pub v0: Vec<f64>,
    /// Which mesh cells are the model's elements and BT4 shells (output fields).
    pub cells: CellMap,
    /// A length below the element size: the probe of the critical-step power iteration.
    pub length: f64,
}

/// Builds the `[structure]` of `case`: mesh and sets, parts, BCs, loads, initial velocity.
/// `rotary` is the rotary inertia of the shells (`Scaled` for explicit steps).
pub fn build(case: &Case, rotary: RotaryInertia) -> anyhow::Result<Structure> {
    let file = case.source.path.clone();
    let file = file.as_path();
    let s = section(case)?;
    let mesh = build_mesh(s, case)?;
    let parts = cell_parts(s, &mesh, file)?;
    // The model's cells: those of a part, in mesh order.
    let kept: Vec<usize> = (0..mesh.cells.len()).filter(|&c| parts[c].is_some()).collect();
    let mut model_cell = vec![None; mesh.cells.len()];
    kept.iter().enumerate().for_each(|(i, &c)| model_cell[c] = Some(i));
    let elements = Mesh {
        nodes: mesh.nodes.clone(),
        cells: kept.iter().map(|&c| mesh.cells[c].clone()).collect(),
        ..Mesh::default()
    };
    let part = |i: usize| parts[kept[i]].expect("kept cells have a part");
    let mut fe = FeModel::new(&elements, part).map_err(|e| match e {
        AssemblyError::Bt4Material { .. } => field_error(
            file,
            "structure.parts",
            "all bt4 parts share one material and number of thickness points",
        ),
        e => field_error(file, "structure.parts", e),
    })?;
    fe.set_rotary_inertia(rotary);
    let mut mesh = mesh;
    // Rigid body of each slave node.
    let mut body_of = vec![None; mesh.nodes.len()];
    for (k, rb) in s.rigid_bodies.iter().enumerate() {
        let f = format!("structure.rigid_bodies[{k}]");
        let nodes = node_set(&mesh, &rb.set, &format!("{f}.set"), file)?;
        let reference = match rb.reference {
            Some(p) => RigidReference::Point(p),
            None => RigidReference::MassCentre,
        };
        let extra = ExtraMass { mass: rb.mass, ..ExtraMass::default() };
        let master =
            fe.rigid_body(&nodes, reference, extra).map_err(|e| field_error(file, &f, e))?;
        // The reference node joins the mesh (output, probes) and the sets `all` and
        // `<set>_reference`.
        let p = fe.initial_positions()[master];
        mesh.nodes.push([p.x, p.y, p.z]);
        mesh.node_sets.insert(format!("{}_reference", rb.set), vec![master]);
        mesh.node_sets.get_mut("all").expect("built with the mesh").push(master);
        body_of.push(None);
        nodes.iter().for_each(|&n| body_of[n] = Some(k));
    }
    let statics = s.integrator() == Integrator::Static;
    let default_curve = if statics { Curve::Linear } else { Curve::Constant };
    let mut skew = Vec::new();
    for (k, bc) in s.bc.iter().enumerate() {
        let f = format!("structure.bc[{k}]");
        let nodes = node_set(&mesh, &bc.set, &format!("{f}.set"), file)?;
        if let Some((n, b)) = nodes.iter().find_map(|&n| body_of[n].map(|b| (n, b))) {
            return Err(field_error(
                file,
                &format!("{f}.set"),
                format!(
                    "node {n} moves with structure.rigid_bodies[{b}]; constrain its reference \
                     node, set \"{}_reference\"",
                    s.rigid_bodies[b].set
                ),
            ));
        }
        if !bc.fixed.is_empty() {
            let mut mask = [false; 6];
            bc.fixed.iter().for_each(|d| mask[d.index()] = true);
            fe.fix(&nodes, mask);
        }
        match bc.symmetry {
            Some(Symmetry::Axis(axis)) => fe.symmetry(&nodes, axis.index()),
            Some(Symmetry::Normal(n)) => skew.push((format!("{f}.symmetry"), nodes.clone(), n)),
            None => {}
        }
        if let Some(p) = &bc.prescribed {
            fe.prescribe(
                &nodes,
                p.dof.index(),
                p.value,
                curve(p.curve.as_ref(), default_curve.clone()),
            );
        }
    }
    // planes of any normal after the fixed and prescribed dofs they combine with
    for (f, nodes, n) in skew {
        fe.symmetry_plane(&nodes, n).map_err(|e| field_error(file, &f, e))?;
    }
    for (k, l) in s.loads.iter().enumerate() {
        let f = format!("structure.loads[{k}]");
        let c = curve(l.curve.as_ref(), default_curve.clone());
        match l.kind().expect("validated") {
            LoadKind::Point { set, dof, value } => {
                for n in node_set(&mesh, set, &format!("{f}.set"), file)? {
                    fe.point_load(n, dof.index(), value, c.clone());
                }
            }
            LoadKind::Pressure { set, p } => {
                let face =
                    |c: &usize| matches!(mesh.cells[*c].kind, CellKind::Tri3 | CellKind::Quad4);
                let cells = match set {
                    Some(name) => cell_set(&mesh, name, &format!("{f}.set"), file)?,
                    None => kept.iter().copied().filter(face).collect(),
                };
                if cells.is_empty() {
                    return Err(field_error(
                        file,
                        &format!("{f}.pressure"),
                        "the model has no shell",
                    ));
                }
                if let Some(bad) = cells.iter().find(|c| !face(c) || model_cell[**c].is_none()) {
                    return Err(field_error(
                        file,
                        &format!("{f}.set"),
                        format!(
                            "a pressure acts on the shells of a part; cell {bad} is a {:?}{}",
                            mesh.cells[*bad].kind,
                            if model_cell[*bad].is_none() { " of no part" } else { "" }
                        ),
                    ));
                }
                let cells: Vec<usize> = cells.iter().filter_map(|&c| model_cell[c]).collect();
                fe.pressure(&cells, p, c);
            }
            LoadKind::Gravity(g) => fe.gravity(g, c),
        }
    }
    let mut v0 = vec![0.0; fe.n_dof()];
    for (k, iv) in s.initial_velocity.iter().enumerate() {
        let f = format!("structure.initial_velocity[{k}].set");
        for node in node_set(&mesh, &iv.set, &f, file)? {
            v0[6 * node + iv.dof.index()] = iv.value;
        }
    }
    for (v, &c) in v0.iter_mut().zip(fe.constrained()) {
        if c {
            *v = 0.0;
        }
    }
    let is_bt4 = |c: &usize| matches!(parts[*c], Some(Part::Bt4(..)));
    let cells = CellMap {
        elements: kept.iter().copied().filter(|c| !is_bt4(c)).collect(),
        bt4: kept.iter().copied().filter(is_bt4).collect(),
        n_cells: mesh.cells.len(),
    };
    let thinnest = parts
        .iter()
        .flatten()
        .filter_map(|p| match p {
            Part::Shell(s) | Part::ShellJ2(s, _) | Part::Bt4(s, _) => Some(s.h),
            _ => None,
        })
        .fold(f64::INFINITY, f64::min);
    let length = if thinnest.is_finite() {
        thinnest
    } else {
        let (lo, hi) =
            mesh.nodes.iter().fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
                (std::array::from_fn(|k| lo[k].min(p[k])), std::array::from_fn(|k| hi[k].max(p[k])))
            });
        let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        1e-3 * d
    };
    Ok(Structure { mesh, model: fe, v0, cells, length })
}

/// The `[structure]` section of a case, or an error naming the file.
pub fn section(case: &Case) -> anyhow::Result<&StructureSection> {
    case.structure.as_ref().ok_or_else(|| {
        anyhow!(
            "{}: a `[structure]` section is required to run structure-solver",
            case.source.path.display()
        )
    })
}

/// What a run alone writes per step: probe rows every `probes_every` steps, the field series
/// every `fields_every` steps (0: first and last only), both at the end; the first non-finite
/// value stops the run.
struct AloneOutput {
    probe_nodes: Vec<usize>,
    probes: ProbeWriter,
    probes_every: u64,
    fields: FieldOutput,
    fields_every: u64,
    disp: Vec<[f64; 3]>,
    vel: Vec<[f64; 3]>,
    bar: Progress,
}

impl AloneOutput {
    /// Writes step `step` at `t` (`last`: the final state); `cells` gives the model for cell
    /// fields (dynamic runs).
    fn write(
        &mut self,
        model: &dyn Model,
        cells: Option<&FeModel>,
        v: &[f64],
        (step, t, dt): (u64, f64, f64),
        last: bool,
    ) -> anyhow::Result<()> {
        let probe = step % self.probes_every == 0 || last;
        let field = step == 0 || last || (self.fields_every > 0 && step % self.fields_every == 0);
        self.bar.update(step, t, dt);
        if !(probe || field) {
            return Ok(());
        }
        gather_nodal(t, model, v, &mut self.disp, &mut self.vel)?;
        if probe {
            let mut row = Vec::with_capacity(6 * self.probe_nodes.len());
            for &p in &self.probe_nodes {
                row.extend_from_slice(&self.disp[p]);
                row.extend_from_slice(&self.vel[p]);
            }
            self.probes.write_row(t, &row)?;
        }
        if field {
            self.fields.gather(t, model, cells, v)?;
            self.fields.write(t)?;
        }
        Ok(())
    }
}

/// Where a restart resumes: step, time step and integrator state (the model is restored).
struct Resume {
    step: u64,
    dt: f64,
    dynamics: Dynamics,
}

/// Restores `model` from the newest complete checkpoint of run folder `from`.
fn read_checkpoint(from: &Path, model: &mut FeModel) -> anyhow::Result<Resume> {
    let dir = from.join("checkpoints");
    let found = checkpoint::latest(&dir, &[PART])?.ok_or_else(|| {
        anyhow!("--restart {}: no complete checkpoint in {}", from.display(), dir.display())
    })?;
    let ck = Checkpoint::read(&dir, &found.tag, PART)?;
    restore_state(model, &ck)?;
    let dt = ck
        .f64("dt")?
        .first()
        .copied()
        .ok_or_else(|| anyhow!("checkpoint {}: empty `dt`", found.tag))?;
    Ok(Resume { step: ck.step, dt, dynamics: load_dynamics(&ck, model.n_dof())? })
}

/// Writes `checkpoints/step_<step>/structure.ckpt`: model state, velocities, accelerations, `dt`.
fn write_checkpoint(
    dir: &OutputDir,
    model: &FeModel,
    d: &Dynamics,
    step: u64,
    dt: f64,
) -> anyhow::Result<()> {
    let mut ck = Checkpoint::new(step, d.t);
    save_state(model, &mut ck)?;
    save_dynamics(&mut ck, d)?;
    ck.put("dt", vec![dt])?;
    ck.write(&dir.checkpoints()?, &checkpoint::tag_for_step(step), PART)?;
    Ok(())
}

/// Runs a case alone.
pub fn run(opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let case = Case::load(&opts.case, &opts.set)?;
    let file = case.source.path.clone();
    let s = section(&case)?;
    let integrator = s.integrator();
    let rotary = if integrator == Integrator::CentralDifference {
        RotaryInertia::Scaled
    } else {
        RotaryInertia::Physical
    };
    let Structure { mesh, mut model, v0, cells, length } = build(&case, rotary)?;
    let statics = integrator == Integrator::Static;
    let t_end = match (statics, s.t_end) {
        (true, t) => t.unwrap_or(1.0),
        (false, _) => *need(&s.t_end, "t_end", &file)?,
    };
    if !model.has_tangent() && integrator != Integrator::CentralDifference {
        return Err(field_error(
            &file,
            "structure.integrator",
            format!(
                "bt4 shells are explicit; use integrator = \"central_difference\", or mitc4/dkt \
                 shells with \"{}\"",
                integrator.name()
            ),
        ));
    }
    if statics && opts.restart.is_some() {
        bail!("--restart applies to dynamic runs; a static run starts from its unloaded state");
    }
    let n = mesh.nodes.len();

    let out = opts.out.clone().unwrap_or_else(|| default_run_dir(&opts.case, SystemTime::now()));
    // Read the checkpoint before the output folder is made: it may be the same folder.
    let mut resume = match &opts.restart {
        Some(from) => Some(read_checkpoint(from, &mut model)?),
        None => None,
    };
    let dir = OutputDir::create(&out, Policy::Overwrite)?;
    let checkpoint_every = case.output.checkpoint_every;
    let checkpoint = |model: &FeModel, d: &Dynamics, step: u64, dt: f64| {
        if checkpoint_every > 0 && step % checkpoint_every == 0 {
            write_checkpoint(&dir, model, d, step, dt)
        } else {
            Ok(())
        }
    };
    let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
    let started = Instant::now();
    // Static steps see the model through `dyn Model` only: nodal fields.
    let field_cells = if statics { None } else { Some(cells.clone()) };
    let mut output = AloneOutput {
        probe_nodes: s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect(),
        probes: ProbeWriter::structure(dir.path(), &names)?,
        probes_every: s.output_every.unwrap_or(1).max(1),
        fields: FieldOutput::create(dir.path(), &mesh, field_cells)?,
        fields_every: case.output.fields_every,
        disp: vec![[0.0; 3]; n],
        vel: vec![[0.0; 3]; n],
        bar: Progress::new(t_end, opts.quiet),
    };
    let mut timers = Timers::new();

    let mut steps = resume.as_ref().map_or(0, |r| r.step);
    let end = |t: f64| t >= t_end * (1.0 - 1e-12);
    let dt;
    match integrator {
        Integrator::CentralDifference => {
            dt = match (&resume, s.dt) {
                (Some(r), _) => r.dt,
                (None, Some(dt)) => dt,
                (None, None) => {
                    let est = critical_dt(&mut model, 0.0, 100, 1e-9 * length);
                    s.safety.unwrap_or(0.8) * est.stable(1.0)
                }
            };
            if !(dt.is_finite() && dt > 0.0) {
                bail!("{}: no stable step could be estimated; give `structure.dt`", file.display());
            }
            let mut cd = match resume.take() {
                Some(r) => CentralDifference::resume(&model, r.dynamics),
                None => CentralDifference::new(&mut model, 0.0, v0, None),
            };
            output.write(&model, Some(&model), &cd.state.v, (steps, cd.state.t, dt), false)?;
            while cd.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - cd.state.t);
                timers.time(bucket::STRUCTURE, || cd.step(&mut model, step, None));
                steps += 1;
                let t0 = Instant::now();
                output
                    .write(
                        &model,
                        Some(&model),
                        &cd.state.v,
                        (steps, cd.state.t, step),
                        end(cd.state.t),
                    )
                    .with_context(|| format!("step {steps} of {dt:.3e} s"))?;
                checkpoint(&model, &cd.state, steps, dt)?;
                timers.add_since(bucket::OUTPUT, t0);
            }
        }
        Integrator::Newmark | Integrator::Midpoint => {
            dt = match &resume {
                Some(r) => r.dt,
                None => *need(&s.dt, "dt", &file)?,
            };
            let scheme = if integrator == Integrator::Newmark {
                ImplicitScheme::Newmark
            } else {
                ImplicitScheme::Midpoint
            };
            let mut im = match resume.take() {
                Some(r) => Implicit::resume(&model, scheme, r.dynamics),
                None => Implicit::new(&mut model, scheme, 0.0, v0, None),
            };
            output.write(&model, Some(&model), &im.state.v, (steps, im.state.t, dt), false)?;
            while im.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - im.state.t);
                timers.time(bucket::STRUCTURE, || im.step(&mut model, step, None))?;
                steps += 1;
                let t0 = Instant::now();
                let last = end(im.state.t);
                output.write(&model, Some(&model), &im.state.v, (steps, im.state.t, step), last)?;
                checkpoint(&model, &im.state, steps, dt)?;
                timers.add_since(bucket::OUTPUT, t0);
            }
        }
        Integrator::Static => {
            let done = run_static(s, &file, &mesh, &mut model, t_end, &mut output, &mut timers)?;
            steps = done.len() as u64;
            dt = t_end / steps.max(1) as f64;
        }
    }
    output.probes.flush()?;
    output.fields.finish()?;
    output.bar.finish();
    write_cell_table(&dir.path().join("structure_cells.csv"), &mesh, &model, &cells)?;
    let report = RunReport {
        case_file: file.display().to_string(),
        case: std::fs::read_to_string(&file)
            .ok()
            .and_then(|text| case_echo(&text).ok())
            .unwrap_or_default(),
        versions: {
            let mut v = versions();
            v.insert("structure-solver".into(), env!("CARGO_PKG_VERSION").into());
            v
        },
        status: "completed".into(),
        steps,
        final_time: t_end,
        counts: [("nodes", n as u64), ("cells", mesh.cells.len() as u64)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        wall_seconds: started.elapsed().as_secs_f64(),
        timings: [("structure".to_string(), timers.seconds())].into_iter().collect(),
    };
    report.write(&dir.run_json())?;
    if !opts.quiet {
        let what = if statics { "load steps to load factor" } else { "steps to t =" };
        eprintln!(
            "structure-solver: {steps} {what} {t_end} (step {dt:.3e}); outputs in {}",
            out.display()
        );
    }
    Ok(RunSummary { steps, t: t_end, dt, out })
}

/// A static run: `steps` equal load increments to the load factor `t_end`, displacement
/// control of one dof to `control.value`, or arc-length path following to the load factor
/// `t_end` in at most `steps` steps (the last two scale the loads with the load factor λ).
/// Each converged step writes a probe row at its load factor.
fn run_static(
    s: &StructureSection,
    file: &Path,
    mesh: &Mesh,
    model: &mut FeModel,
    t_end: f64,
    output: &mut AloneOutput,
    timers: &mut Timers,
) -> anyhow::Result<Vec<Converged>> {
    let steps = s.steps.unwrap_or(10);
    let defaults = NewtonSettings::default();
    let newton = s.newton.unwrap_or_default();
    let settings = NewtonSettings {
        tol: newton.tol.unwrap_or(defaults.tol),
        max_iter: newton.max_iter.unwrap_or(defaults.max_iter),
        max_cuts: newton.max_cuts.unwrap_or(defaults.max_cuts),
    };
    let zero = vec![0.0; model.n_dof()];
    output.write(&*model, None, &zero, (0, 0.0, 0.0), false)?;
    let mut k = 0u64;
    let mut failure = None;
    // `reached`: the arc length passed `t_end`; load steps and control end after `steps`.
    let mut on_step = |m: &mut dyn Model, c: Converged, reached: bool| {
        k += 1;
        let last = reached || k == steps as u64;
        if failure.is_none() {
            if let Err(e) = output.write(&*m, None, &zero, (k, c.t, c.t), last) {
                failure = Some(e);
            }
        }
    };
    let done = match (&s.control, &s.arc_length) {
        (None, Some(a)) => {
            linear_loads(s, file, "arc-length path following")?;
            let arc = ArcLengthSettings {
                newton: settings,
                initial: a.initial,
                min: a.min(),
                max: a.max(),
                desired_iterations: a.desired_iterations.unwrap_or(4),
                max_steps: steps,
                start: 0.0,
            };
            let mut reached = false;
            let done = timers.time(bucket::STRUCTURE, || {
                arc_length(model, &arc, |m, c| {
                    reached = c.t >= t_end;
                    on_step(m, c, reached);
                    !reached
                })
            })?;
            if !reached {
                return Err(field_error(
                    file,
                    "structure.steps",
                    format!(
                        "the arc length took {steps} steps to the load factor {:.4}, short of \
                         t_end = {t_end}; allow more steps or a longer arc",
                        done.last().map_or(0.0, |c| c.t)
                    ),
                ));
            }
            Ok(done)
        }
        (None, None) => {
            let targets: Vec<f64> = (1..=steps).map(|i| t_end * i as f64 / steps as f64).collect();
            timers.time(bucket::STRUCTURE, || {
                load_steps(model, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
        (Some(c), _) => {
            let node = match (&c.point, &c.set) {
                (Some(p), _) => mesh.nearest_node(*p),
                (None, Some(name)) => {
                    let nodes = node_set(mesh, name, "structure.control.set", file)?;
                    if nodes.len() != 1 {
                        return Err(field_error(
                            file,
                            "structure.control.set",
                            format!("expected a set of one node, \"{name}\" holds {}", nodes.len()),
                        ));
                    }
                    nodes[0]
                }
                (None, None) => unreachable!("validated: a point or a set"),
            };
            linear_loads(s, file, "displacement control")?;
            let targets: Vec<f64> =
                (1..=steps).map(|i| c.value * i as f64 / steps as f64).collect();
            let dof = 6 * node + c.dof.index();
            timers.time(bucket::STRUCTURE, || {
                displacement_control(model, dof, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
    };
    if let Some(e) = failure {
        return Err(e);
    }
    done.map_err(|e| anyhow!("{}: static solve: {e}", file.display()))
}

/// Path following scales the loads with the load factor: their curves must be linear and the
/// constrained dofs fixed.
fn linear_loads(s: &StructureSection, file: &Path, what: &str) -> anyhow::Result<()> {
    for (k, l) in s.loads.iter().enumerate() {
        if !matches!(l.curve, None | Some(CurveSpec::Named(CurveName::Linear))) {
            return Err(field_error(
                file,
                &format!("structure.loads[{k}].curve"),
                format!("{what} scales the loads with the load factor; use \"linear\""),
            ));
        }
    }
    if let Some(k) = s.bc.iter().position(|b| b.prescribed.is_some()) {
        return Err(field_error(
            file,
            &format!("structure.bc[{k}].prescribed"),
            format!("{what} holds the constrained dofs fixed; use `fixed`"),
        ));
    }
    Ok(())
}
