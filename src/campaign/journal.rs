//! The resume journal `results/<name>/runs.jsonl`: one [`JobRecord`] JSON line per finished job.
//!
//! * Writing ([`JournalWriter::append`]): the whole line plus its newline goes out in a single
//!   `write` on a file opened with `O_APPEND`, then the file is flushed and `fsync`ed, so a line
//!   is either entirely there or (after a kill -9 or a power cut in the middle) a torn tail.
//! * Reading ([`read_journal`]): every complete (newline-terminated) line must parse; a corrupt
//!   complete line is an error naming the file and line (something other than a crash damaged
//!   the file) and is never deleted, wherever it is. Only a last line without its newline — what
//!   a cut-off append leaves — is torn: it is reported in [`JournalRead::torn`] and ignored, and
//!   that job simply runs again.
//! * Repair ([`JournalWriter::open`]): before appending, a torn tail is truncated away so the file
//!   stays valid JSONL.
//!
//! Blank lines are skipped. Records with a newer `schema_version` than this program knows are
//! refused (an error naming the line) rather than misread.

use std::fs::{File, OpenOptions};
use std::io::{self, Write};
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
    #[error("{}:{line}: corrupt journal line (not a job record): {message}", path.display())]
    Corrupt {
        /// The journal.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What the JSON parser said.
        message: String,
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
}

fn io_err(path: &Path) -> impl FnOnce(io::Error) -> JournalError + '_ {
    move |source| JournalError::Io { path: path.to_path_buf(), source }
}

/// Parses one line; `Err` is the parser's message, or the newer schema version.
fn parse_line(text: &str) -> Result<JobRecord, Result<String, u32>> {
    #[derive(serde::Deserialize)]
    struct Version {
        schema_version: u32,
    }
    if let Ok(v) = serde_json::from_str::<Version>(text) {
        if v.schema_version > SCHEMA_VERSION {
            return Err(Err(v.schema_version));
        }
    }
    serde_json::from_str(text).map_err(|e| Ok(e.to_string()))
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
    let mut offset = 0usize;
    let mut line_no = 0usize;
    while offset < bytes.len() {
        line_no += 1;
        let (end, complete) = match bytes[offset..].iter().position(|&b| b == b'\n') {
            Some(i) => (offset + i, true),
            None => (bytes.len(), false),
        };
        let raw = &bytes[offset..end];
        let torn = |reason: String| TornTail { line: line_no, offset: offset as u64, len: bytes.len() - offset, reason };
        if !complete {
            out.torn = Some(torn("no trailing newline (the write was cut short)".into()));
            break;
        }
        let text = match std::str::from_utf8(raw) {
            Ok(t) => t.trim(),
            Err(e) => return Err(JournalError::Corrupt { path: path.to_path_buf(), line: line_no, message: format!("not UTF-8: {e}") }),
        };
        if !text.is_empty() {
            match parse_line(text) {
                Ok(r) => out.records.push(r),
                Err(Err(found)) => return Err(JournalError::NewerSchema { path: path.to_path_buf(), line: line_no, found }),
                Err(Ok(message)) => return Err(JournalError::Corrupt { path: path.to_path_buf(), line: line_no, message }),
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
}

impl JournalWriter {
    /// Opens (creating it and its folder if needed) the journal for appending, after cutting off
    /// a torn last line if there is one. Returns the writer and what was read.
    pub fn open(path: &Path) -> Result<(JournalWriter, JournalRead), JournalError> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io_err(path))?;
        }
        let read = read_journal(path)?;
        if let Some(t) = &read.torn {
            let f = OpenOptions::new().write(true).open(path).map_err(io_err(path))?;
            f.set_len(t.offset).map_err(io_err(path))?;
            f.sync_all().map_err(io_err(path))?;
        }
        let file = OpenOptions::new().create(true).append(true).open(path).map_err(io_err(path))?;
        Ok((JournalWriter { path: path.to_path_buf(), file }, read))
    }

    /// The journal's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Appends one record as one line: a single write of line + newline, flush, fsync.
    pub fn append(&mut self, record: &JobRecord) -> Result<(), JournalError> {
        let mut line = serde_json::to_vec(record)
            .map_err(|e| JournalError::Serialise { job: record.job_id.to_string(), message: e.to_string() })?;
        line.push(b'\n');
        let path = &self.path;
        self.file.write_all(&line).map_err(io_err(path))?;
        self.file.flush().map_err(io_err(path))?;
        self.file.sync_data().map_err(io_err(path))
    }
}
