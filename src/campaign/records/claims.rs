//! Job claims: how several `campaign run` processes (on one machine, or on machines sharing the
//! results folder over a network filesystem) agree that each job runs once.
//!
//! A claim is the file `claims/<job id>.claim` held with an exclusive advisory lock
//! ([`File::try_lock`], `flock(2)`) for as long as the job runs. Taking one:
//!
//! 1. open (creating) the file and `try_lock` it; if another process holds it the job is
//!    [`TryClaim::Busy`];
//! 2. check the path still names the file we locked (a finishing owner unlinks it; without this
//!    check two processes could each lock a different inode of the same name);
//! 3. write the owner ([`ClaimOwner`]: host, pid, start time, journal) into it, for `status`.
//!
//! The caller must then re-read the journals: a claim only says "nobody else is running it", and
//! the job may have finished just before (the protocol is claim → check the journals → run →
//! journal → [`ClaimGuard::release`], so a finished job's record is durable before its claim is
//! dropped).
//!
//! Stale claims need no detection: the kernel drops the lock when its process dies, `kill -9`
//! included, so the file left behind is free for the next claimant. (A claim file without its
//! lock — left by a dead process — shows in `status` as stale.)
//!
//! One case keeps a dead owner's lock: a machine that crashed while holding locks on an NFSv3
//! share keeps them until it reboots. As a safety net, a claim held by a process on *another*
//! host for longer than [`overdue_after`] (twice the job's CPU budget plus [`OVERDUE_MARGIN`]) is
//! broken: under the job's break lock (`<job id>.break`, so that only one process breaks it), the
//! file is renamed away and claimed afresh. If its owner was in fact alive the job then runs
//! twice, which costs time but no result (readers count a job once).
//!
//! NFS: `flock` on an NFS mount is a whole-file POSIX lock at the server (Linux ≥ 2.6.12; NFSv4
//! locks, or NFSv3 with the NLM lock daemon). This needs locking to be enabled (not the `nolock`
//! or `local_lock=flock|all` mount options). The server drops the locks of a client that dies
//! when its lease expires (NFSv4, ~90 s) or when it reboots (NFSv3 NLM). Because POSIX locks are
//! per process, a process must not open a file it holds a claim on a second time (closing that
//! second descriptor would drop the lock); this module never does.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::campaign::model::jobs::JobId;

/// Slack of [`overdue_after`] (s): clock skew between hosts, a loaded node, journal and trace I/O.
pub const OVERDUE_MARGIN: f64 = 600.0;

/// How long (s) a job with CPU budget `cpumax` may stay claimed by a process on another host
/// before its claim is broken: 2·cpumax + [`OVERDUE_MARGIN`].
pub fn overdue_after(cpumax: f64) -> f64 {
    2.0 * cpumax + OVERDUE_MARGIN
}

/// The claims folder inside a campaign's results folder.
pub const CLAIMS_DIR: &str = "claims";

/// A claim file could not be made or read.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct ClaimError {
    /// The file or folder.
    pub path: PathBuf,
    /// The cause.
    #[source]
    pub source: io::Error,
}

/// Who holds a claim (written into the claim file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClaimOwner {
    /// Host name.
    pub host: String,
    /// Process id.
    pub pid: u32,
    /// When the job was claimed (Unix seconds).
    pub since_unix_s: f64,
    /// The journal the owner appends to.
    pub journal: String,
}

impl ClaimOwner {
    /// This process, appending to `journal`, claiming now.
    pub fn this_process(journal: &Path) -> ClaimOwner {
        ClaimOwner {
            host: crate::campaign::leaves::provenance::host_name(),
            pid: std::process::id(),
            since_unix_s: unix_now(),
            journal: journal.display().to_string(),
        }
    }
}

/// Seconds since the Unix epoch.
pub fn unix_now() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
}

/// The claims of one results folder.
#[derive(Debug, Clone)]
pub struct ClaimDir {
    dir: PathBuf,
}

/// A held claim; [`release`](ClaimGuard::release) it once the job's record is journaled (or the
/// job was interrupted). Dropping it without release also unlocks, but leaves the file.
#[derive(Debug)]
pub struct ClaimGuard {
    path: PathBuf,
    file: File,
}

/// The outcome of [`ClaimDir::try_claim`].
#[derive(Debug)]
pub enum TryClaim {
    /// Ours: run the job (after checking the journals).
    Claimed(ClaimGuard),
    /// Another live process holds it.
    Busy,
}

