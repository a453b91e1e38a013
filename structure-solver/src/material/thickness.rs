//! Through-thickness quadrature of shells: points `ζ ∈ [-1, 1]` (`z = ζ h/2`) and weights
//! summing to 2, Gauss-Legendre or Gauss-Lobatto (which samples the surfaces, where yield
//! starts).

/// Points and weights of a through-thickness rule.
#[derive(Debug, Clone, PartialEq)]
pub struct ThicknessRule {
    pub points: Vec<f64>,
    pub weights: Vec<f64>,
}

/// Legendre polynomial `P_n(x)` and its derivative.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let dp = if (x * x - 1.0).abs() < 1e-300 {
        0.5 * (n * (n + 1)) as f64 * x.powi(n as i32 + 1)
    } else {
        n as f64 * (x * p1 - p0) / (x * x - 1.0)
    };
    (p1, dp)
}

impl ThicknessRule {
    /// `n`-point Gauss-Legendre rule (exact for degree `2n - 1`), `n >= 1`.
    pub fn gauss(n: usize) -> ThicknessRule {
        assert!(n >= 1, "a Gauss rule needs at least one point");
        let mut points = vec![0.0; n];
        let mut weights = vec![0.0; n];
        for i in 0..n {
            // Newton from the Chebyshev-like guess.
            let mut x = -(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(n, x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, dp) = legendre(n, x);
            points[i] = x;
            weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
        }
        ThicknessRule { points, weights }
    }

    /// `n`-point Gauss-Lobatto rule with both surfaces (exact for degree `2n - 3`), `n >= 2`.
    pub fn lobatto(n: usize) -> ThicknessRule {
        assert!(n >= 2, "a Lobatto rule needs at least two points");
        let m = n - 1;
        let mut points = vec![-1.0; n];
        points[m] = 1.0;
        // Interior points: roots of P'_{n-1}, via Newton on P'_m with P''_m from Legendre's ODE.
        for (i, p) in points.iter_mut().enumerate().take(m).skip(1) {
            let mut x = -(std::f64::consts::PI * i as f64 / m as f64).cos();
            for _ in 0..100 {
                let (pm, dpm) = legendre(m, x);
                let ddpm = (2.0 * x * dpm - (m * (m + 1)) as f64 * pm) / (1.0 - x * x);
                let dx = dpm / ddpm;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            *p = x;
        }
        let weights = points
            .iter()
            .map(|&x| {
                let (pm, _) = legendre(m, x);
                2.0 / ((m * (m + 1)) as f64 * pm * pm)
            })
            .collect();
        ThicknessRule { points, weights }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// `true` for a rule without points (never built by the constructors).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// `Σ w_i |ζ_i|`: the fully plastic moment of this rule relative to `σy b h²/4`.
    pub fn plastic_moment_factor(&self) -> f64 {
        self.points.iter().zip(&self.weights).map(|(z, w)| w * z.abs()).sum()
    }
}
