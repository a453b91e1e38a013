//! `structure-solver run CASE`: a structure alone, from the `[structure]` section of a case
//! (DESIGN §7): mesh, node sets, material, BCs, loads, initial velocity, integrator; probes go
//! to `structure_probes.csv` in the output folder.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use anyhow::{anyhow, bail, Context};
use interface_protocol::case::{structure_dof, Case, StructureMesh, StructureSection};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;

use crate::assembly::{Curve, FeModel, Part};
use crate::elements::bt4::{Bt4, Bt4Settings};
use crate::elements::ShellSection;
use crate::explicit_shell::ShellModel;
use crate::material::{Elastic, J2};
use crate::mesh::{generate, gmsh, CellKind, Mesh};
use crate::model::Model;
use crate::time::{critical_dt, CentralDifference, Implicit, ImplicitScheme};

/// Options of `run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub case: PathBuf,
    pub out: Option<PathBuf>,
    pub set: Vec<String>,
    pub quiet: bool,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub steps: u64,
    pub t: f64,
    pub dt: f64,
    pub out: PathBuf,
}

fn need<'a, T>(v: &'a Option<T>, field: &str, file: &Path) -> anyhow::Result<&'a T> {
    v.as_ref().ok_or_else(|| {
        anyhow!("{}: field `structure.{field}` is required to run structure-solver", file.display())
    })
}

/// The mesh of the case, with the box sets and `all` added.
fn build_mesh(s: &StructureSection, case: &Case) -> anyhow::Result<Mesh> {
    let file = &case.source.path;
    let mut mesh = match need(&s.mesh, "mesh", file)? {
        StructureMesh::Rectangle { lx, ly, nx, ny, .. } => generate::rectangle(*lx, *ly, *nx, *ny),
        StructureMesh::Gmsh { gmsh: path } => {
            let p = case.dir().join(path);
            gmsh::read(&p)
                .with_context(|| format!("{}: field `structure.mesh.gmsh`", file.display()))?
        }
    };
    for (name, b) in &s.sets {
        let nodes = mesh.nodes_where(|p| (0..3).all(|k| p[k] >= b.min[k] && p[k] <= b.max[k]));
        if nodes.is_empty() {
            bail!("{}: field `structure.sets.{name}`: no node inside the box", file.display());
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    mesh.node_sets.insert("all".into(), (0..mesh.nodes.len()).collect());
    Ok(mesh)
}

fn set<'a>(mesh: &'a Mesh, name: &str, field: &str, file: &Path) -> anyhow::Result<&'a [usize]> {
    mesh.node_set(name).map_err(|_| {
        anyhow!("{}: field `structure.{field}`: no node set \"{name}\"", file.display())
    })
}

