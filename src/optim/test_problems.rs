//! Standard test problems with known minimisers, for the tests and the benchmark
//! (`benches/optim.rs`). Each is an [`Objective`] with `fmin()` and `xmin()`.

use super::objective::Objective;
use faer::{Mat, Side};
use rand::{Rng, RngCore};

fn sgn(r: f64) -> f64 {
    if r >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Nesterov's first nonsmooth Chebyshev–Rosenbrock function (Gurbuzbalaban & Overton 2012,
/// "On Nesterov's nonsmooth Chebyshev–Rosenbrock functions"):
/// f(x) = ¼(x₁ − 1)² + Σᵢ₌₁ⁿ⁻¹ |x_{i+1} − 2xᵢ² + 1|, min 0 at (1, …, 1) (its only Clarke
/// stationary point), hard for BFGS as n grows (the iterates must follow a curved manifold).
#[derive(Debug, Clone)]
pub struct ChebyshevRosenbrock {
    /// Dimension.
    pub n: usize,
}

impl Objective for ChebyshevRosenbrock {
    fn nvar(&self) -> usize {
        self.n
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut f = 0.25 * (x[0] - 1.0).powi(2);
        g[0] = 0.5 * (x[0] - 1.0);
        for i in 0..self.n - 1 {
            let r = x[i + 1] - 2.0 * x[i] * x[i] + 1.0;
            let s = sgn(r);
            f += r.abs();
            g[i + 1] += s;
            g[i] -= 4.0 * x[i] * s;
        }
        f
    }
}

/// The smooth Rosenbrock function 100(x₂ − x₁²)² + (1 − x₁)² (chained for n > 2),
/// min 0 at (1, …, 1).
#[derive(Debug, Clone)]
pub struct Rosenbrock {
    /// Dimension (≥ 2).
    pub n: usize,
}

impl Objective for Rosenbrock {
    fn nvar(&self) -> usize {
        self.n
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut f = 0.0;
        for i in 0..self.n - 1 {
            let a = x[i + 1] - x[i] * x[i];
            let b = 1.0 - x[i];
            f += 100.0 * a * a + b * b;
            g[i] += -400.0 * x[i] * a - 2.0 * b;
            g[i + 1] += 200.0 * a;
        }
        f
    }
}

/// Max of quadratics fₖ(x) = cₖᵀx + ½xᵀAₖx, k = 1…K, with Aₖ ≻ 0 and Σₖ cₖ = 0 (so 0 is in the
/// interior of conv{cₖ} when K > n): f ≥ mean fₖ ≥ 0 with equality only at 0 — min 0 at 0,
/// nonsmooth there.
#[derive(Debug, Clone)]
pub struct MaxQuad {
    n: usize,
    c: Vec<Vec<f64>>,
    a: Vec<Vec<f64>>,
}

impl MaxQuad {
    /// K = n + 2 random pieces.
    pub fn random(n: usize, rng: &mut dyn RngCore) -> Self {
        let k = n + 2;
        let mut c: Vec<Vec<f64>> = (0..k).map(|_| (0..n).map(|_| rng.random::<f64>() * 2.0 - 1.0).collect()).collect();
        let mean: Vec<f64> = (0..n).map(|j| c.iter().map(|ci| ci[j]).sum::<f64>() / k as f64).collect();
        c.iter_mut().for_each(|ci| ci.iter_mut().zip(&mean).for_each(|(v, m)| *v -= m));
        let a = (0..k)
            .map(|_| {
                // A = BᵀB/n + 0.1 I.
                let b: Vec<f64> = (0..n * n).map(|_| rng.random::<f64>() - 0.5).collect();
                let mut a = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..n {
                        a[i * n + j] = (0..n).map(|l| b[l * n + i] * b[l * n + j]).sum::<f64>() / n as f64
                            + if i == j { 0.1 } else { 0.0 };
                    }
                }
                a
            })
            .collect();
        MaxQuad { n, c, a }
    }
}

impl Objective for MaxQuad {
    fn nvar(&self) -> usize {
        self.n
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let n = self.n;
        let mut best = f64::NEG_INFINITY;
        for (c, a) in self.c.iter().zip(&self.a) {
            let ax: Vec<f64> = (0..n).map(|i| (0..n).map(|j| a[i * n + j] * x[j]).sum()).collect();
            let v: f64 = (0..n).map(|i| c[i] * x[i] + 0.5 * x[i] * ax[i]).sum();
            if v > best {
                best = v;
                for i in 0..n {
                    g[i] = c[i] + ax[i];
                }
            }
        }
        best
    }
}

/// f(x) = ‖M x‖₁ with M = I + (a random matrix)/2, min 0 at 0 (a polyhedral kink in every
/// direction).
#[derive(Debug, Clone)]
pub struct L1Norm {
    n: usize,
    m: Vec<f64>,
}

impl L1Norm {
    /// Random M = I + (U[−½, ½])/2.
    pub fn random(n: usize, rng: &mut dyn RngCore) -> Self {
        let m =
            (0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 } + 0.5 * (rng.random::<f64>() - 0.5)).collect();
        L1Norm { n, m }
    }
}

