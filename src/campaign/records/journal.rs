//! The resume journal `results/<name>/runs.jsonl`: one [`JobRecord`] JSON line per finished job.
//!
//! * Writing ([`JournalWriter::append`]): the whole line plus its newline goes out in a single
//!   `write` on a file opened with `O_APPEND`, then the file is flushed and `fsync`ed, so a line
//!   is either entirely there or (after a kill -9 or a power cut in the middle) a torn tail.
//! * Reading ([`read_journal`]): every complete (newline-terminated) line must parse; a corrupt
//!   complete line is an error naming the file and line (something other than a crash damaged
//!   the file) and is never deleted, wherever it is. A last line without its newline that parses
//!   as a whole record (a copy or an editor dropped the final newline; a cut-off append cannot
//!   leave one, since a record is one JSON object and no proper prefix of it parses) is kept and
//!   counted in [`JournalRead::unterminated`]. A last line without its newline that does not
//!   parse — what a cut-off append leaves — is torn: it is reported in [`JournalRead::torn`] and
//!   ignored, and that job simply runs again.
//! * Repair ([`JournalWriter::open`]): before appending, a torn tail is truncated away and a kept
//!   unterminated last record gets its newline, so the file stays valid JSONL.
//!
//! * Identity ([`JournalWriter::append`]): before each append the writer compares the open
//!   file's (device, inode) with what the path names now. If the journal was deleted (or its
//!   folder) or replaced by another file, appending would write into a file nobody can read:
//!   instead the writer saves everything the open file holds plus the new record to a new
//!   journal `runs.rescued-<pid>.jsonl` in the same folder (re-creating the folder if it is
//!   gone), goes on appending there, and returns [`JournalError::Gone`] naming it, which stops
//!   the run with an error. The rescued file is a journal like any other: a resume skips its
//!   jobs.
//!
//! Blank lines are skipped. Records with a newer `schema_version` than this program knows are
//! refused (an error naming the line) rather than misread.
//!
//! Several processes sharing one results folder (see `claims`): each appends to a journal of its
//! own, the first of `runs.jsonl`, `runs.2.jsonl`, `runs.3.jsonl`, … that no live process holds
//! ([`JournalWriter::open_in`] keeps an exclusive lock on it for the writer's life), so lines of
//! different processes never interleave, and only the owner ever cuts a torn tail. Readers take
//! every `runs*.jsonl` of the folder ([`journals_in`]); a [`Follower`] reads them incrementally
//! while a run goes on, never consuming a last line that is not complete yet.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::record::{JobRecord, SCHEMA_VERSION};

/// The journal's file name inside `results/<name>/`.
pub const JOURNAL_FILE: &str = "runs.jsonl";

/// A journal that cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// An I/O error on the journal file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The journal.
        path: PathBuf,
        /// The error.
        #[source]
        source: io::Error,
    },
    /// A complete line (not the last) that is not a valid record.
    #[error("{}:{line}: corrupt journal line (not a job record): {problem}", path.display())]
    Corrupt {
        /// The journal.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with the line.
        #[source]
        problem: CorruptLine,
    },
    /// A record written by a newer hinfix.
    #[error("{}:{line}: journal record has schema_version {found}, this program reads up to {SCHEMA_VERSION}", path.display())]
    NewerSchema {
        /// The journal.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// The version found.
        found: u32,
    },
    /// The journal is locked by another live process.
    #[error("{}: in use by another running process", path.display())]
    Busy {
        /// The journal.
        path: PathBuf,
    },
    /// The journal file was deleted or replaced while this writer appended to it.
    #[error(
        "{}: the journal was {what} while the run was writing it; {rescue}",
        path.display()
    )]
    Gone {
        /// The journal.
        path: PathBuf,
        /// `deleted` or `replaced by another file`.
        what: &'static str,
        /// Where this writer's records went, or why they could not be saved.
        rescue: String,
    },
    /// A record could not be serialised (cannot happen for well-formed records).
    #[error("cannot serialise the record of job {job}: {message}")]
    Serialise {
        /// The job id.
        job: String,
        /// The serde error.
        message: String,
    },
}

/// A torn last line: what a kill in the middle of an append leaves behind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TornTail {
    /// 1-based line number of the torn line.
    pub line: usize,
    /// Byte offset where it starts (the file is valid up to here).
    pub offset: u64,
    /// Its length in bytes.
    pub len: usize,
    /// Why it is considered torn.
    pub reason: String,
}

/// What [`read_journal`] found.
#[derive(Debug, Clone, Default)]
pub struct JournalRead {
    /// The records, in file order.
    pub records: Vec<JobRecord>,
    /// The torn last line, if any (ignored).
    pub torn: Option<TornTail>,
    /// Whether the last record (kept, in `records`) lacks its final newline.
    pub unterminated: bool,
}

