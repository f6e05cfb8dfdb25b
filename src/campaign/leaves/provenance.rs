//! Where and with what a job ran: every journal record carries a [`Provenance`] so that results
//! gathered on several machines (Slurm array tasks, `--journal` merges) can be told apart.
//!
//! * `hinfix_version`: the crate version;
//! * `git_commit`: `HEAD` when the binary was built from a git checkout (recorded by `build.rs`;
//!   `<commit>+dirty` when its sources differed from `HEAD`; absent when built outside git);
//! * `host`: the host name (`gethostname`);
//! * `threads`: worker threads of the run;
//! * `cpu_model`: the first `model name` of `/proc/cpuinfo` (else the architecture).

use serde::{Deserialize, Serialize};

/// The provenance of one journal record.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Provenance {
    /// hinfix version (`CARGO_PKG_VERSION`).
    pub hinfix_version: String,
    /// Git commit the binary was built from, if built from a checkout.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_commit: Option<String>,
    /// Host name.
    pub host: String,
    /// Worker threads of the run.
    pub threads: usize,
    /// CPU model.
    pub cpu_model: String,
}

impl Provenance {
    /// The provenance of a run on this machine with `threads` workers.
    pub fn here(threads: usize) -> Provenance {
        let commit = env!("HINFIX_GIT_COMMIT");
        Provenance {
            hinfix_version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: (!commit.is_empty()).then(|| commit.to_string()),
            host: host_name(),
            threads,
            cpu_model: cpu_model(),
        }
    }
}

/// This machine's host name (`"unknown"` if it cannot be read).
pub(crate) fn host_name() -> String {
    crate::fs_atomic::host_name()
}

/// The CPU model from `/proc/cpuinfo` (`model name`, else `Model`/`Hardware`), else the
/// architecture.
pub(crate) fn cpu_model() -> String {
    let text = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    for key in ["model name", "Model", "Hardware", "cpu model"] {
        let found = text.lines().find_map(|l| {
            let (k, v) = l.split_once(':')?;
            (k.trim() == key && !v.trim().is_empty()).then(|| v.trim().to_string())
        });
        if let Some(v) = found {
            return v;
        }
    }
    std::env::consts::ARCH.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn provenance_names_this_machine() {
        let p = Provenance::here(3);
        assert_eq!(p.threads, 3);
        assert_eq!(p.hinfix_version, env!("CARGO_PKG_VERSION"));
        assert!(!p.host.is_empty() && !p.cpu_model.is_empty());
        if let Some(c) = &p.git_commit {
            let hash = c.strip_suffix("+dirty").unwrap_or(c);
            assert!(hash.len() >= 7 && hash.chars().all(|c| c.is_ascii_hexdigit()), "{c}");
        }
        let v = serde_json::to_value(&p).unwrap();
        assert_eq!(serde_json::from_value::<Provenance>(v).unwrap(), p);
    }
}
