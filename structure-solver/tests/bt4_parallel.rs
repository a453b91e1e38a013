//! The explicit BT4 loop: forces and state bitwise independent of the thread count, the same
//! on every vector width the processor has, and a part of two materials equal to two parts of
//! one material each.

use structure_solver::elements::bt4::LANES;
use structure_solver::elements::bt4::{Bt4, Bt4Error, Bt4Settings, SimdPath};
use structure_solver::elements::incidence::chunk_bounds;
use structure_solver::material::{Elastic, J2};

fn steel() -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 1e9 }
}

fn aluminium() -> J2 {
    J2 { elastic: Elastic { e: 70e9, nu: 0.33, rho: 2700.0 }, sigma_y: 120e6, h: 5e8 }
}

/// A warped `nx` x `ny` plate on `[0, 1]²` with its elements in a scrambled order (so blocks
/// gather scattered nodes), and a deformation path: stretch, bending and twisting increments.
struct Plate {
    x0: Vec<[f64; 3]>,
    conn: Vec<[u32; 4]>,
}

impl Plate {
    fn new(nx: usize, ny: usize) -> Plate {
        let mut x0 = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                let (u, v) = (i as f64 / nx as f64, j as f64 / ny as f64);
                let warp = 0.002 * (((i * 7 + j * 13) % 5) as f64 - 2.0) / nx as f64;
                x0.push([u + 0.1 * v * v, v, 0.05 * u * v + warp]);
            }
        }
        let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut conn: Vec<[u32; 4]> = (0..ny)
            .flat_map(|j| {
                (0..nx).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
            })
            .collect();
        // A fixed scramble: element k goes to (k * 37) mod n (37 coprime with n).
        let n = conn.len();
        assert_eq!(gcd(37, n), 1);
        let mut scrambled = conn.clone();
        for (k, c) in conn.drain(..).enumerate() {
            scrambled[(k * 37) % n] = c;
        }
        Plate { x0, conn: scrambled }
    }

    /// Positions and increment of step `s`.
    fn step(&self, s: usize, x: &mut [[f64; 3]], du: &mut [f64]) {
        let t = s as f64;
        for (i, p) in x.iter_mut().enumerate() {
            let q = self.x0[i];
            let d = [
                4e-4 * q[0] + 1e-4 * q[1] * (1.0 + 0.1 * t),
                -1.5e-4 * q[1],
                3e-4 * q[0] * q[0] - 2e-4 * q[1] * q[1] + 1e-4 * q[0] * q[1],
            ];
            for k in 0..3 {
                p[k] += d[k];
                du[6 * i + k] = d[k];
            }
            du[6 * i + 3] = -4e-4 * q[1] + 1e-4 * q[0];
            du[6 * i + 4] = 6e-4 * q[0];
            du[6 * i + 5] = 2e-5 * (q[0] - q[1]);
        }
    }
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// Forces of every step and the final state of `bt4` driven along the plate's path.
fn drive(plate: &Plate, bt4: &mut Bt4, steps: usize, path: SimdPath) -> Vec<Vec<f64>> {
    let mut x = plate.x0.clone();
    let mut du = vec![0.0; 6 * x.len()];
    let mut out = Vec::new();
    for s in 0..steps {
        plate.step(s, &mut x, &mut du);
        let mut f = vec![0.0; du.len()];
        bt4.internal_force_on(path, &x, &du, &mut f).expect("a supported path");
        bt4.commit();
        out.push(f);
    }
    out
}

fn max_plastic(bt4: &Bt4) -> f64 {
    let np = bt4.settings.rule.len();
    (0..bt4.n_elements())
        .flat_map(|e| (0..np).map(move |p| (e, p)))
        .map(|(e, p)| bt4.plastic_strain(e, p))
        .fold(0.0, f64::max)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap()
}

#[test]
fn forces_and_state_are_bitwise_the_same_on_1_and_2_threads() {
    // 31 x 27 = 837 elements: 105 blocks (the last one partial), 13 chunks on 2 threads.
    let plate = Plate::new(31, 27);
    let ne = plate.conn.len();
    assert!(chunk_bounds(ne, LANES, 2).len() > 4 && !ne.is_multiple_of(LANES));
    let run = |threads: usize| {
        let mut bt4 = Bt4::new(plate.conn.clone(), vec![0.01; ne], steel(), Bt4Settings::default());
        let f = pool(threads).install(|| drive(&plate, &mut bt4, 12, SimdPath::detected()));
        (f, bt4)
    };
    let (f1, b1) = run(1);
    let (f2, b2) = run(2);
    let alpha = max_plastic(&b1);
    println!("{} elements, max plastic strain {alpha:.3e}", ne);
    assert!(alpha > 1e-3, "the path must yield: {alpha}");
    assert!(f1.iter().flatten().any(|&v| v != 0.0));
    for (s, (a, b)) in f1.iter().zip(&f2).enumerate() {
        let same = a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "step {s}: forces on 1 and 2 threads differ");
    }
    assert_eq!(b1.state(), b2.state(), "state on 1 and 2 threads");
}

