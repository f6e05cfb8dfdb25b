//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::Command;

/// The LaTeX tables compile with a real `pdflatex` (CI installs it from Debian's packages). Where
/// none can be installed, `HINFIX_NO_PDFLATEX=1` downgrades this to a structural check.
pub fn latex_compiles(dir: &Path) {
    let have = Command::new("pdflatex").arg("--version").output().is_ok_and(|o| o.status.success());
    if !have {
        assert_eq!(
            std::env::var("HINFIX_NO_PDFLATEX").as_deref(),
            Ok("1"),
            "pdflatex is not on PATH: install it (texlive-latex-base, texlive-latex-recommended) or set HINFIX_NO_PDFLATEX=1"
        );
        for f in ["tables.tex", "compare.tex"] {
            let tex = std::fs::read_to_string(dir.join(f)).unwrap();
            assert_eq!(tex.matches("\\begin{").count(), tex.matches("\\end{").count(), "{f}: unbalanced environments");
            assert!(tex.contains("\\toprule") && tex.contains("\\bottomrule"), "{f}: not booktabs");
        }
        return;
    }
    std::fs::write(
        dir.join("wrap.tex"),
        "\\documentclass{article}\n\\usepackage{booktabs}\n\\begin{document}\n\\input{tables.tex}\n\\input{compare.tex}\n\\end{document}\n",
    )
    .unwrap();
    let out = Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error", "wrap.tex"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "pdflatex failed:\n{}", String::from_utf8_lossy(&out.stdout));
    assert!(dir.join("wrap.pdf").is_file());
}
