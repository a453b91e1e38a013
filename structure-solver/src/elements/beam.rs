//! 2-node Euler-Bernoulli beam, local and small strain; large rotations come from the
//! corotated frame (`corotation::FrameRule::Beam`, Crisfield 1990 / Battini & Pacoste 2002).
//! Local dofs per node `[u, v, w, θx, θy, θz]`, `x` along the beam. Elastic (`stiffness`) or
//! J2 by fibres over the section (`FibreBeam`).

use nalgebra::DMatrix;

use super::section::{BeamSection, BeamYield, FibreState};
use crate::material::ThicknessRule;

/// Local 12x12 stiffness of a beam of length `l`.
pub fn stiffness(l: f64, s: &BeamSection) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(12, 12);
    let g = s.e / (2.0 * (1.0 + s.nu));
    let mut put = |dofs: [usize; 2], v: f64| {
        k[(dofs[0], dofs[0])] += v;
        k[(dofs[1], dofs[1])] += v;
        k[(dofs[0], dofs[1])] -= v;
        k[(dofs[1], dofs[0])] -= v;
    };
    put([0, 6], s.e * s.area / l);
    put([3, 9], g * s.j / l);
    // bending in x-y (v, θz) and x-z (w, θy; θy = -dw/dx)
    for (v, th, i, sign) in [(1usize, 5usize, s.iz, 1.0), (2, 4, s.iy, -1.0)] {
        let c = s.e * i / l.powi(3);
        let dofs = [v, th, v + 6, th + 6];
        let m = [
            [12.0, 6.0 * l * sign, -12.0, 6.0 * l * sign],
            [6.0 * l * sign, 4.0 * l * l, -6.0 * l * sign, 2.0 * l * l],
            [-12.0, -6.0 * l * sign, 12.0, -6.0 * l * sign],
            [6.0 * l * sign, 2.0 * l * l, -6.0 * l * sign, 4.0 * l * l],
        ];
        for a in 0..4 {
            for b in 0..4 {
                k[(dofs[a], dofs[b])] += c * m[a][b];
            }
        }
    }
    k
}

/// Stations along the beam: 3-point Gauss-Lobatto in `s = x/l` (exact for the cubic
/// elastic integrand; the end sections, where hinges form, are sampled).
const STATIONS: [(f64, f64); 3] = [(0.0, 1.0 / 6.0), (0.5, 4.0 / 6.0), (1.0, 1.0 / 6.0)];

/// Rows of the generalised strains `[ε0, κy, κz]` over the 12 local dofs at station `s`
/// (`ε0 = u'`, `κy = θy' = -w''`, `κz = θz' = v''`; cubic Hermite `v`, `w`, `θy = -w'`,
/// `θz = v'`). A fibre at `(y, z)` strains by `ε = ε0 + z κy - y κz`.
fn strain_rows(l: f64, s: f64) -> [[f64; 12]; 3] {
    let mut r = [[0.0; 12]; 3];
    r[0][0] = -1.0 / l;
    r[0][6] = 1.0 / l;
    let (a, b, c, d) = (
        (-6.0 + 12.0 * s) / (l * l),
        (-4.0 + 6.0 * s) / l,
        (6.0 - 12.0 * s) / (l * l),
        (-2.0 + 6.0 * s) / l,
    );
    // κz = v'' (slopes θz)
    r[2][1] = a;
    r[2][5] = b;
    r[2][7] = c;
    r[2][11] = d;
    // κy = -w'' with slopes w' = -θy
    r[1][2] = -a;
    r[1][4] = b;
    r[1][8] = -c;
    r[1][10] = d;
    r
}

/// A 2-node beam of a J2 material by fibres (displacement-based, Euler-Bernoulli): at each
/// station the fibres of the section's equivalent rectangle (`b = √(12 I_z/A)` along `y`,
/// `h = √(12 I_y/A)` along `z`; exact for rectangles) on a `points` x `points` Gauss-Legendre
/// grid strain by `ε = ε0 + z κy - y κz`, return by `BeamYield::fibre`, and give the
/// resultants `N = ∫σ dA`, `M_y = ∫σ z dA`, `M_z = -∫σ y dA`; the local force is
/// `f = Σ_s l w_s Bᵀ (N, M_y, M_z) + K_t d` (torsion `G J / l` stays elastic). Elastic
/// fibres give exactly `stiffness(l, sec) d`.
///
/// State: `[εp, α]` per fibre, station major, then `y`, then `z`.
#[derive(Debug, Clone)]
pub struct FibreBeam {
    pub l: f64,
    pub sec: BeamSection,
    pub yield_: BeamYield,
    rule: ThicknessRule,
}

/// State values per fibre.
pub const FIBRE_STATE: usize = 2;

impl FibreBeam {
    pub fn new(l: f64, sec: BeamSection, yield_: BeamYield) -> Self {
        FibreBeam { l, sec, yield_, rule: ThicknessRule::gauss(yield_.points.max(1)) }
    }

