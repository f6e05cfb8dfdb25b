//! A continuous-time state-space system x' = A x + B w, z = C x + D w.

use faer::Mat;

use crate::lti::error::LtiError;
use crate::numeric::all_finite;

/// Real state-space realisation (A, B, C, D): A n×n, B n×m, C p×n, D p×m.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// State matrix (n × n).
    pub a: Mat<f64>,
    /// Input matrix (n × m).
    pub b: Mat<f64>,
    /// Output matrix (p × n).
    pub c: Mat<f64>,
    /// Feedthrough (p × m).
    pub d: Mat<f64>,
}

impl StateSpace {
    /// Builds a system after checking that the four shapes fit together (shapes follow D and A).
    pub fn new(a: Mat<f64>, b: Mat<f64>, c: Mat<f64>, d: Mat<f64>) -> Result<Self, LtiError> {
        let (n, p, m) = (a.nrows(), d.nrows(), d.ncols());
        let check = |what, m: &Mat<f64>, expected: (usize, usize)| {
            let got = (m.nrows(), m.ncols());
            if got == expected {
                Ok(())
            } else {
                Err(LtiError::Shape { what, expected, got })
            }
        };
        check("A", &a, (n, n))?;
        check("B", &b, (n, m))?;
        check("C", &c, (p, n))?;
        Ok(StateSpace { a, b, c, d })
    }

    /// Number of states n.
    pub fn order(&self) -> usize {
        self.a.nrows()
    }

    /// Number of inputs m.
    pub fn inputs(&self) -> usize {
        self.d.ncols()
    }

    /// Number of outputs p.
    pub fn outputs(&self) -> usize {
        self.d.nrows()
    }

    /// Whether every entry of A, B, C, D is finite.
    pub fn is_finite(&self) -> bool {
        [&self.a, &self.b, &self.c, &self.d].iter().all(|m| all_finite(m.as_ref()))
    }
}
