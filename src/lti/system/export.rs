//! A controller as ready-to-paste MATLAB or python-control code.
//!
//! Sign convention (docs/ALGORITHMS.md §1–2): the controller is **positive feedback**, u = K y:
//!
//! ```text
//! xk' = AK xk + BK y,   u = CK xk + DK y
//! ```
//!
//! and the closed loop is the lower LFT F_l(P, K) = P11 + P12 K (I − P22 K)⁻¹ P21, which is what
//! MATLAB's `lft(P, K)` and python-control's `P.lft(K)` compute. `feedback(G, K)` assumes
//! *negative* feedback in both; keep u = K y with `feedback(G, K, +1)` (MATLAB) or
//! `control.feedback(G, K, sign=1)` (python), or pass `-K`.
//!
//! A discrete-time controller (xk⁺ = AK xk + BK y) is built with its sampling time: MATLAB's
//! `ss(AK, BK, CK, DK, Ts)`, python-control's `control.ss(AK, BK, CK, DK, dt=Ts)`; the plant must
//! then be discrete with the same Ts for `lft` to accept the pair.
//!
//! Numbers are printed with Rust's shortest round-trip representation, so the pasted matrices
//! are bit-for-bit the controller's.

use faer::MatRef;

use super::controller::Controller;

/// Target language of [`export_code`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportTarget {
    /// MATLAB (Control System Toolbox `ss`).
    Matlab,
    /// Python with numpy and python-control.
    Python,
}

/// Shortest representation that reads back to the same f64 in `target`. MATLAB reads every
/// literal as a double, so "2" and "-0" will do; Python reads "-0" as the integer 0, which numpy
/// turns into +0.0 (a fixed −0.0 came back as +0.0), so a Python number keeps its ".0".
fn number(x: f64, target: ExportTarget) -> String {
    let s = format!("{x:?}");
    match target {
        ExportTarget::Matlab => s.strip_suffix(".0").map_or(s.clone(), str::to_string),
        ExportTarget::Python => s,
    }
}

fn matlab_matrix(m: MatRef<'_, f64>) -> String {
    if m.nrows() == 0 || m.ncols() == 0 {
        return format!("zeros({}, {})", m.nrows(), m.ncols());
    }
    let rows: Vec<String> = (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| number(m[(i, j)], ExportTarget::Matlab)).collect::<Vec<_>>().join(", "))
        .collect();
    format!("[{}]", rows.join(";\n      "))
}

fn python_matrix(m: MatRef<'_, f64>) -> String {
    if m.nrows() == 0 || m.ncols() == 0 {
        return format!("np.zeros(({}, {}))", m.nrows(), m.ncols());
    }
    let rows: Vec<String> = (0..m.nrows())
        .map(|i| {
            format!(
                "[{}]",
                (0..m.ncols()).map(|j| number(m[(i, j)], ExportTarget::Python)).collect::<Vec<_>>().join(", ")
            )
        })
        .collect();
    format!("np.array([{}])", rows.join(",\n               "))
}