/// Runs a case alone.
pub fn run(opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let case = Case::load(&opts.case, &opts.set)?;
    let file = case.source.path.clone();
    let s = case.structure.as_ref().ok_or_else(|| {
        anyhow!("{}: a `[structure]` section is required to run structure-solver", file.display())
    })?;
    let mesh = build_mesh(s, &case)?;
    let m = need(&s.material, "material", &file)?;
    let h = *need(&s.thickness, "thickness", &file)?;
    let t_end = *need(&s.t_end, "t_end", &file)?;
    let elastic = Elastic { e: m.e, nu: m.nu, rho: m.rho };
    let j2 = J2 { elastic, sigma_y: m.sigma_y.unwrap_or(f64::INFINITY), h: m.hardening };
    let element = s.element.as_deref().unwrap_or("bt4");
    let integrator = s.integrator.as_deref().unwrap_or("central_difference");
    let n = mesh.nodes.len();

    let mut model: Box<dyn Model> = match element {
        "bt4" => {
            let mut conn = Vec::with_capacity(mesh.cells.len());
            for (i, c) in mesh.cells.iter().enumerate() {
                if c.kind != CellKind::Quad4 {
                    bail!("{}: field `structure.element`: bt4 needs quadrilaterals, cell {i} is a {:?}", file.display(), c.kind);
                }
                conn.push([c.nodes[0], c.nodes[1], c.nodes[2], c.nodes[3]].map(|v| v as u32));
            }
            let ne = conn.len();
            let mut sm = ShellModel::new(
                mesh.nodes.clone(),
                Bt4::new(conn, vec![h; ne], j2, Bt4Settings::default()),
            );
            for (k, bc) in s.bc.iter().enumerate() {
                for &node in set(&mesh, &bc.set, &format!("bc[{k}].set"), &file)? {
                    for d in &bc.dofs {
                        let dof = 6 * node + structure_dof(d).expect("validated");
                        sm.constrain(dof);
                        sm.prescribed_velocity[dof] = bc.velocity;
                    }
                }
            }
            for (k, l) in s.loads.iter().enumerate() {
                for &node in set(&mesh, &l.set, &format!("loads[{k}].set"), &file)? {
                    sm.loads[6 * node + structure_dof(&l.dof).expect("validated")] += l.value;
                }
            }
            Box::new(sm)
        }
        _ => {
            if m.sigma_y.is_some() {
                bail!("{}: field `structure.material.sigma_y`: the mitc4 model is elastic; use element = \"bt4\" for J2", file.display());
            }
            let section = ShellSection { e: m.e, nu: m.nu, rho: m.rho, h };
            let mut fe = FeModel::new(&mesh, |_| Part::Shell(section))?;
            for (k, bc) in s.bc.iter().enumerate() {
                let nodes = set(&mesh, &bc.set, &format!("bc[{k}].set"), &file)?.to_vec();
                for d in &bc.dofs {
                    let c = structure_dof(d).expect("validated");
                    if bc.velocity == 0.0 {
                        let mut mask = [false; 6];
                        mask[c] = true;
                        fe.fix(&nodes, mask);
                    } else {
                        fe.prescribe(&nodes, c, bc.velocity, Curve::Linear);
                    }
                }
            }
            for (k, l) in s.loads.iter().enumerate() {
                for &node in set(&mesh, &l.set, &format!("loads[{k}].set"), &file)? {
                    fe.point_load(
                        node,
                        structure_dof(&l.dof).expect("validated"),
                        l.value,
                        Curve::Constant,
                    );
                }
            }
            Box::new(fe)
        }
    };
    let mut v0 = vec![0.0; 6 * n];
    for (k, iv) in s.initial_velocity.iter().enumerate() {
        for &node in set(&mesh, &iv.set, &format!("initial_velocity[{k}].set"), &file)? {
            v0[6 * node + structure_dof(&iv.dof).expect("validated")] = iv.value;
        }
    }
    for (v, &c) in v0.iter_mut().zip(model.constrained()) {
        if c {
            *v = 0.0;
        }
    }

    let out = opts.out.clone().unwrap_or_else(|| default_run_dir(&opts.case, SystemTime::now()));
    let dir = OutputDir::create(&out, Policy::Overwrite)?;
    let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
    let probe_nodes: Vec<usize> = s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect();
    let mut probes = ProbeWriter::structure(dir.path(), &names)?;
    let every = s.output_every.unwrap_or(1).max(1);
    let mut disp = vec![[0.0; 3]; n];
    let mut row = vec![0.0; 6 * probe_nodes.len()];
    let mut write =
        |model: &dyn Model, v: &[f64], t: f64, probes: &mut ProbeWriter| -> anyhow::Result<()> {
            model.displacement(&mut disp);
            for (i, &p) in probe_nodes.iter().enumerate() {
                row[6 * i..6 * i + 3].copy_from_slice(&disp[p]);
                row[6 * i + 3..6 * i + 6].copy_from_slice(&v[6 * p..6 * p + 3]);
            }
            probes.write_row(t, &row)?;
            Ok(())
        };

    let mut steps = 0u64;
    let dt;
    match integrator {
        "central_difference" => {
            let est = critical_dt(model.as_mut(), 0.0, 100, 1e-9 * h);
            dt = s.dt.unwrap_or(s.safety.unwrap_or(0.8) * est.stable(1.0));
            if !(dt.is_finite() && dt > 0.0) {
                bail!("{}: no stable step could be estimated; give `structure.dt`", file.display());
            }
            let mut cd = CentralDifference::new(model.as_mut(), 0.0, v0, None);
            write(model.as_ref(), &cd.state.v, 0.0, &mut probes)?;
            while cd.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - cd.state.t);
                cd.step(model.as_mut(), step, None);
                steps += 1;
                if steps % every == 0 || cd.state.t >= t_end * (1.0 - 1e-12) {
                    if cd.state.v.iter().any(|v| !v.is_finite()) {
                        bail!("non-finite velocity at step {steps}, t = {}: the step {dt:.3e} is unstable", cd.state.t);
                    }
                    write(model.as_ref(), &cd.state.v, cd.state.t, &mut probes)?;
                }
            }
        }
        scheme => {
            if element == "bt4" {
                bail!("{}: field `structure.integrator`: bt4 is explicit; use element = \"mitc4\" with {scheme}", file.display());
            }
            dt = *need(&s.dt, "dt", &file)?;
            let scheme = if scheme == "newmark" {
                ImplicitScheme::Newmark
            } else {
                ImplicitScheme::Midpoint
            };
            let mut im = Implicit::new(model.as_mut(), scheme, 0.0, v0, None);
            write(model.as_ref(), &im.state.v, 0.0, &mut probes)?;
            while im.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - im.state.t);
                im.step(model.as_mut(), step, None)?;
                steps += 1;
                if steps % every == 0 || im.state.t >= t_end * (1.0 - 1e-12) {
                    write(model.as_ref(), &im.state.v, im.state.t, &mut probes)?;
                }
            }
        }
    }
    probes.flush()?;
    if !opts.quiet {
        eprintln!(
            "structure-solver: {steps} steps of {dt:.3e} s to t = {t_end}; outputs in {}",
            out.display()
        );
    }
    Ok(RunSummary { steps, t: t_end, dt, out })
}