fn io_err(path: &Path) -> impl FnOnce(io::Error) -> JournalError + '_ {
    move |source| JournalError::Io { path: path.to_path_buf(), source }
}

/// Parses one line; `Err` is the parser's message, or the newer schema version.
/// Why a complete journal line is not a job record.
#[derive(Debug, thiserror::Error)]
pub enum CorruptLine {
    /// The line is not UTF-8 text.
    #[error("not UTF-8: {0}")]
    NotUtf8(#[from] std::str::Utf8Error),
    /// The line is not the JSON of a record (the parser's message).
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

/// Why [`parse_line`] read no record.
enum LineError {
    /// Written by a newer hinfix: its schema version.
    Newer(u32),
    /// Not a record of any version.
    Corrupt(CorruptLine),
}

fn parse_line(text: &str) -> Result<JobRecord, LineError> {
    #[derive(serde::Deserialize)]
    struct Version {
        schema_version: u32,
    }
    if let Ok(v) = serde_json::from_str::<Version>(text) {
        if v.schema_version > SCHEMA_VERSION {
            return Err(LineError::Newer(v.schema_version));
        }
    }
    serde_json::from_str(text).map_err(|e| LineError::Corrupt(e.into()))
}

/// Reads a journal. A missing file is an empty journal.
pub fn read_journal(path: &Path) -> Result<JournalRead, JournalError> {
    let bytes = match crate::input::read_capped(path, crate::input::MAX_JOURNAL_BYTES, "journal") {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(JournalRead::default()),
        Err(e) => return Err(io_err(path)(e)),
    };
    parse_journal(&bytes, path)
}

/// Parses journal bytes (`path` names the file in errors).
pub fn parse_journal(bytes: &[u8], path: &Path) -> Result<JournalRead, JournalError> {
    let mut out = JournalRead::default();
    // a UTF-8 byte-order mark, which an editor may put at the start of a saved file, as the
    // other JSON inputs accept it (the first line was "corrupt: expected value at column 1")
    let mut offset = if bytes.starts_with(b"\xEF\xBB\xBF") { 3 } else { 0 };
    let mut line_no = 0usize;
    while offset < bytes.len() {
        line_no += 1;
        let (end, complete) = match bytes[offset..].iter().position(|&b| b == b'\n') {
            Some(i) => (offset + i, true),
            None => (bytes.len(), false),
        };
        let raw = &bytes[offset..end];
        let torn =
            |reason: String| TornTail { line: line_no, offset: offset as u64, len: bytes.len() - offset, reason };
        if !complete {
            // A whole record lacking only its newline is kept; anything else is a cut-off write.
            match std::str::from_utf8(raw).map(|t| parse_line(t.trim())) {
                Ok(Ok(r)) => {
                    out.records.push(r);
                    out.unterminated = true;
                }
                Ok(Err(LineError::Newer(found))) => {
                    return Err(JournalError::NewerSchema { path: path.to_path_buf(), line: line_no, found })
                }
                _ => {
                    out.torn = Some(torn("no trailing newline and not a whole record (the write was cut short)".into()))
                }
            }
            break;
        }
        let text = match std::str::from_utf8(raw) {
            Ok(t) => t.trim(),
            Err(e) => return Err(JournalError::Corrupt { path: path.to_path_buf(), line: line_no, problem: e.into() }),
        };
        if !text.is_empty() {
            match parse_line(text) {
                Ok(r) => out.records.push(r),
                Err(LineError::Newer(found)) => {
                    return Err(JournalError::NewerSchema { path: path.to_path_buf(), line: line_no, found })
                }
                Err(LineError::Corrupt(problem)) => {
                    return Err(JournalError::Corrupt { path: path.to_path_buf(), line: line_no, problem })
                }
            }
        }
        offset = end + 1;
    }
    Ok(out)
}

/// Appends records to a journal, one durable line each.
#[derive(Debug)]
pub struct JournalWriter {
    path: PathBuf,
    file: File,
    /// (device, inode) of `file`: the path must still name it at each append.
    id: (u64, u64),
}

/// (device, inode) of a file's metadata.
fn file_id(m: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (m.dev(), m.ino())
}

impl JournalWriter {
    /// Opens (creating it and its folder if needed) the journal for appending, locked
    /// exclusively for this writer's life, after cutting off a torn last line if there is one.
    /// Returns the writer and what was read. Fails with [`JournalError::Busy`] if another
    /// process holds it.
    pub fn open(path: &Path) -> Result<(JournalWriter, JournalRead), JournalError> {
        Self::try_open(path)?.ok_or_else(|| JournalError::Busy { path: path.to_path_buf() })
    }

    /// Opens the first journal of `dir` that no live process holds: `runs.jsonl`, then
    /// `runs.2.jsonl`, `runs.3.jsonl`, … (see the module docs).
    pub fn open_in(dir: &Path) -> Result<(JournalWriter, JournalRead), JournalError> {
        for k in 1.. {
            let name = if k == 1 { JOURNAL_FILE.to_string() } else { format!("runs.{k}.jsonl") };
            if let Some(w) = Self::try_open(&dir.join(name))? {
                return Ok(w);
            }
        }
        unreachable!("some journal number is free")
    }

    /// [`open`](Self::open), or `None` if another process holds the lock. Everything is read
    /// and repaired through the locked descriptor (under NFS, closing another descriptor of a
    /// locked file would drop the lock).
    fn try_open(path: &Path) -> Result<Option<(JournalWriter, JournalRead)>, JournalError> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            crate::fs_atomic::create_dir_all(dir).map_err(io_err(path))?;
        }
        let mut file = OpenOptions::new().create(true).read(true).append(true).open(path).map_err(io_err(path))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => return Ok(None),
            Err(std::fs::TryLockError::Error(e)) => return Err(io_err(path)(e)),
        }
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io_err(path))?;
        let read = parse_journal(&bytes, path)?;
        if let Some(t) = &read.torn {
            file.set_len(t.offset).map_err(io_err(path))?;
            file.sync_all().map_err(io_err(path))?;
        }
        if read.unterminated {
            file.write_all(b"\n").map_err(io_err(path))?;
            file.sync_data().map_err(io_err(path))?;
        }
        let id = file_id(&file.metadata().map_err(io_err(path))?);
        Ok(Some((JournalWriter { path: path.to_path_buf(), file, id }, read)))
    }

    /// The journal's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends one record as one line: a single write of line + newline, flush, fsync. If the
    /// path no longer names the open file, the records are rescued first and the result is
    /// [`JournalError::Gone`] (see the module docs).
    pub fn append(&mut self, record: &JobRecord) -> Result<(), JournalError> {
        let mut line = serde_json::to_vec(record)
            .map_err(|e| JournalError::Serialise { job: record.job_id.to_string(), message: e.to_string() })?;
        line.push(b'\n');
        let gone = match std::fs::metadata(&self.path) {
            Ok(m) if file_id(&m) == self.id => None,
            Ok(_) => Some("replaced by another file"),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Some("deleted"),
            Err(e) => return Err(io_err(&self.path)(e)),
        };
        if let Some(what) = gone {
            let path = self.path.clone();
            let rescue = match self.rescue(&line) {
                Ok((to, n)) => format!(
                    "its {n} records (this one included) are saved in {}, which a resume reads; the run stops",
                    to.display()
                ),
                Err(e) => format!("its records could not be saved ({e}); the run stops"),
            };
            return Err(JournalError::Gone { path, what, rescue });
        }
        let path = &self.path;
        self.file.write_all(&line).map_err(io_err(path))?;
        self.file.flush().map_err(io_err(path))?;
        self.file.sync_data().map_err(io_err(path))
    }

    /// Writes what the open (unlinked or replaced) file holds plus `line` to a new journal
    /// `runs.rescued-<pid>.jsonl` of the folder, atomically, and moves this writer there.
    /// Returns the new path and the number of lines it holds.
    fn rescue(&mut self, line: &[u8]) -> io::Result<(PathBuf, usize)> {
        let mut bytes = Vec::new();
        self.file.seek(SeekFrom::Start(0))?;
        self.file.read_to_end(&mut bytes)?;
        if !bytes.is_empty() && !bytes.ends_with(b"\n") {
            bytes.push(b'\n'); // a torn tail cannot be left in the middle of the file
        }
        bytes.extend_from_slice(line);
        let dir = self.path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        crate::fs_atomic::create_dir_all(dir)?;
        let to = dir.join(format!("runs.rescued-{}.jsonl", std::process::id()));
        crate::fs_atomic::write_atomic(&to, &bytes)?;
        let file = OpenOptions::new().read(true).append(true).open(&to)?;
        // Our own new file: the lock can only fail on a file system without locks.
        let _ = file.try_lock();
        self.id = file_id(&file.metadata()?);
        self.file = file;
        self.path = to.clone();
        Ok((to, bytes.iter().filter(|&&b| b == b'\n').count()))
    }
}

