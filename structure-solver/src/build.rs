//! The structure of a case, ready to integrate: the `[structure]` section (DESIGN §7; the
//! schema is documented in `interface_protocol::case::structure`) made into one
//! `assembly::FeModel`: the mesh and its sets ([`crate::case_mesh`]), the element part of each
//! cell, boundary conditions, loads with time curves, rigid bodies (and their springs) and the
//! initial velocity.
//! Errors name the case file and the field.

use anyhow::anyhow;
use interface_protocol::case::{
    BeamSectionSpec, Case, CurveName, CurveSpec, ElementType, Integrator, LoadKind,
    StructureMaterial, StructureSection, Symmetry,
};

use crate::assembly::{Curve, FeModel, NodeSpring, Part, RotaryInertia};
use crate::case_mesh::build_mesh;
use crate::elements::{BeamSection, BeamYield, ShellSection, ShellYield};
use crate::material::{Elastic, Material, J2};
use crate::mesh::{validate, CellKind, Mesh};
use crate::model::Model;
use crate::output::CellMap;
use crate::rigid::{ExtraMass, RigidReference};
use crate::wet::tet_boundary;

pub(crate) fn need<'a, T>(v: &'a Option<T>, field: &str, case: &Case) -> anyhow::Result<&'a T> {
    v.as_ref().ok_or_else(|| {
        field_error(case, &format!("structure.{field}"), "is required to run structure-solver")
    })
}

