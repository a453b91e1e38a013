//! Per-edge flux cost: Roe and HLLC for each EOS, MUSCL + Roe, and the Alg. 5.1 wall flux, over
//! a block of 4096 pre-generated edges (so the numbers include realistic branch variety).
//! `cargo bench -p fluid-solver --bench flux`; criterion reports the time per block (divide by
//! 4096) and the throughput in edges per second.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use fluid_solver::eos::Eos;
use fluid_solver::flux::{numerical_flux, wall_flux, FluxScheme};
use fluid_solver::reconstruct::limiter::Limiter;
use fluid_solver::reconstruct::muscl::reconstruct;
use std::hint::black_box;

const EDGES: usize = 4096;

/// Deterministic pseudo-random numbers in [0, 1) (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Edge {
    wl: [f64; 5],
    wr: [f64; 5],
    n: [f64; 3],
}

fn edges(eos: &Eos) -> Vec<Edge> {
    let mut r = Lcg(12345);
    let state = |r: &mut Lcg| {
        let (rho, p) = match eos {
            Eos::PerfectGas { .. } => (1.2 * (1.0 + 0.2 * r.next()), 1e5 * (1.0 + 0.2 * r.next())),
            Eos::StiffenedGas { .. } => (1000.0 + 5.0 * r.next(), 1e5 + 1e7 * r.next()),
            Eos::Tait { .. } => {
                let rho = 1000.0 + 5.0 * r.next();
                (rho, eos.tait_pressure(rho))
            }
        };
        [rho, 20.0 * r.next() - 10.0, 20.0 * r.next() - 10.0, 20.0 * r.next() - 10.0, p]
    };
    (0..EDGES)
        .map(|_| Edge {
            wl: state(&mut r),
            wr: state(&mut r),
            n: [r.next() - 0.5, r.next() - 0.5, r.next() - 0.5],
        })
        .collect()
}

fn bench_fluxes(c: &mut Criterion) {
    let mut group = c.benchmark_group("flux");
    group.throughput(Throughput::Elements(EDGES as u64));
    let eoses = [
        ("perfect_gas", Eos::PerfectGas { gamma: 1.4 }),
        ("stiffened_gas", Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 }),
        ("tait", Eos::tait(2.07e9, 7.15, 1000.0, 1e5)),
    ];
    for (name, eos) in eoses {
        let block = edges(&eos);
        for scheme in [FluxScheme::Roe, FluxScheme::Hllc] {
            group.bench_function(format!("{scheme:?}/{name}"), |b| {
                b.iter(|| {
                    let mut acc = [0.0; 5];
                    for e in &block {
                        let f = numerical_flux(scheme, black_box(&eos), &e.wl, &e.wr, &e.n);
                        for k in 0..5 {
                            acc[k] += f[k];
                        }
                    }
                    acc
                })
            });
        }
        group.bench_function(format!("muscl_van_albada+Roe/{name}"), |b| {
            let grad = [[1e-3, -2e-3, 5e-4]; 5];
            b.iter(|| {
                let mut acc = [0.0; 5];
                for e in &block {
                    let (wl, wr) = reconstruct(
                        Limiter::VanAlbada,
                        &eos,
                        &e.wl,
                        &grad,
                        &eos,
                        &e.wr,
                        &grad,
                        &e.n,
                    );
                    let f = numerical_flux(FluxScheme::Roe, black_box(&eos), &wl, &wr, &e.n);
                    for k in 0..5 {
                        acc[k] += f[k];
                    }
                }
                acc
            })
        });
        group.bench_function(format!("wall_roe/{name}"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for e in &block {
                    let len = (e.n[0] * e.n[0] + e.n[1] * e.n[1] + e.n[2] * e.n[2]).sqrt();
                    let nh = [e.n[0] / len, e.n[1] / len, e.n[2] / len];
                    let wf = wall_flux(
                        FluxScheme::Roe,
                        black_box(&eos),
                        &e.wl,
                        &e.n,
                        &nh,
                        &[1.0, 2.0, -3.0],
                    );
                    acc += wf.map_or(f64::NAN, |w| w.p);
                }
                acc
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_fluxes);
criterion_main!(benches);