/// Whether `name` is a journal's file name: `runs.jsonl` or `runs.<anything>.jsonl`.
pub fn is_journal_name(name: &str) -> bool {
    name == JOURNAL_FILE || (name.starts_with("runs.") && name.ends_with(".jsonl") && name.len() > "runs..jsonl".len())
}

/// The journals in folder `dir` (sorted by name). A missing folder has none. A journal's name
/// on something that is not a regular file (a folder, a FIFO, a dangling symbolic link) is an
/// error naming it: skipping it silently re-ran the jobs it was meant to hold.
pub fn journals_in(dir: &Path) -> Result<Vec<PathBuf>, JournalError> {
    let rd = match std::fs::read_dir(dir) {
        Ok(rd) => rd,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io_err(dir)(e)),
    };
    let mut out = Vec::new();
    for e in rd {
        let e = e.map_err(io_err(dir))?;
        if is_journal_name(&e.file_name().to_string_lossy()) {
            if !e.path().is_file() {
                let not_a_file = io::Error::new(
                    io::ErrorKind::InvalidInput,
                    "is not a regular file, and every runs*.jsonl of a results folder is read as a journal (move it away)",
                );
                return Err(io_err(&e.path())(not_a_file));
            }
            out.push(e.path());
        }
    }
    out.sort();
    Ok(out)
}

