//! Writing a whole file atomically and durably: the one function every output file goes through
//! (the campaign reports, the controller file of `campaign design`).
//!
//! A reader sees either the old file or the complete new one, never a part, and after the
//! function returns the new content survives a crash or power cut (docs/ARCHITECTURE.md §3):
//!
//! 1. write `.<name>.<host>.<pid>.<seq>.tmp` in the same directory (so the rename below stays
//!    within one file system; host, process id and a per-process sequence number keep two
//!    writers of the same file — threads, processes, or machines sharing the folder — from
//!    sharing a tmp file);
//! 2. `fsync` it (its data is on disk before its name is);
//! 3. `rename` it over `<name>` (atomic on POSIX file systems);
//! 4. `fsync` the directory (the rename itself is on disk).
//!
//! On an error the tmp file is removed (best effort) and the target is left as it was.
//! The MCAP traces are written incrementally by their own writer and use the same
//! tmp-then-rename scheme (`campaign::trace`); the journal is append-only (`campaign::journal`).

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Replaces `path` by a file holding exactly `bytes`, atomically and durably (see the module
/// docs). The error is the underlying I/O error; the caller adds the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let tmp = tmp_path(path)?;
    let result = write_synced(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    remove_dead_writers_tmp(path);
    sync_dir(path)
}

/// Removes the tmp files of `path` (step 1 of the module docs) that processes of this host left
/// and that are no longer running: a second Ctrl-C ends a process at once, between its tmp write
/// and its rename, and nothing else would ever remove its `.best.csv.<host>.<pid>.<seq>.tmp`.
/// A process that still runs (or that this user may not signal) keeps its file, and so does
/// another host's. Best effort.
fn remove_dead_writers_tmp(path: &Path) {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name().and_then(|n| n.to_str())) else { return };
    let dir = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    let prefix = format!(".{name}.{}.", host_name());
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let file = e.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)).and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some(pid) =
            rest.split_once('.').and_then(|(pid, seq)| seq.parse::<usize>().ok().and(pid.parse::<i32>().ok()))
        else {
            continue;
        };
        if pid > 0 && pid != std::process::id() as i32 && !process_runs(pid) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Whether a process `pid` exists on this host (`kill(pid, 0)`: only ESRCH means it does not).
fn process_runs(pid: i32) -> bool {
    // SAFETY: signal 0 sends nothing; it only checks that the process exists.
    let rc = unsafe { libc::kill(pid, 0) };
    rc == 0 || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// [`std::fs::create_dir_all`], whose error for a path component that is a file — "File exists
/// (os error 17)", "Not a directory (os error 20)" — names that file as no folder.
pub fn create_dir_all(dir: &Path) -> io::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| match dir.ancestors().find(|a| a.exists() && !a.is_dir()) {
        Some(file) => io::Error::new(e.kind(), format!("{} is a file, not a folder", file.display())),
        None => e,
    })
}

/// Whether `path` can be written by [`write_atomic`]: a tmp file of the same unique name scheme
/// is created next to it (`create_new`, so never another writer's) and removed again. A
/// directory at `path` is an error saying so. Used to refuse an unusable output before long
/// work; sharing one fixed probe name (`<path>.tmp`) let concurrent writers of one file delete
/// each other's probe and fail.
pub fn check_writable(path: &Path) -> io::Result<()> {
    if path.is_dir() {
        return Err(io::Error::new(io::ErrorKind::IsADirectory, "is a directory, not a file"));
    }
    let tmp = tmp_path(path)?;
    std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp)?;
    std::fs::remove_file(&tmp)
}

/// `<dir>/.<name>.<host>.<pid>.<seq>.tmp` next to `path`.
fn tmp_path(path: &Path) -> io::Result<PathBuf> {
    static SEQ: AtomicUsize = AtomicUsize::new(0);
    let name =
        path.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path does not name a file"))?;
    let seq = SEQ.fetch_add(1, Ordering::Relaxed);
    let mut tmp = std::ffi::OsString::from(".");
    tmp.push(name);
    tmp.push(format!(".{}.{}.{seq}.tmp", host_name(), std::process::id()));
    Ok(path.with_file_name(tmp))
}