/// An error naming the case file, the line of `field` and the field.
pub(crate) fn field_error(
    case: &Case,
    field: &str,
    message: impl std::fmt::Display,
) -> anyhow::Error {
    case.field_error(field, message.to_string()).into()
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
pub(crate) fn node_set(
    mesh: &Mesh,
    name: &str,
    field: &str,
    case: &Case,
) -> anyhow::Result<Vec<usize>> {
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
    Err(field_error(case, field, format!("no set \"{name}\"; known sets: {}", known_sets(mesh))))
}

/// The cells of set `name` (a cell set, else the cells whose nodes all lie in the node set).
fn cell_set(mesh: &Mesh, name: &str, field: &str, case: &Case) -> anyhow::Result<Vec<usize>> {
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
            return Err(field_error(case, field, format!("node set \"{name}\" holds no cell")));
        }
        return Ok(cells);
    }
    Err(field_error(case, field, format!("no set \"{name}\"; known sets: {}", known_sets(mesh))))
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
fn cell_parts(s: &StructureSection, mesh: &Mesh, case: &Case) -> anyhow::Result<Vec<Option<Part>>> {
    let materials = s.all_materials();
    let single;
    let parts = if s.parts.is_empty() {
        let element = s.element.unwrap_or(ElementType::Bt4);
        let thickness = match element {
            ElementType::Beam => {
                return Err(field_error(
                    case,
                    "structure.element",
                    "beams need a section and an `up` vector: give them in [[structure.parts]]",
                ))
            }
            ElementType::Tet4 => None,
            _ => Some(*need(&s.thickness, "thickness", case)?),
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
            need(&s.material, "material", case)?;
        }
        &single[..]
    } else {
        &s.parts[..]
    };
    let top = s.parts.is_empty();
    let top_dim = mesh.cells.iter().map(|c| dimension(c.kind)).max().unwrap_or(0);
    let mut out: Vec<Option<(usize, Part)>> = vec![None; mesh.cells.len()];
    // the first J2 bt4 part and its thickness points: the others must have as many
    let mut bt4_points: Option<(usize, usize)> = None;
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
                field_error(case, "structure.material", "is required to run structure-solver")
            })?,
        };
        let mut cells = match &p.set {
            Some(name) => cell_set(mesh, name, &f("set"), case)?,
            None => (0..mesh.cells.len())
                .filter(|&c| dimension(mesh.cells[c].kind) == top_dim)
                .collect(),
        };
        // in the user's order, so an error names the user's first offending cell
        cells.sort_by_key(|&c| mesh.cell_user(c));
        let h = p.thickness.unwrap_or_default();
        let (section, yield_) = shell(m, h, p.points);
        if let (ElementType::Bt4, Some(y)) = (p.element, yield_) {
            let (first, n) = *bt4_points.get_or_insert((k, y.points));
            if n != y.points {
                return Err(field_error(
                    case,
                    &f("points"),
                    format!(
                        "J2 bt4 parts share one number of thickness points: \
                         structure.parts[{first}] has {n}, this part {}",
                        y.points
                    ),
                ));
            }
        }
        for c in cells {
            let kind = mesh.cells[c].kind;
            let part = match (p.element, kind) {
                // the cell decides: BT4 on quadrilaterals, BLT3 on triangles
                (ElementType::Bt4, CellKind::Quad4 | CellKind::Tri3) => Part::Bt4(section, yield_),
                (ElementType::Mitc4, CellKind::Quad4)
                | (ElementType::Dkt, CellKind::Tri3)
                | (ElementType::Shell, CellKind::Quad4 | CellKind::Tri3) => match yield_ {
                    Some(y) => Part::ShellJ2(section, y),
                    None => Part::Shell(section),
                },
                (ElementType::Beam, CellKind::Line2) => {
                    let sec = p.section.as_ref().expect("validated: beams have a section");
                    let up = p.up.expect("validated: beams have up");
                    match m.sigma_y {
                        None => Part::Beam(beam_section(m, sec), up),
                        // J2 beams integrate fibres over the rectangle
                        Some(_) if sec.rectangle.is_none() => {
                            return Err(field_error(
                                case,
                                &f("section"),
                                "J2 beams (a material with sigma_y) need `rectangle = [b, h]`",
                            ))
                        }
                        Some(sigma_y) => {
                            let y = BeamYield {
                                sigma_y,
                                hardening: m.hardening,
                                points: p.points.unwrap_or(8),
                            };
                            Part::BeamJ2(beam_section(m, sec), up, y)
                        }
                    }
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
                        ElementType::Mitc4 => "quadrilaterals",
                        ElementType::Dkt => "triangles",
                        ElementType::Bt4 | ElementType::Shell => "triangles or quadrilaterals",
                        ElementType::Beam => "2-node lines",
                        ElementType::Tet4 => "tetrahedra",
                    };
                    let set = p.set.as_deref().unwrap_or("all");
                    return Err(field_error(
                        case,
                        &f("element"),
                        format!(
                            "{e:?} needs {needs}; cell {} of set \"{set}\" is a {kind:?}",
                            mesh.cell_user(c)
                        )
                        .to_lowercase(),
                    ));
                }
            };
            if let Some((other, _)) = out[c] {
                return Err(field_error(
                    case,
                    &f("set"),
                    format!(
                        "cell {} already belongs to structure.parts[{other}]",
                        mesh.cell_user(c)
                    ),
                ));
            }
            out[c] = Some((k, part));
        }
    }
    // the first in the user's numbering
    if let Some(c) = mesh
        .cells_in_user_order()
        .into_iter()
        .find(|&c| out[c].is_none() && dimension(mesh.cells[c].kind) == top_dim)
    {
        return Err(field_error(
            case,
            "structure.parts",
            format!(
                "cell {} (a {:?}) belongs to no part; add a part over it",
                mesh.cell_user(c),
                mesh.cells[c].kind
            ),
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
    let s = section(case)?;
    let mesh = build_mesh(s, case)?;
    let parts = cell_parts(s, &mesh, case)?;
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
    let mut fe =
        FeModel::new(&elements, part).map_err(|e| field_error(case, "structure.parts", e))?;
    fe.set_rotary_inertia(rotary);
    // The user's ids (gmsh node tags, else the input numbers) in the topology layer, apart
    // from the storage slots of the renumbered mesh.
    let node_ids = (0..mesh.nodes.len()).map(|s| mesh.node_id(s)).collect();
    let cell_ids = kept.iter().map(|&c| mesh.cell_user(c) as u64).collect();
    fe.set_ids(node_ids, cell_ids).map_err(|e| field_error(case, "structure.mesh", e))?;
    let mut mesh = mesh;
    // Rigid body of each slave node.
    let mut body_of = vec![None; mesh.nodes.len()];
    for (k, rb) in s.rigid_bodies.iter().enumerate() {
        let f = format!("structure.rigid_bodies[{k}]");
        let nodes = node_set(&mesh, &rb.set, &format!("{f}.set"), case)?;
        let reference = match (rb.reference, &rb.reference_set) {
            (Some(p), _) => RigidReference::Point(p),
            (None, Some(name)) => {
                let field = format!("{f}.reference_set");
                match node_set(&mesh, name, &field, case)?[..] {
                    [n] => RigidReference::Node(n),
                    ref other => {
                        return Err(field_error(
                            case,
                            &field,
                            format!("expected a set of one node, \"{name}\" holds {}", other.len()),
                        ))
                    }
                }
            }
            (None, None) => RigidReference::MassCentre,
        };
        let extra = ExtraMass {
            mass: rb.mass,
            inertia: rb.inertia.unwrap_or_default(),
            ..ExtraMass::default()
        };
        let field = if rb.inertia.is_some() { format!("{f}.inertia") } else { f.clone() };
        let master =
            fe.rigid_body(&nodes, reference, extra).map_err(|e| field_error(case, &field, e))?;
        if !matches!(reference, RigidReference::Node(_)) {
            // A new reference node joins the mesh (output, probes) and the set `all`.
            let p = fe.initial_positions()[master];
            mesh.push_node([p.x, p.y, p.z]);
            mesh.node_sets.get_mut("all").expect("built with the mesh").push(master);
            body_of.push(None);
        }
        if let Some(sp) = &rb.spring {
            let spring = NodeSpring { node: master, stiffness: sp.stiffness, preload: sp.preload };
            fe.add_spring(spring).map_err(|e| field_error(case, &format!("{f}.spring"), e))?;
        }
        mesh.node_sets.insert(format!("{}_reference", rb.set), vec![master]);
        nodes.iter().filter(|&&n| n != master).for_each(|&n| body_of[n] = Some(k));
    }
    let statics = s.integrator() == Integrator::Static;
    let default_curve = if statics { Curve::Linear } else { Curve::Constant };
    let mut skew = Vec::new();
    for (k, bc) in s.bc.iter().enumerate() {
        let f = format!("structure.bc[{k}]");
        let nodes = node_set(&mesh, &bc.set, &format!("{f}.set"), case)?;
        if let Some((n, b)) = nodes.iter().find_map(|&n| body_of[n].map(|b| (n, b))) {
            return Err(field_error(
                case,
                &format!("{f}.set"),
                format!(
                    "node {} moves with structure.rigid_bodies[{b}]; constrain its reference \
                     node, set \"{}_reference\"",
                    mesh.node_id(n),
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
        fe.symmetry_plane(&nodes, n).map_err(|e| field_error(case, &f, e))?;
    }
    for (k, l) in s.loads.iter().enumerate() {
        let f = format!("structure.loads[{k}]");
        let c = curve(l.curve.as_ref(), default_curve.clone());
        match l.kind().expect("validated") {
            LoadKind::Point { set, dof, value } => {
                for n in node_set(&mesh, set, &format!("{f}.set"), case)? {
                    fe.point_load(n, dof.index(), value, c.clone());
                }
            }
            LoadKind::Pressure { set: Some(name), p } if solid_set(&mesh, name, &kept) => {
                let faces = solid_faces(&mesh, name, &kept);
                if faces.is_empty() {
                    return Err(field_error(
                        case,
                        &format!("{f}.set"),
                        format!("no boundary face of a tet of a part lies in \"{name}\""),
                    ));
                }
                fe.face_pressure(&faces, p, c).map_err(|e| field_error(case, &f, e))?;
            }
            LoadKind::Pressure { set, p } => {
                let face =
                    |c: &usize| matches!(mesh.cells[*c].kind, CellKind::Tri3 | CellKind::Quad4);
                let cells = match set {
                    Some(name) => cell_set(&mesh, name, &format!("{f}.set"), case)?,
                    None => kept.iter().copied().filter(face).collect(),
                };
                if cells.is_empty() {
                    return Err(field_error(
                        case,
                        &format!("{f}.pressure"),
                        "the model has no shell",
                    ));
                }
                if let Some(bad) = cells.iter().find(|c| !face(c) || model_cell[**c].is_none()) {
                    return Err(field_error(
                        case,
                        &format!("{f}.set"),
                        format!(
                            "a pressure acts on the shells of a part; cell {} is a {:?}{}",
                            mesh.cell_user(*bad),
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
        for node in node_set(&mesh, &iv.set, &f, case)? {
            v0[6 * node + iv.dof.index()] = iv.value;
        }
    }
    for (v, &c) in v0.iter_mut().zip(fe.constrained()) {
        if c {
            *v = 0.0;
        }
    }
    let is_bt4 = |c: &usize| matches!(parts[*c], Some(Part::Bt4(..)));
    let cells_of = &mesh.cells;
    let kind = |k: CellKind| move |c: &usize| is_bt4(c) && cells_of[*c].kind == k;
    let cells = CellMap {
        elements: kept.iter().copied().filter(|c| !is_bt4(c)).collect(),
        bt4: kept.iter().copied().filter(kind(CellKind::Quad4)).collect(),
        blt3: kept.iter().copied().filter(kind(CellKind::Tri3)).collect(),
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
    let length =
        if thinnest.is_finite() { thinnest } else { 1e-3 * validate::diagonal(&mesh.nodes) };
    Ok(Structure { mesh, model: fe, v0, cells, length })
}

/// Whether the load set `name` names faces of solids: a cell set of tets, a cell set of
/// faces in no part (a gmsh physical surface on a solid), or a node set (not a cell set)
/// when the model has tets.
fn solid_set(mesh: &Mesh, name: &str, kept: &[usize]) -> bool {
    let tets = || kept.iter().any(|&c| mesh.cells[c].kind == CellKind::Tet4);
    match mesh.cell_set(name) {
        Ok(cells) => {
            cells.iter().all(|&c| mesh.cells[c].kind == CellKind::Tet4)
                || (tets() && cells.iter().all(|c| kept.binary_search(c).is_err()))
        }
        Err(_) => mesh.node_set(name).is_ok() && tets(),
    }
}

/// The boundary faces (outward, `wet::tet_boundary`) a pressure on the solid set `name`
/// acts on: those of its tets, or the boundary faces of the model's tets whose nodes all
/// belong to the set's cells or nodes.
fn solid_faces(mesh: &Mesh, name: &str, kept: &[usize]) -> Vec<[usize; 3]> {
    let is_tet = |c: &usize| mesh.cells[*c].kind == CellKind::Tet4;
    if let Ok(cells) = mesh.cell_set(name) {
        if cells.iter().all(is_tet) {
            return tet_boundary(mesh, cells);
        }
    }
    let mut inside = vec![false; mesh.nodes.len()];
    match mesh.cell_set(name) {
        Ok(cells) => {
            cells.iter().flat_map(|&c| &mesh.cells[c].nodes).for_each(|&n| inside[n] = true)
        }
        Err(_) => mesh.node_set(name).unwrap_or(&[]).iter().for_each(|&n| inside[n] = true),
    }
    let tets: Vec<usize> = kept.iter().copied().filter(is_tet).collect();
    tet_boundary(mesh, &tets).into_iter().filter(|f| f.iter().all(|&n| inside[n])).collect()
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