    /// Length of the state array.
    pub fn n_state(&self) -> usize {
        STATIONS.len() * self.rule.len() * self.rule.len() * FIBRE_STATE
    }

    /// Half-width along `y` and half-depth along `z` of the equivalent rectangle.
    fn half_sizes(&self) -> (f64, f64) {
        let a = self.sec.area;
        ((3.0 * self.sec.iz / a).sqrt(), (3.0 * self.sec.iy / a).sqrt())
    }

    /// Calls `visit(station, fibre index, y, z, weight·area)` for every fibre.
    fn fibres(&self, mut visit: impl FnMut(usize, usize, f64, f64, f64)) {
        let (cy, cz) = self.half_sizes();
        let n = self.rule.len();
        for st in 0..STATIONS.len() {
            for (iy, (&py, &wy)) in self.rule.points.iter().zip(&self.rule.weights).enumerate() {
                for (iz, (&pz, &wz)) in self.rule.points.iter().zip(&self.rule.weights).enumerate()
                {
                    let idx = (st * n + iy) * n + iz;
                    visit(st, idx, py * cy, pz * cz, wy * wz * cy * cz);
                }
            }
        }
    }

    /// Local force `fl` at local deformational displacements `d` from the committed state
    /// `old`; writes the trial state into `new`, and with `kl` the consistent local tangent
    /// `Σ_s l w_s Bᵀ D_s B + K_t`, `D_s = Σ_fibres E_t [1, z, -y]ᵀ [1, z, -y] dA`.
    pub fn force(
        &self,
        d: &[f64],
        old: &[f64],
        new: &mut [f64],
        fl: &mut [f64],
        mut kl: Option<&mut DMatrix<f64>>,
    ) {
        let l = self.l;
        let rows: Vec<[[f64; 12]; 3]> = STATIONS.iter().map(|&(s, _)| strain_rows(l, s)).collect();
        let gen: Vec<[f64; 3]> =
            rows.iter().map(|r| r.map(|row| row.iter().zip(d).map(|(a, b)| a * b).sum())).collect();
        let mut res = [[0.0; 3]; STATIONS.len()];
        let mut dsec = [[[0.0; 3]; 3]; STATIONS.len()];
        let e = self.sec.e;
        self.fibres(|st, idx, y, z, da| {
            let g = gen[st];
            let eps = g[0] + z * g[1] - y * g[2];
            let i = idx * FIBRE_STATE;
            let s0 = FibreState { eps_p: old[i], alpha: old[i + 1] };
            let (sigma, s1, et) = self.yield_.fibre(e, eps, &s0);
            new[i] = s1.eps_p;
            new[i + 1] = s1.alpha;
            let a = [1.0, z, -y];
            for p in 0..3 {
                res[st][p] += sigma * a[p] * da;
                for q in 0..3 {
                    dsec[st][p][q] += et * a[p] * a[q] * da;
                }
            }
        });
        // torsion
        let kt = self.sec.e / (2.0 * (1.0 + self.sec.nu)) * self.sec.j / l;
        fl.fill(0.0);
        fl[3] = kt * (d[3] - d[9]);
        fl[9] = -fl[3];
        if let Some(k) = kl.as_deref_mut() {
            k.fill(0.0);
            k[(3, 3)] = kt;
            k[(9, 9)] = kt;
            k[(3, 9)] = -kt;
            k[(9, 3)] = -kt;
        }
        for (st, &(_, w)) in STATIONS.iter().enumerate() {
            let lw = l * w;
            for p in 0..3 {
                for (o, b) in fl.iter_mut().zip(&rows[st][p]) {
                    *o += lw * b * res[st][p];
                }
            }
            if let Some(k) = kl.as_deref_mut() {
                for p in 0..3 {
                    for q in 0..3 {
                        let c = lw * dsec[st][p][q];
                        if c == 0.0 {
                            continue;
                        }
                        for a in 0..12 {
                            let ra = rows[st][p][a];
                            if ra == 0.0 {
                                continue;
                            }
                            for b in 0..12 {
                                k[(a, b)] += c * ra * rows[st][q][b];
                            }
                        }
                    }
                }
            }
        }
    }

    /// Largest fibre von Mises (here `|σ|`) stress at local displacements `d` with the
    /// committed `state`.
    pub fn von_mises(&self, d: &[f64], state: &[f64]) -> f64 {
        let gen: Vec<[f64; 3]> = STATIONS
            .iter()
            .map(|&(s, _)| {
                strain_rows(self.l, s).map(|row| row.iter().zip(d).map(|(a, b)| a * b).sum())
            })
            .collect();
        let mut vm = 0.0f64;
        self.fibres(|st, idx, y, z, _| {
            let g = gen[st];
            let i = idx * FIBRE_STATE;
            let s0 = FibreState { eps_p: state[i], alpha: state[i + 1] };
            let (sigma, _, _) = self.yield_.fibre(self.sec.e, g[0] + z * g[1] - y * g[2], &s0);
            vm = vm.max(sigma.abs());
        });
        vm
    }
}