/// Where a [`Follower`] is in one journal.
#[derive(Debug, Clone, Default)]
struct Tail {
    offset: u64,
    lines: usize,
    torn: Option<TornTail>,
}

/// Reads the journals of a folder (and extra journal files) incrementally: each
/// [`poll`](Follower::poll) returns the complete records appended since the last one, including
/// those of journals that appeared meanwhile. An incomplete last line (one that does not parse
/// as a whole record) is left for the next poll
/// (its writer may still be writing it); if its writer died it stays, and is reported by
/// [`torn`](Follower::torn).
#[derive(Debug, Clone)]
pub struct Follower {
    dirs: Vec<PathBuf>,
    files: Vec<PathBuf>,
    skip: Option<PathBuf>,
    tails: BTreeMap<PathBuf, Tail>,
}

impl Follower {
    /// Follows every journal in `dirs` and the journal `files`, except `skip` (a writer's own
    /// journal, which it must not open a second time).
    pub fn new(dirs: Vec<PathBuf>, files: Vec<PathBuf>, skip: Option<PathBuf>) -> Follower {
        Follower { dirs, files, skip, tails: BTreeMap::new() }
    }

    /// The journals followed so far.
    pub fn journals(&self) -> Vec<PathBuf> {
        self.tails.keys().cloned().collect()
    }

    /// Torn (incomplete or unparsable) last lines seen at the last poll, by journal.
    pub fn torn(&self) -> Vec<(PathBuf, TornTail)> {
        self.tails.iter().filter_map(|(p, t)| t.torn.clone().map(|t| (p.clone(), t))).collect()
    }

    /// The records appended since the last poll, journal by journal in name order.
    pub fn poll(&mut self) -> Result<Vec<JobRecord>, JournalError> {
        let mut paths = self.files.clone();
        for d in &self.dirs {
            paths.extend(journals_in(d)?);
        }
        // one file named twice (`--journal` repeating the folder's) is read once
        let canon = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
        let skip = self.skip.as_deref().map(canon);
        let mut out = Vec::new();
        let mut done = std::collections::HashSet::new();
        for path in paths {
            let path = canon(&path);
            if skip.as_ref() == Some(&path) || !done.insert(path.clone()) {
                continue;
            }
            let tail = self.tails.entry(path.clone()).or_default();
            let mut bytes = Vec::new();
            match File::open(&path) {
                Ok(mut f) => {
                    f.seek(SeekFrom::Start(tail.offset)).map_err(io_err(&path))?;
                    f.read_to_end(&mut bytes).map_err(io_err(&path))?;
                }
                Err(e) if e.kind() == io::ErrorKind::NotFound => continue,
                Err(e) => return Err(io_err(&path)(e)),
            }
            let read = parse_journal(&bytes, &path).map_err(|e| match e {
                JournalError::Corrupt { path, line, problem } => {
                    JournalError::Corrupt { path, line: line + tail.lines, problem }
                }
                JournalError::NewerSchema { path, line, found } => {
                    JournalError::NewerSchema { path, line: line + tail.lines, found }
                }
                e => e,
            })?;
            let consumed = read.torn.as_ref().map_or(bytes.len(), |t| t.offset as usize);
            let base = (tail.offset, tail.lines);
            tail.offset += consumed as u64;
            tail.lines += bytes[..consumed].iter().filter(|&&b| b == b'\n').count();
            tail.torn = read.torn.map(|t| TornTail { line: t.line + base.1, offset: t.offset + base.0, ..t });
            out.extend(read.records);
        }
        Ok(out)
    }
}