impl Objective for L1Norm {
    fn nvar(&self) -> usize {
        self.n
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let n = self.n;
        g.iter_mut().for_each(|v| *v = 0.0);
        let mut f = 0.0;
        for i in 0..n {
            let r: f64 = (0..n).map(|j| self.m[i * n + j] * x[j]).sum();
            f += r.abs();
            let s = sgn(r);
            for (gj, &mij) in g.iter_mut().zip(&self.m[i * n..(i + 1) * n]) {
                *gj += s * mij;
            }
        }
        f
    }
}

/// λ_max(A₀ + Σᵢ xᵢAᵢ) for symmetric m×m matrices, built with a known minimiser: A₀ = diag with
/// λ_max = 1 of multiplicity r, and each Aᵢ random symmetric with tr(UᵀAᵢU) = 0 for the top
/// eigenspace U of A₀. Then 0 is in the interior of the subdifferential {(tr(UᵀAᵢU W))ᵢ : W ⪰ 0,
/// tr W = 1} when n ≤ r(r+1)/2 − 1 (generically), so x* = 0, f* = 1, nonsmooth (multiplicity r).
/// The function is convex. Gradient: ∂f/∂xᵢ = uᵀAᵢu, u the top unit eigenvector (faer).
#[derive(Debug, Clone)]
pub struct MaxEigenvalue {
    m: usize,
    a0: Vec<f64>,
    a: Vec<Vec<f64>>,
}

impl MaxEigenvalue {
    /// m = 6, multiplicity r = 3, n ≤ 5 variables.
    pub fn random(n: usize, rng: &mut dyn RngCore) -> Self {
        let m = 6;
        let r = 3;
        let diag = [1.0, 1.0, 1.0, 0.3, -0.4, -1.0];
        let mut a0 = vec![0.0; m * m];
        for i in 0..m {
            a0[i * m + i] = diag[i];
        }
        let a = (0..n)
            .map(|_| {
                let mut ai = vec![0.0; m * m];
                for i in 0..m {
                    for j in 0..=i {
                        let v = rng.random::<f64>() * 2.0 - 1.0;
                        ai[i * m + j] = v;
                        ai[j * m + i] = v;
                    }
                }
                let tr: f64 = (0..r).map(|i| ai[i * m + i]).sum();
                for i in 0..r {
                    ai[i * m + i] -= tr / r as f64;
                }
                ai
            })
            .collect();
        MaxEigenvalue { m, a0, a }
    }
}

impl Objective for MaxEigenvalue {
    fn nvar(&self) -> usize {
        self.a.len()
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let m = self.m;
        let mat = Mat::from_fn(m, m, |i, j| {
            self.a0[i * m + j] + self.a.iter().zip(x).map(|(ai, xi)| xi * ai[i * m + j]).sum::<f64>()
        });
        let Ok(eig) = mat.self_adjoint_eigen(Side::Lower) else {
            g.iter_mut().for_each(|v| *v = f64::NAN);
            return f64::NAN;
        };
        let lam = eig.S().column_vector()[m - 1];
        let u: Vec<f64> = (0..m).map(|i| eig.U()[(i, m - 1)]).collect();
        for (gi, ai) in g.iter_mut().zip(&self.a) {
            *gi = (0..m).map(|i| u[i] * (0..m).map(|j| ai[i * m + j] * u[j]).sum::<f64>()).sum();
        }
        lam
    }
}

/// A function that is +∞ outside the box |xᵢ| ≤ 1:
/// f(x) = Σᵢ dᵢ (xᵢ − cᵢ)² + |x₁ − c₁| inside, min 0 at c (inside the box). Steep scales dᵢ make
/// the unit first BFGS step leave the box, so the line search must back off.
/// Counts the evaluations that returned +∞.
#[derive(Debug, Clone)]
pub struct Walled {
    /// The minimiser.
    pub c: Vec<f64>,
    d: Vec<f64>,
    /// Number of evaluations outside the domain.
    pub infinite_evals: usize,
}

impl Walled {
    /// In n variables, c = (0.5, −0.5, 0.5, …), dᵢ = 10^(i mod 3).
    pub fn new(n: usize) -> Self {
        Walled {
            c: (0..n).map(|i| if i % 2 == 0 { 0.5 } else { -0.5 }).collect(),
            d: (0..n).map(|i| 10f64.powi((i % 3) as i32)).collect(),
            infinite_evals: 0,
        }
    }
}

impl Objective for Walled {
    fn nvar(&self) -> usize {
        self.c.len()
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        if x.iter().any(|v| !(v.abs() <= 1.0)) {
            self.infinite_evals += 1;
            g.iter_mut().for_each(|v| *v = f64::NAN);
            return f64::INFINITY;
        }
        let mut f = (x[0] - self.c[0]).abs();
        for i in 0..x.len() {
            let r = x[i] - self.c[i];
            f += self.d[i] * r * r;
            g[i] = 2.0 * self.d[i] * r;
        }
        g[0] += sgn(x[0] - self.c[0]);
        f
    }
}