/// A claim file as `status` sees it.
#[derive(Debug, Clone)]
pub struct ClaimState {
    /// The job.
    pub job: JobId,
    /// Whether a live process holds it (false: left behind by a process that died).
    pub held: bool,
    /// Who claimed it (None if the file is empty or unreadable).
    pub owner: Option<ClaimOwner>,
}

fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    a.dev() == b.dev() && a.ino() == b.ino()
}

impl ClaimDir {
    /// The claims of results folder `results_dir`.
    pub fn new(results_dir: &Path) -> ClaimDir {
        ClaimDir { dir: results_dir.join(CLAIMS_DIR) }
    }

    /// The claim file of `job`.
    pub fn path(&self, job: &JobId) -> PathBuf {
        self.dir.join(format!("{job}.claim"))
    }

    /// Tries to claim `job` (CPU budget `cpumax` s) for `owner` (see the module docs).
    pub fn try_claim(&self, job: &JobId, cpumax: f64, owner: &ClaimOwner) -> Result<TryClaim, ClaimError> {
        let path = self.path(job);
        let err = |source| ClaimError { path: path.clone(), source };
        crate::fs_atomic::create_dir_all(&self.dir).map_err(|source| ClaimError { path: self.dir.clone(), source })?;
        let mut broke = false;
        // A few rounds at most: each retry means a finishing owner unlinked the file in between
        // (or we broke an overdue claim).
        for _ in 0..16 {
            let mut file =
                OpenOptions::new().read(true).write(true).create(true).truncate(false).open(&path).map_err(err)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    if !broke && self.break_if_overdue(job, &mut file, cpumax, owner)? {
                        broke = true;
                        continue;
                    }
                    return Ok(TryClaim::Busy);
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(err(e)),
            }
            let ours = file.metadata().map_err(err)?;
            match std::fs::metadata(&path) {
                Ok(now) if same_file(&ours, &now) => {}
                Ok(_) => continue,
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(err(e)),
            }
            let text = serde_json::to_vec(owner).map_err(|e| err(io::Error::other(e)))?;
            file.set_len(0).map_err(err)?;
            (&file).write_all(&text).map_err(err)?;
            return Ok(TryClaim::Claimed(ClaimGuard { path, file }));
        }
        Ok(TryClaim::Busy)
    }

    /// Breaks the held claim open in `file` if its owner is on another host and has held it for
    /// longer than [`overdue_after`]`(cpumax)`; true if it did.
    fn break_if_overdue(&self, job: &JobId, file: &mut File, cpumax: f64, me: &ClaimOwner) -> Result<bool, ClaimError> {
        let overdue = |f: &mut File| -> bool {
            let mut text = String::new();
            let read = f.seek(std::io::SeekFrom::Start(0)).and_then(|_| f.read_to_string(&mut text));
            match (read, serde_json::from_str::<ClaimOwner>(&text)) {
                (Ok(_), Ok(o)) => o.host != me.host && unix_now() - o.since_unix_s > overdue_after(cpumax),
                _ => false,
            }
        };
        if !overdue(file) {
            return Ok(false);
        }
        let path = self.path(job);
        let lock_path = self.dir.join(format!("{job}.break"));
        let err = |p: &Path| {
            let p = p.to_path_buf();
            move |source| ClaimError { path: p, source }
        };
        let lock =
            OpenOptions::new().write(true).create(true).truncate(false).open(&lock_path).map_err(err(&lock_path))?;
        lock.lock().map_err(err(&lock_path))?;
        // Under the break lock, look again: another process may have broken it already.
        let mut again = match File::open(&path) {
            Ok(f) => f,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(true),
            Err(e) => return Err(err(&path)(e)),
        };
        let still = matches!(again.try_lock_shared(), Err(std::fs::TryLockError::WouldBlock)) && overdue(&mut again);
        if still {
            let away = self.dir.join(format!("{job}.claim.broken.{}.{}", me.host, me.pid));
            std::fs::rename(&path, &away).map_err(err(&path))?;
            let _ = std::fs::remove_file(&away);
        }
        Ok(true)
    }

    /// Every claim file, held or left behind, sorted by job id. A missing folder is no claims.
    ///
    /// Held-ness is probed with a non-blocking shared lock, taken and dropped at once; a run
    /// trying to claim that very job in the same microseconds sees it busy and retries later.
    pub fn list(&self) -> Result<Vec<ClaimState>, ClaimError> {
        let rd = match std::fs::read_dir(&self.dir) {
            Ok(rd) => rd,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(source) => return Err(ClaimError { path: self.dir.clone(), source }),
        };
        let mut out = Vec::new();
        for entry in rd {
            let entry = entry.map_err(|source| ClaimError { path: self.dir.clone(), source })?;
            let name = entry.file_name().to_string_lossy().to_string();
            let Some(id) = name.strip_suffix(".claim") else { continue };
            let path = entry.path();
            let mut file = match File::open(&path) {
                Ok(f) => f,
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue, // released meanwhile
                Err(source) => return Err(ClaimError { path, source }),
            };
            let held = match file.try_lock_shared() {
                Ok(()) => false,
                Err(std::fs::TryLockError::WouldBlock) => true,
                Err(std::fs::TryLockError::Error(source)) => return Err(ClaimError { path, source }),
            };
            let mut text = String::new();
            let owner = file.read_to_string(&mut text).ok().and_then(|_| serde_json::from_str(&text).ok());
            out.push(ClaimState { job: JobId(id.to_string()), held, owner });
        }
        out.sort_by(|a, b| a.job.cmp(&b.job));
        Ok(out)
    }
}