/// The code that builds `k` as a state-space object in `target`, with the sign convention in
/// comments. `source` names where the controller came from (printed in the first comment).
pub fn export_code(k: &Controller, target: ExportTarget, source: &str) -> String {
    let (nk, m, p) = (k.order(), k.outputs(), k.inputs());
    let mats = [("AK", k.ak.as_ref()), ("BK", k.bk.as_ref()), ("CK", k.ck.as_ref()), ("DK", k.dk.as_ref())];
    let update = if k.domain.is_discrete() { "xk[t+1] = AK xk[t] + BK y[t]" } else { "xk' = AK xk + BK y" };
    let ts = k.domain.ts().map(|ts| number(ts, target));
    let (comment, end) = match target {
        ExportTarget::Matlab => ("%", ";"),
        ExportTarget::Python => ("#", ""),
    };
    let mut s = format!(
        "{comment} hinfix controller from {source}: order {nk}, {m} control input(s) u, {p} measurement(s) y.\n"
    );
    s += &format!("{comment} Sign convention: POSITIVE feedback u = K y ({update}, u = CK xk + DK y).\n");
    s += match target {
        ExportTarget::Matlab => concat!(
            "% Closed loop with the plant P = ss(A, [B1 B2], [C1; C2], [D11 D12; D21 D22]):\n",
            "%   Tzw = lft(P, K);                 % lft keeps u = K y\n",
            "%   L = feedback(P22, K, +1);        % feedback() is negative by default: use +1 (or -K)\n",
        ),
        ExportTarget::Python => concat!(
            "# Closed loop with P = control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]), np.block([[D11, D12], [D21, D22]])):\n",
            "#   Tzw = P.lft(K)                          # lower LFT, keeps u = K y\n",
            "#   L = control.feedback(P22, K, sign=1)    # feedback() is negative by default: use sign=1 (or -K)\n",
            "import numpy as np\nimport control\n\n",
        ),
    };
    for (name, mat) in mats {
        let text = match target {
            ExportTarget::Matlab => matlab_matrix(mat),
            ExportTarget::Python => python_matrix(mat),
        };
        s += &format!("{name} = {text}{end}\n");
    }
    s += &match (target, &ts) {
        (ExportTarget::Matlab, None) => "K = ss(AK, BK, CK, DK);\n".to_string(),
        (ExportTarget::Matlab, Some(ts)) => {
            format!("Ts = {ts};  % sampling time (s): a discrete-time controller\nK = ss(AK, BK, CK, DK, Ts);\n")
        }
        (ExportTarget::Python, None) => "K = control.ss(AK, BK, CK, DK)\n".to_string(),
        (ExportTarget::Python, Some(ts)) => {
            format!(
                "Ts = {ts}  # sampling time (s): a discrete-time controller\nK = control.ss(AK, BK, CK, DK, dt=Ts)\n"
            )
        }
    };
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    #[test]
    fn numbers_round_trip_and_empty_blocks_have_shapes() {
        for x in [0.1, -1.0 / 3.0, 1e-300, 123456789.0, -0.0, 2.0] {
            for t in [ExportTarget::Matlab, ExportTarget::Python] {
                assert_eq!(number(x, t).parse::<f64>().unwrap().to_bits(), x.to_bits(), "{x}");
            }
            // Python reads a literal without '.', 'e' or "inf" as an integer: −0 would become +0.0
            let py = number(x, ExportTarget::Python);
            assert!(py.contains('.') || py.contains('e'), "{py}");
        }
        let k = Controller::continuous(
            Mat::zeros(0, 0),
            Mat::zeros(0, 2),
            Mat::zeros(1, 0),
            Mat::from_fn(1, 2, |_, j| j as f64 + 0.5),
        );
        let m = export_code(&k, ExportTarget::Matlab, "k.json");
        assert!(
            m.contains("BK = zeros(0, 2);") && m.contains("CK = zeros(1, 0);") && m.contains("DK = [0.5, 1.5];"),
            "{m}"
        );
        assert!(m.contains("K = ss(AK, BK, CK, DK);") && m.contains("u = K y"));
        let p = export_code(&k, ExportTarget::Python, "k.json");
        assert!(p.contains("BK = np.zeros((0, 2))") && p.contains("DK = np.array([[0.5, 1.5]])"), "{p}");
        let neg_zero =
            Controller::continuous(Mat::zeros(0, 0), Mat::zeros(0, 1), Mat::zeros(1, 0), Mat::full(1, 1, -0.0));
        assert!(export_code(&neg_zero, ExportTarget::Python, "k.json").contains("DK = np.array([[-0.0]])"));
        assert!(p.contains("K = control.ss(AK, BK, CK, DK)") && p.contains("sign=1"));
        assert!(!m.contains("Ts") && !p.contains("dt="));
    }

    /// A discrete-time controller carries its sampling time into both languages.
    #[test]
    fn a_discrete_controller_is_built_with_its_sampling_time() {
        let k = Controller::zeros(1, 1, 1).in_domain(crate::lti::TimeDomain::Discrete { ts: 0.01 });
        let m = export_code(&k, ExportTarget::Matlab, "k.json");
        assert!(m.contains("Ts = 0.01;") && m.contains("K = ss(AK, BK, CK, DK, Ts);") && m.contains("xk[t+1]"), "{m}");
        let p = export_code(&k, ExportTarget::Python, "k.json");
        assert!(p.contains("Ts = 0.01") && p.contains("K = control.ss(AK, BK, CK, DK, dt=Ts)"), "{p}");
    }
}
