//! `structure-solver run CASE`: a structure alone, from the `[structure]` section of a case
//! (DESIGN §7): mesh, node sets, material, BCs, loads, initial velocity, integrator; probes go
//! to `structure_probes.csv` in the output folder.

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use anyhow::{anyhow, bail, Context};
use interface_protocol::case::{structure_dof, Case, StructureMesh, StructureSection};
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{bucket, case_echo, versions, RunReport, Timers};

use crate::assembly::{Curve, FeModel, Part, RotaryInertia};
use crate::elements::bt4::{Bt4, Bt4Settings};
use crate::elements::ShellSection;
use crate::explicit_shell::ShellModel;
use crate::material::{Elastic, J2};
use crate::mesh::{generate, gmsh, CellKind, Mesh};
use crate::output::{gather_nodal, FieldOutput};
use crate::restart::{load_dynamics, save_dynamics, Restorable, PART};
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

/// The structure of a case, ready to integrate: its mesh, model and initial velocity.
pub struct Structure {
    pub mesh: Mesh,
    pub model: Box<dyn Restorable>,
    /// Initial velocity per dof (zero on constrained dofs).
    pub v0: Vec<f64>,
    /// `"bt4"` or `"mitc4"`.
    pub element: String,
    pub thickness: f64,
}

/// Builds the `[structure]` of `case`: mesh and sets, elements, BCs, loads, initial velocity.
/// `rotary` is the rotary inertia of the MITC4 model (BT4 always scales it).
pub fn build(case: &Case, rotary: RotaryInertia) -> anyhow::Result<Structure> {
    let file = case.source.path.clone();
    let s = section(case)?;
    let mesh = build_mesh(s, case)?;
    let m = need(&s.material, "material", &file)?;
    let h = *need(&s.thickness, "thickness", &file)?;
    let elastic = Elastic { e: m.e, nu: m.nu, rho: m.rho };
    let j2 = J2 { elastic, sigma_y: m.sigma_y.unwrap_or(f64::INFINITY), h: m.hardening };
    let element = s.element.as_deref().unwrap_or("bt4");
    let n = mesh.nodes.len();
    let model: Box<dyn Restorable> = match element {
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
            fe.set_rotary_inertia(rotary);
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

    Ok(Structure { mesh, model, v0, element: element.to_string(), thickness: h })
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
    t_end: f64,
}

impl AloneOutput {
    fn write(
        &mut self,
        model: &dyn Restorable,
        v: &[f64],
        step: u64,
        t: f64,
        dt: f64,
    ) -> anyhow::Result<()> {
        let last = t >= self.t_end * (1.0 - 1e-12);
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
            self.fields.gather(t, model, v)?;
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
fn read_checkpoint(from: &Path, model: &mut dyn Restorable) -> anyhow::Result<Resume> {
    let dir = from.join("checkpoints");
    let found = checkpoint::latest(&dir, &[PART])?.ok_or_else(|| {
        anyhow!("--restart {}: no complete checkpoint in {}", from.display(), dir.display())
    })?;
    let ck = Checkpoint::read(&dir, &found.tag, PART)?;
    model.restore_state(&ck)?;
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
    model: &dyn Restorable,
    d: &Dynamics,
    step: u64,
    dt: f64,
) -> anyhow::Result<()> {
    let mut ck = Checkpoint::new(step, d.t);
    model.save_state(&mut ck)?;
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
    let Structure { mesh, mut model, v0, element, thickness: h } =
        build(&case, RotaryInertia::Physical)?;
    let t_end = *need(&s.t_end, "t_end", &file)?;
    let element = element.as_str();
    let integrator = s.integrator.as_deref().unwrap_or("central_difference");
    let n = mesh.nodes.len();

    let out = opts.out.clone().unwrap_or_else(|| default_run_dir(&opts.case, SystemTime::now()));
    // Read the checkpoint before the output folder is made: it may be the same folder.
    let mut resume = match &opts.restart {
        Some(from) => Some(read_checkpoint(from, model.as_mut())?),
        None => None,
    };
    let dir = OutputDir::create(&out, Policy::Overwrite)?;
    let checkpoint_every = case.output.checkpoint_every;
    let checkpoint = |model: &dyn Restorable, d: &Dynamics, step: u64, dt: f64| {
        if checkpoint_every > 0 && step % checkpoint_every == 0 {
            write_checkpoint(&dir, model, d, step, dt)
        } else {
            Ok(())
        }
    };
    let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
    let started = Instant::now();
    let mut output = AloneOutput {
        probe_nodes: s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect(),
        probes: ProbeWriter::structure(dir.path(), &names)?,
        probes_every: s.output_every.unwrap_or(1).max(1),
        fields: FieldOutput::create(dir.path(), &mesh)?,
        fields_every: case.output.fields_every,
        disp: vec![[0.0; 3]; n],
        vel: vec![[0.0; 3]; n],
        bar: Progress::new(t_end, opts.quiet),
        t_end,
    };
    let mut timers = Timers::new();
    let write =
        |o: &mut AloneOutput, model: &dyn Restorable, v: &[f64], step: u64, t: f64, dt: f64| {
            o.write(model, v, step, t, dt)
        };

    let mut steps = resume.as_ref().map_or(0, |r| r.step);
    let dt;
    match integrator {
        "central_difference" => {
            dt = match (&resume, s.dt) {
                (Some(r), _) => r.dt,
                (None, Some(dt)) => dt,
                (None, None) => {
                    let est = critical_dt(model.as_mut(), 0.0, 100, 1e-9 * h);
                    s.safety.unwrap_or(0.8) * est.stable(1.0)
                }
            };
            if !(dt.is_finite() && dt > 0.0) {
                bail!("{}: no stable step could be estimated; give `structure.dt`", file.display());
            }
            let mut cd = match resume.take() {
                Some(r) => CentralDifference::resume(model.as_ref(), r.dynamics),
                None => CentralDifference::new(model.as_mut(), 0.0, v0, None),
            };
            write(&mut output, model.as_ref(), &cd.state.v, steps, cd.state.t, dt)?;
            while cd.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - cd.state.t);
                timers.time(bucket::STRUCTURE, || cd.step(model.as_mut(), step, None));
                steps += 1;
                let t0 = Instant::now();
                write(&mut output, model.as_ref(), &cd.state.v, steps, cd.state.t, step)
                    .with_context(|| format!("step {steps} of {dt:.3e} s"))?;
                checkpoint(model.as_ref(), &cd.state, steps, dt)?;
                timers.add_since(bucket::OUTPUT, t0);
            }
        }
        scheme => {
            if element == "bt4" {
                bail!("{}: field `structure.integrator`: bt4 is explicit; use element = \"mitc4\" with {scheme}", file.display());
            }
            dt = match &resume {
                Some(r) => r.dt,
                None => *need(&s.dt, "dt", &file)?,
            };
            let scheme = if scheme == "newmark" {
                ImplicitScheme::Newmark
            } else {
                ImplicitScheme::Midpoint
            };
            let mut im = match resume.take() {
                Some(r) => Implicit::resume(model.as_ref(), scheme, r.dynamics),
                None => Implicit::new(model.as_mut(), scheme, 0.0, v0, None),
            };
            write(&mut output, model.as_ref(), &im.state.v, steps, im.state.t, dt)?;
            while im.state.t < t_end * (1.0 - 1e-12) {
                let step = dt.min(t_end - im.state.t);
                timers.time(bucket::STRUCTURE, || im.step(model.as_mut(), step, None))?;
                steps += 1;
                let t0 = Instant::now();
                write(&mut output, model.as_ref(), &im.state.v, steps, im.state.t, step)?;
                checkpoint(model.as_ref(), &im.state, steps, dt)?;
                timers.add_since(bucket::OUTPUT, t0);
            }
        }
    }
    output.probes.flush()?;
    output.fields.finish()?;
    output.bar.finish();
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
        eprintln!(
            "structure-solver: {steps} steps of {dt:.3e} s to t = {t_end}; outputs in {}",
            out.display()
        );
    }
    Ok(RunSummary { steps, t: t_end, dt, out })
}