impl ClaimGuard {
    /// The claim file.
    #[cfg(test)]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Removes the claim file (if it is still ours) and unlocks it.
    pub fn release(self) {
        if let (Ok(ours), Ok(now)) = (self.file.metadata(), std::fs::metadata(&self.path)) {
            if same_file(&ours, &now) {
                let _ = std::fs::remove_file(&self.path);
            }
        }
        drop(self.file);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn owner() -> ClaimOwner {
        ClaimOwner::this_process(Path::new("runs.jsonl"))
    }

    /// A claim folder in a fresh temporary folder (kept while the guard lives), and a job id of
    /// the hex digits `hex` repeated.
    fn claim_dir(hex: &str) -> (tempfile::TempDir, ClaimDir, JobId) {
        let dir = tempfile::tempdir().unwrap();
        let claims = ClaimDir::new(dir.path());
        (dir, claims, JobId(hex.repeat(32)))
    }

    #[test]
    fn a_claim_is_exclusive_until_released_and_listed_meanwhile() {
        let (_dir, claims, id) = claim_dir("ab");
        let TryClaim::Claimed(g) = claims.try_claim(&id, 10.0, &owner()).unwrap() else { panic!("free claim refused") };
        // A second claimant (another open file description, as another process would have).
        assert!(matches!(claims.try_claim(&id, 10.0, &owner()).unwrap(), TryClaim::Busy));
        let list = claims.list().unwrap();
        assert_eq!(list.len(), 1);
        assert!(list[0].held);
        assert_eq!(list[0].owner.as_ref().unwrap().pid, std::process::id());
        g.release();
        assert!(claims.list().unwrap().is_empty(), "release removes the file");
        assert!(matches!(claims.try_claim(&id, 10.0, &owner()).unwrap(), TryClaim::Claimed(_)));
    }

    #[test]
    fn a_dropped_lock_leaves_a_stale_file_that_can_be_claimed() {
        let (_dir, claims, id) = claim_dir("cd");
        let TryClaim::Claimed(g) = claims.try_claim(&id, 10.0, &owner()).unwrap() else { panic!() };
        drop(g); // as a killed process: lock gone, file left
        let list = claims.list().unwrap();
        assert_eq!((list.len(), list[0].held), (1, false));
        assert!(matches!(claims.try_claim(&id, 10.0, &owner()).unwrap(), TryClaim::Claimed(_)));
    }

    #[test]
    fn only_an_overdue_claim_of_another_host_is_broken() {
        let (_dir, claims, id) = claim_dir("ef");
        let old = unix_now() - overdue_after(10.0) - 1.0;
        for (host, since, broken) in
            [("elsewhere", old, true), ("elsewhere", unix_now(), false), (owner().host.as_str(), old, false)]
        {
            let ghost = ClaimOwner { host: host.to_string(), since_unix_s: since, ..owner() };
            let TryClaim::Claimed(g) = claims.try_claim(&id, 10.0, &ghost).unwrap() else { panic!() };
            match claims.try_claim(&id, 10.0, &owner()).unwrap() {
                TryClaim::Claimed(mine) => {
                    assert!(broken, "{host} {since}: broken");
                    // the ghost's late release does not remove the new claim
                    g.release();
                    assert!(mine.path().exists());
                    mine.release();
                }
                TryClaim::Busy => {
                    assert!(!broken, "{host} {since}: not broken");
                    g.release();
                }
            }
        }
    }
}
