//! Build script: records the git commit the binary is built from (for the provenance of every
//! journal record, `campaign::provenance`). Outside a git checkout (a source tarball, a crate
//! download) `git` fails and the commit is simply unknown; the build never fails because of it.
//! `HINFIX_GIT_COMMIT` set at build time overrides (for packagers building from an export).
//! A build whose sources (src/, build.rs, Cargo.toml, Cargo.lock) differ from HEAD records
//! `<commit>+dirty`: its records then say that they do not come from that commit's code.
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    let s = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (out.status.success() && !s.is_empty()).then_some(s)
}

fn main() {
    println!("cargo:rerun-if-env-changed=HINFIX_GIT_COMMIT");
    // Only a checkout of this crate itself counts (not an enclosing repository it is vendored in).
    let manifest = std::env::var("CARGO_MANIFEST_DIR").ok().and_then(|d| std::fs::canonicalize(d).ok());
    let toplevel = git(&["rev-parse", "--show-toplevel"]).and_then(|d| std::fs::canonicalize(d).ok());
    let commit = match std::env::var("HINFIX_GIT_COMMIT") {
        Ok(c) if !c.trim().is_empty() => Some(c.trim().to_string()),
        _ if manifest.is_some() && manifest == toplevel => git(&["rev-parse", "HEAD"]).map(|c| {
            // Sources that differ from HEAD: the commit alone would misname the binary.
            let dirty = git(&[
                "status",
                "--porcelain",
                "--untracked-files=no",
                "--",
                "src",
                "build.rs",
                "Cargo.toml",
                "Cargo.lock",
            ]);
            if dirty.is_some() {
                format!("{c}+dirty")
            } else {
                c
            }
        }),
        _ => None,
    };
    if commit.is_some() {
        // Rebuild when HEAD moves: HEAD itself, the branch it points to, and packed refs.
        let mut watch = vec![git(&["rev-parse", "--git-path", "HEAD"])];
        if let Some(r) = git(&["symbolic-ref", "-q", "HEAD"]) {
            watch.push(git(&["rev-parse", "--git-path", &r]));
        }
        watch.push(git(&["rev-parse", "--git-path", "packed-refs"]));
        for p in watch.into_iter().flatten() {
            if std::path::Path::new(&p).exists() {
                println!("cargo:rerun-if-changed={p}");
            }
        }
        // and when the sources change, for the `+dirty` mark
        for p in ["src", "build.rs", "Cargo.toml", "Cargo.lock"] {
            println!("cargo:rerun-if-changed={p}");
        }
    } else {
        println!("cargo:rerun-if-changed=build.rs");
    }
    println!("cargo:rustc-env=HINFIX_GIT_COMMIT={}", commit.unwrap_or_default());
}
