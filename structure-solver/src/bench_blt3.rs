//! `structure-solver bench`, the 3-node shell row: whole explicit steps of BLT3 + J2 (5 points,
//! plane-stress return) on the bench plate split into triangles, the same number of elements
//! as the BT4 row, natural order, on each thread count (DESIGN §6). The step is the one of
//! the model's explicit loop: forces, velocity and position update, and the stable step
//! scaled from the reference bound (`Blt3::scaled_stable_dt`).

use serde::Serialize;

use crate::bench::{advance_positions, plate_velocity, steel, timed, update_velocities};
use crate::elements::blt3::{Blt3, Blt3Settings};
use crate::mesh::generate::rectangle;

/// The BLT3 row.
#[derive(Debug, Serialize)]
pub struct Blt3Bench {
    pub elements: usize,
    pub steps: usize,
    pub thickness_points: usize,
    /// State and work arrays per element, without the nodal arrays.
    pub bytes_per_element: f64,
    /// On the first thread count (1 by default).
    pub element_updates_per_s_per_core: f64,
    pub runs: Vec<Blt3Run>,
    /// Element updates per second on 2 threads over 1 thread.
    pub speedup_2_threads: Option<f64>,
}

/// Timed whole steps on `threads` threads.
#[derive(Debug, Serialize)]
pub struct Blt3Run {
    pub threads: usize,
    /// Share of thickness points yielding in the timed steps.
    pub plastic_fraction: f64,
    pub element_updates_per_s: f64,
    pub element_updates_per_s_per_core: f64,
    pub ns_per_element_update: f64,
    /// Per second of processor time of the process (all threads).
    pub element_updates_per_cpu_s: f64,
}

/// Free explicit dynamics of the triangulated bench plate (central difference, no load).
struct Blt3Explicit {
    blt3: Blt3,
    x: Vec<[f64; 3]>,
    v: Vec<f64>,
    du: Vec<f64>,
    f: Vec<f64>,
    inv_mass: Vec<f64>,
    dt: f64,
}

impl Blt3Explicit {
    /// The unit square in `n x n` quads numbered row by row, each split in two triangles along
    /// its first diagonal, `n` the smallest with `2 n² >= elements`; 10 mm steel.
    fn new(elements: usize) -> anyhow::Result<Blt3Explicit> {
        let n = ((elements as f64 / 2.0).sqrt().ceil() as usize).max(1);
        let mesh = rectangle(1.0, 1.0, n, n);
        let conn: Vec<[u32; 3]> = mesh
            .cells
            .iter()
            .flat_map(|c| {
                let q = [c.nodes[0], c.nodes[1], c.nodes[2], c.nodes[3]].map(|v| v as u32);
                [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
            })
            .collect();
        let ne = conn.len();
        let x0 = mesh.nodes;
        let mut blt3 = Blt3::new(conn, vec![0.01; ne], steel(), Blt3Settings::default())?;
        blt3.set_reference(&x0);
        let nn = x0.len();
        let mut mass = vec![0.0; 6 * nn];
        blt3.lumped_mass(&x0, &mut mass);
        let dt = 0.9 * blt3.scaled_stable_dt(&x0);
        Ok(Blt3Explicit {
            blt3,
            v: plate_velocity(&x0),
            x: x0,
            du: vec![0.0; 6 * nn],
            f: vec![0.0; 6 * nn],
            inv_mass: mass.iter().map(|m| 1.0 / m).collect(),
            dt,
        })
    }

    /// One whole step, as `bench::Bt4Explicit::step`.
    fn step(&mut self) {
        advance_positions(self.dt, &mut self.x, &mut self.du, &self.v, &mut self.f);
        self.blt3.internal_force(&self.x, &self.du, &mut self.f);
        self.blt3.commit();
        update_velocities(self.dt, &mut self.v, &self.f, &self.inv_mass);
        self.dt = 0.9 * self.blt3.scaled_stable_dt(&self.x);
    }

    fn plastic(&self) -> Vec<f64> {
        let np = self.blt3.settings.rule.len();
        (0..self.blt3.n_elements())
            .flat_map(|e| (0..np).map(move |p| (e, p)))
            .map(|(e, p)| self.blt3.plastic_strain(e, p))
            .collect()
    }
}

/// Times `steps` whole steps (after 20 untimed) of the triangulated plate of about `elements`
/// elements on each thread count.
pub fn run(elements: usize, steps: usize, threads: &[usize]) -> anyhow::Result<Blt3Bench> {
    anyhow::ensure!(elements > 0 && steps > 0, "--elements and the steps must be positive");
    anyhow::ensure!(
        !threads.is_empty() && threads.iter().all(|&t| t > 0),
        "--threads must list thread counts of at least 1, e.g. 1,2"
    );
    const WARMUP: usize = 20;
    let mut runs = Vec::new();
    let mut info = None;
    for &t in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let mut sim = Blt3Explicit::new(elements)?;
        let (secs, cpu, plastic) = pool.install(|| {
            for _ in 0..WARMUP {
                sim.step();
            }
            let alpha0 = sim.plastic();
            let (secs, cpu) = timed(|| (0..steps).for_each(|_| sim.step()));
            let alpha = sim.plastic();
            let yielding = alpha.iter().zip(&alpha0).filter(|(a, b)| a > b).count();
            (secs, cpu, yielding as f64 / alpha.len() as f64)
        });
        let ne = sim.blt3.n_elements();
        info.get_or_insert((ne, sim.blt3.settings.rule.len(), sim.blt3.bytes_per_element()));
        let rate = (ne * steps) as f64 / secs;
        runs.push(Blt3Run {
            threads: t,
            plastic_fraction: plastic,
            element_updates_per_s: rate,
            element_updates_per_s_per_core: rate / t as f64,
            ns_per_element_update: 1e9 / rate,
            element_updates_per_cpu_s: (ne * steps) as f64 / cpu,
        });
    }
    let (elements, thickness_points, bytes_per_element) = info.expect("one run at least");
    let rate = |t: usize| runs.iter().find(|r| r.threads == t).map(|r| r.element_updates_per_s);
    Ok(Blt3Bench {
        elements,
        steps,
        thickness_points,
        bytes_per_element,
        element_updates_per_s_per_core: runs[0].element_updates_per_s_per_core,
        speedup_2_threads: rate(1).zip(rate(2)).map(|(a, b)| b / a),
        runs,
    })
}