#[test]
fn every_vector_width_gives_the_forces_of_the_scalar_path() {
    let plate = Plate::new(17, 13);
    let ne = plate.conn.len();
    let run = |path: SimdPath| {
        let mut bt4 = Bt4::new(plate.conn.clone(), vec![0.01; ne], steel(), Bt4Settings::default());
        let f = drive(&plate, &mut bt4, 10, path);
        (f, bt4)
    };
    let (f_ref, b_ref) = run(SimdPath::Scalar);
    assert!(max_plastic(&b_ref) > 1e-3);
    let mut checked = Vec::new();
    for path in [SimdPath::Avx512, SimdPath::Avx2Fma] {
        if !path.is_supported() {
            println!("{}: skipped (not on this processor)", path.name());
            continue;
        }
        let (f, b) = run(path);
        for (s, (a, r)) in f.iter().zip(&f_ref).enumerate() {
            let same = a.iter().zip(r).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "{}: step {s} forces differ from the scalar path", path.name());
        }
        assert_eq!(b.state(), b_ref.state(), "{}: state", path.name());
        println!("{}: bitwise equal to the scalar path", path.name());
        checked.push(path.name());
    }
    println!("detected: {}, checked: {checked:?}", SimdPath::detected().name());
}

#[test]
fn two_materials_in_one_part_equal_two_parts_of_one_material() {
    let plate = Plate::new(19, 15);
    let ne = plate.conn.len();
    // Material by position (so both mix within blocks): aluminium where the element's first
    // node has x > 0.45, steel elsewhere.
    let of: Vec<u16> =
        plate.conn.iter().map(|c| u16::from(plate.x0[c[0] as usize][0] > 0.45)).collect();
    let mats = vec![steel(), aluminium()];
    let h: Vec<f64> = (0..ne).map(|e| 0.008 + 0.004 * (e % 3) as f64).collect();
    let settings = Bt4Settings::default();
    let mut both = Bt4::with_materials(
        plate.conn.clone(),
        h.clone(),
        mats.clone(),
        of.clone(),
        settings.clone(),
    )
    .unwrap();
    let part = |m: u16| {
        let idx: Vec<usize> = (0..ne).filter(|&e| of[e] == m).collect();
        let conn = idx.iter().map(|&e| plate.conn[e]).collect();
        let hh = idx.iter().map(|&e| h[e]).collect();
        (idx, Bt4::new(conn, hh, mats[m as usize], settings.clone()))
    };
    let (idx_s, mut steel_part) = part(0);
    let (idx_a, mut al_part) = part(1);
    assert!(idx_s.len() > 50 && idx_a.len() > 50);
    let path = SimdPath::detected();
    let f_both = drive(&plate, &mut both, 12, path);
    let f_s = drive(&plate, &mut steel_part, 12, path);
    let f_a = drive(&plate, &mut al_part, 12, path);
    // Stress and plastic strain per element: bitwise.
    let np = settings.rule.len();
    for (idx, single) in [(&idx_s, &steel_part), (&idx_a, &al_part)] {
        for (k, &e) in idx.iter().enumerate() {
            for p in 0..np {
                assert_eq!(both.stress(e, p), single.stress(k, p), "element {e} point {p}");
                assert_eq!(both.plastic_strain(e, p), single.plastic_strain(k, p));
            }
        }
    }
    // Forces: the sum of the two parts (added in another order): to round-off.
    let mut worst: f64 = 0.0;
    for ((fb, fs), fa) in f_both.iter().zip(&f_s).zip(&f_a) {
        let norm = fb.iter().map(|v| v * v).sum::<f64>().sqrt();
        let diff = fb
            .iter()
            .zip(fs.iter().zip(fa))
            .map(|(b, (s, a))| (b - (s + a)).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(diff / norm);
    }
    let (ps, pa) = (max_plastic(&steel_part), max_plastic(&al_part));
    println!("max plastic strain: steel {ps:.3e}, aluminium {pa:.3e}; forces {worst:.2e}");
    assert!(ps > 1e-4 && pa > 1e-4 && (ps - pa).abs() > 1e-4, "both yield, differently");
    assert!(worst < 1e-13, "two materials in one part vs two parts: {worst:e}");
}

#[test]
fn bad_material_lists_are_refused_with_the_element_named() {
    let plate = Plate::new(3, 2);
    let ne = plate.conn.len();
    let s = Bt4Settings::default;
    let mut of = vec![0u16; ne];
    of[4] = 2;
    let err = Bt4::with_materials(plate.conn.clone(), vec![0.01; ne], vec![steel()], of, s())
        .unwrap_err();
    assert_eq!(err, Bt4Error::MaterialIndex { element: 4, index: 2, n: 1 });
    assert!(err.to_string().contains("element 4"), "{err}");
    let err = Bt4::with_materials(
        plate.conn.clone(),
        vec![0.01; ne - 1],
        vec![steel()],
        vec![0; ne],
        s(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("thickness"), "{err}");
    let err =
        Bt4::with_materials(plate.conn, vec![0.01; ne], vec![], vec![0; ne], s()).unwrap_err();
    assert_eq!(err, Bt4Error::NoMaterial);
}