/// This machine's host name (`gethostname`), or `"unknown"`.
pub fn host_name() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: gethostname writes at most buf.len() bytes into the buffer we own.
    let rc = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if rc != 0 {
        return "unknown".into();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    match String::from_utf8_lossy(&buf[..end]).trim() {
        "" => "unknown".into(),
        s => s.to_string(),
    }
}

fn write_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = File::create(path)?;
    f.write_all(bytes)?;
    f.sync_all()
}

/// `fsync` of the directory holding `path`, so that a rename into it is durable.
fn sync_dir(path: &Path) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    File::open(dir)?.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("hinfix-fs-atomic-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// The tmp file of a writer that died before its rename (a second Ctrl-C) goes with the
    /// next write of the file; one of a process that still runs, or of another host, stays.
    #[test]
    fn a_dead_writers_tmp_file_goes_with_the_next_write() {
        let d = scratch("dead");
        let p = d.join("best.csv");
        let host = host_name();
        // a process id that is not running: a child that has exited and been reaped
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let dead_tmp = d.join(format!(".best.csv.{host}.{dead}.0.tmp"));
        let live_tmp = d.join(format!(".best.csv.{host}.1.0.tmp")); // init: always runs
        let other_host = d.join(format!(".best.csv.{host}-elsewhere.{dead}.0.tmp"));
        for f in [&dead_tmp, &live_tmp, &other_host] {
            std::fs::write(f, b"half").unwrap();
        }
        write_atomic(&p, b"new\n").unwrap();
        assert!(!dead_tmp.exists());
        assert!(live_tmp.exists() && other_host.exists());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_file_in_the_way_of_a_folder_is_named() {
        let d = scratch("in-the-way");
        std::fs::write(d.join("claims"), b"").unwrap();
        let e = create_dir_all(&d.join("claims").join("x")).unwrap_err();
        assert_eq!(e.to_string(), format!("{} is a file, not a folder", d.join("claims").display()));
        create_dir_all(&d.join("ok").join("x")).unwrap();
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn writes_replaces_and_leaves_no_tmp_file() {
        let d = scratch("ok");
        let p = d.join("best.csv");
        write_atomic(&p, b"first\n").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"first\n");
        write_atomic(&p, b"second, longer\n").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second, longer\n");
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("best.csv")]);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn failure_keeps_the_old_file_and_removes_the_tmp_file() {
        let d = scratch("fail");
        // The target is a non-empty directory: the rename fails after the tmp file was written.
        let p = d.join("out");
        std::fs::create_dir_all(p.join("inside")).unwrap();
        assert!(write_atomic(&p, b"x").is_err());
        assert!(p.join("inside").is_dir());
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("out")]);
        // A path that names no file at all.
        assert_eq!(write_atomic(Path::new("/"), b"x").unwrap_err().kind(), io::ErrorKind::InvalidInput);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn concurrent_writers_of_one_file_all_succeed() {
        // `design --out` probed `<out>.tmp`, one name for every writer; two
        // runs at once deleted each other's probe and one failed (about 1 in 8).
        let d = scratch("concurrent");
        let p = d.join("K.json");
        std::thread::scope(|s| {
            for t in 0..8 {
                let p = &p;
                s.spawn(move || {
                    for i in 0..50 {
                        check_writable(p).unwrap();
                        write_atomic(p, format!("{t} {i}\n").as_bytes()).unwrap();
                    }
                });
            }
        });
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.ends_with(" 49\n"), "{text}");
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("K.json")]);
        assert_eq!(check_writable(&d).unwrap_err().kind(), io::ErrorKind::IsADirectory);
        let _ = std::fs::remove_dir_all(&d);
    }
}
