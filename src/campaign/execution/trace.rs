//! Per-job optimiser traces in MCAP (Foxglove-readable): `traces/<job_id>.mcap`.
//!
//! Two channels, both with message encoding `json` and a JSON Schema (schema encoding
//! `jsonschema`):
//! * [`ITER_TOPIC`] — one message per optimiser iteration ([`iter_message`]: phase, start,
//!   iteration, f, ‖Tzw‖∞ as `gamma`, ‖K‖∞ as `k_hinf` (older builds: `hinf_cl`, `hinf_k`),
//!   α_cl, α_K, dnorm, step, evaluations, elapsed CPU seconds) at trace level `full` (observer
//!   mode [`ObserverMode::Always`]); at level `sparse` (the default; [`ObserverMode::Sparse`])
//!   only the iterations [`SparseFilter`] keeps: the writer is a [`DesignObserver`] with a mode
//!   ([`TraceLevel::mode`]), as any other. A message's MCAP
//!   sequence number is its index among all the iterations, so a sparse trace's gaps show what
//!   was left out ([`TraceSummary::offered`]);
//! * [`RESULT_TOPIC`] — one final message, the job's [`JobRecord`] as journaled (with its
//!   `search` summary: starts, best start, CPU time to best, stop reason).
//!
//! A message's MCAP `log_time` (and `publish_time`) is the wall-clock time of its iteration in
//! nanoseconds since the Unix epoch (what MCAP tools such as Foxglove expect): the writer's start
//! as Unix time plus the monotonic time elapsed since, so the times of one trace never go back.
//!
//! Non-finite numbers are written as the strings `"inf"`, `"-inf"` or `"nan"` (JSON has no
//! such numbers); the schema allows number or string for every float.
//!
//! Level `off` makes no writer and no file ([`trace_observers`]).
//!
//! Messages are written in zstd-compressed chunks. A chunk is readable only once it is finished,
//! so the writer ends the chunk and flushes the file when the messages written since the last
//! flush reach [`CHUNK_BYTES`] (uncompressed) or [`FLUSH_INTERVAL`] has passed: a killed job's
//! tmp file is a readable trace up to at most that much before the kill. Large chunks compress
//! well: a short job's sparse trace is one chunk, and the smoke campaign's sparse chunks shrink to
//! about 27 % of their JSON (campaigns/FORMAT.md, "Traces").
//!
//! The writer ([`TraceWriter`], a [`JobObserver`], i.e. a [`DesignObserver`] told how the job ended) writes `<job_id>.mcap.<host>.<pid>.tmp` (a
//! name no other process uses, even on another machine sharing the folder), and on `finish`
//! renames it atomically to `<job_id>.mcap`; `abandon` deletes the tmp file, so a cut-off run never leaves a
//! complete-looking trace. The job's claim is held while it runs, so on creation the leftover
//! tmp files of the same job (from a killed process) are deleted. An I/O error is kept and stops
//! the job's tracing (never the job).

use std::collections::BTreeMap;
use std::fmt;
use std::fs::File;
use std::io::BufWriter;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use super::scheduler::{no_observers, JobObserver, ObserverError};
use crate::campaign::leaves::trace_filter::TraceLevel;
use crate::campaign::model::jobs::Job;
use crate::campaign::records::record::JobRecord;
#[cfg(doc)]
use crate::design::SparseFilter;
use crate::design::{DesignIterRecord, DesignObserver, ModeFilter, ObserverMode};

/// Topic of the per-iteration channel.
pub const ITER_TOPIC: &str = "/hinfix/iterations";
/// Topic of the final-result channel.
pub const RESULT_TOPIC: &str = "/hinfix/result";
/// End the chunk and flush when the messages written since the last flush reach this many bytes
/// (uncompressed JSON) …
pub const CHUNK_BYTES: usize = 64 * 1024;
/// … or after this much wall time, whichever comes first.
pub const FLUSH_INTERVAL: Duration = Duration::from_secs(10);

/// Errors of the trace writer and reader, naming the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TraceError {
    /// Reading or writing the file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP layer failed (bad or truncated file).
    #[error("{}: MCAP: {source}", path.display())]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: mcap::McapError,
    },
    /// The MCAP reader failed on damaged data (it panicked; the panic was caught).
    #[error("{}: damaged trace, not readable as MCAP ({message})", path.display())]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What the reader's panic said.
        message: String,
    },
    /// A message is not the JSON this module writes.
    #[error("{}: message {index} on {topic}: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// Topic of the message.
        topic: String,
        /// Index of the message in the file.
        index: usize,
        /// The cause.
        #[source]
        source: serde_json::Error,
    },
}

pub use crate::design::{f64_from_json, f64_to_json as json_f64};

/// Keys of [`ITER_TOPIC`] messages renamed since older builds: (current, old). ‖Tzw‖∞ and ‖K‖∞
/// have one name each across the crate (docs/ARCHITECTURE.md §5); traces written before the
/// rename stay readable through [`iter_field`].
pub const RENAMED_ITER_KEYS: [(&str, &str); 2] = [("gamma", "hinf_cl"), ("k_hinf", "hinf_k")];

/// Field `key` of an iteration message, under its old name if the message predates the rename
/// ([`RENAMED_ITER_KEYS`]); `Null` if absent.
pub fn iter_field<'a>(v: &'a Value, key: &str) -> &'a Value {
    match (v.get(key), RENAMED_ITER_KEYS.iter().find(|(new, _)| *new == key)) {
        (None, Some((_, old))) => &v[*old],
        _ => &v[key],
    }
}

/// One iteration as written on [`ITER_TOPIC`].
pub fn iter_message(rec: &DesignIterRecord) -> Value {
    json!({
        "phase": rec.phase.name(),
        "start": rec.start,
        "iteration": rec.iter,
        "f": json_f64(rec.f),
        "gamma": json_f64(rec.gamma),
        "k_hinf": json_f64(rec.k_hinf),
        "alpha_cl": json_f64(rec.alpha_cl),
        "alpha_k": json_f64(rec.alpha_k),
        "dnorm": json_f64(rec.dnorm),
        "step": json_f64(rec.step),
        "evaluations": rec.evals,
        "elapsed_cpu_s": json_f64(rec.cpu_s),
    })
}

/// JSON Schema of an [`ITER_TOPIC`] message.
pub fn iter_schema() -> Value {
    let float =
        json!({"type": ["number", "string", "null"], "description": "finite number, or \"inf\"/\"-inf\"/\"nan\""});
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "hinfix.Iteration",
        "type": "object",
        "properties": {
            "phase": {"type": "string"},
            "start": {"type": "integer"},
            "iteration": {"type": "integer"},
            "f": float, "gamma": float, "k_hinf": float, "alpha_cl": float, "alpha_k": float,
            "dnorm": float, "step": float,
            "evaluations": {"type": "integer"},
            "elapsed_cpu_s": float,
        },
        "required": ["phase", "iteration", "f"],
    })
}

/// JSON Schema of a [`RESULT_TOPIC`] message (a journal line; loosely typed).
pub fn result_schema() -> Value {
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "hinfix.JobRecord",
        "type": "object",
        "properties": {"job_id": {"type": "string"}, "plant": {"type": "string"}, "order": {"type": "integer"},
                       "status": {"type": "object"}, "gamma": {"type": ["number", "string", "null"]}},
        "required": ["job_id", "status"],
    })
}

/// Nanoseconds since the Unix epoch now (0 on a clock set before 1970).
fn unix_now_ns() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64)
}

/// An iteration waiting to be written: its sequence number and time are those of its arrival.
#[derive(Debug)]
struct Stamped {
    seq: u32,
    log_time: u64,
    rec: DesignIterRecord,
}

/// Writes one job's trace; see the module doc.
pub struct TraceWriter {
    writer: Option<mcap::Writer<BufWriter<File>>>,
    /// Which iterations are written (the observer mode of the trace level).
    filter: ModeFilter<Stamped>,
    tmp: PathBuf,
    target: PathBuf,
    iter_channel: u16,
    result_channel: u16,
    seq: u32,
    /// Message bytes written since the last flush.
    since_flush: usize,
    last_flush: Instant,
    started: Instant,
    /// Unix time of `started`, in nanoseconds.
    started_unix_ns: u64,
    error: Option<TraceError>,
}

impl TraceWriter {
    /// Creates `<dir>/<job_id>.mcap.<host>.<pid>.tmp` (and `dir`), deleting other tmp files of
    /// the job (the caller runs the job, so they are leftovers), and writes the header, schemas
    /// and channels. It writes the iterations that `mode` passes on (a trace level's:
    /// [`TraceLevel::mode`]).
    pub fn create(dir: &Path, job_id: &str, mode: ObserverMode) -> Result<Self, TraceError> {
        let target = dir.join(format!("{job_id}.mcap"));
        let host = crate::campaign::leaves::provenance::host_name();
        let tmp = dir.join(format!("{job_id}.mcap.{host}.{}.tmp", std::process::id()));
        let io = |source| TraceError::Io { path: tmp.clone(), source };
        crate::fs_atomic::create_dir_all(dir).map_err(|source| TraceError::Io { path: dir.to_path_buf(), source })?;
        let stale = format!("{job_id}.mcap.");
        for e in std::fs::read_dir(dir).map_err(|source| TraceError::Io { path: dir.to_path_buf(), source })?.flatten()
        {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with(&stale) && name.ends_with(".tmp") {
                let _ = std::fs::remove_file(e.path());
            }
        }
        let file = File::create(&tmp).map_err(io)?;
        let mc = |source| TraceError::Mcap { path: tmp.clone(), source };
        let mut w = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            // On the writing thread: no zstd worker threads beside the campaign's own.
            .compression_threads(0)
            // Chunks end where the writer flushes (module doc), not at mcap's 1 MiB default.
            .chunk_size(None)
            .profile("")
            .library(concat!("hinfix ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(mc)?;
        let s_iter =
            w.add_schema("hinfix.Iteration", "jsonschema", iter_schema().to_string().as_bytes()).map_err(mc)?;
        let s_res =
            w.add_schema("hinfix.JobRecord", "jsonschema", result_schema().to_string().as_bytes()).map_err(mc)?;
        let meta = BTreeMap::new();
        let iter_channel = w.add_channel(s_iter, ITER_TOPIC, "json", &meta).map_err(mc)?;
        let result_channel = w.add_channel(s_res, RESULT_TOPIC, "json", &meta).map_err(mc)?;
        Ok(TraceWriter {
            writer: Some(w),
            filter: ModeFilter::new(mode),
            tmp,
            target,
            iter_channel,
            result_channel,
            seq: 0,
            since_flush: 0,
            last_flush: Instant::now(),
            // Unix time first: the monotonic clock added to it then never runs ahead of the
            // wall clock
            started_unix_ns: unix_now_ns(),
            started: Instant::now(),
            error: None,
        })
    }

    /// The temporary path written while the job runs.
    pub fn tmp_path(&self) -> &Path {
        &self.tmp
    }

    /// The next sequence number and the time now.
    fn stamp(&mut self) -> (u32, u64) {
        let seq = self.seq;
        self.seq += 1;
        (seq, self.started_unix_ns.saturating_add(self.started.elapsed().as_nanos() as u64))
    }

    fn write(&mut self, channel: u16, (sequence, t): (u32, u64), data: &Value) -> Result<(), TraceError> {
        let Some(w) = self.writer.as_mut() else { return Ok(()) };
        let header = mcap::records::MessageHeader { channel_id: channel, sequence, log_time: t, publish_time: t };
        let bytes = data.to_string();
        self.since_flush += bytes.len();
        w.write_to_known_channel(&header, bytes.as_bytes())
            .map_err(|source| TraceError::Mcap { path: self.tmp.clone(), source })
    }

    fn flush_if_due(&mut self) -> Result<(), TraceError> {
        if self.since_flush >= CHUNK_BYTES || self.last_flush.elapsed() >= FLUSH_INTERVAL {
            if let Some(w) = self.writer.as_mut() {
                w.flush().map_err(|source| TraceError::Mcap { path: self.tmp.clone(), source })?;
            }
            self.since_flush = 0;
            self.last_flush = Instant::now();
        }
        Ok(())
    }

    fn write_iter(&mut self, s: Stamped) -> Result<(), TraceError> {
        self.write(self.iter_channel, (s.seq, s.log_time), &iter_message(&s.rec))?;
        self.flush_if_due()
    }

    /// Takes one iteration: gives it to the mode's filter (stamped with its sequence number and
    /// time of arrival) and writes what that passes on.
    pub fn record_iter(&mut self, rec: &DesignIterRecord) -> Result<(), TraceError> {
        let (seq, log_time) = self.stamp();
        let s = Stamped { seq, log_time, rec: rec.clone() };
        self.filter.push(rec, s).into_iter().try_for_each(|s| self.write_iter(s))
    }

    /// Writes the iterations the filter still holds (the last one), the final result, finishes
    /// the file, fsyncs it and renames it into place.
    pub fn complete(mut self, record: &JobRecord) -> Result<PathBuf, TraceError> {
        if let Some(e) = self.error.take() {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(e);
        }
        for held in self.filter.finish() {
            self.write_iter(held)?;
        }
        let data = serde_json::to_value(record).map_err(|source| TraceError::Json {
            path: self.tmp.clone(),
            topic: RESULT_TOPIC.into(),
            index: self.seq as usize,
            source,
        })?;
        let stamp = self.stamp();
        self.write(self.result_channel, stamp, &data)?;
        let mc = |source| TraceError::Mcap { path: self.tmp.clone(), source };
        let mut w = self.writer.take().ok_or_else(|| TraceError::Io {
            path: self.tmp.clone(),
            source: std::io::Error::other("trace already closed"),
        })?;
        w.finish().map_err(mc)?;
        let buf = w.into_inner();
        let io = |source| TraceError::Io { path: self.tmp.clone(), source };
        let file = buf.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&self.tmp, &self.target)
            .map_err(|source| TraceError::Io { path: self.target.clone(), source })?;
        Ok(self.target.clone())
    }

    /// Deletes the temporary file.
    pub fn discard(mut self) {
        self.writer.take();
        let _ = std::fs::remove_file(&self.tmp);
    }
}

impl DesignObserver for TraceWriter {
    fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
        if self.error.is_none() {
            if let Err(e) = self.record_iter(rec) {
                // Keep the error; stop tracing, not the job.
                self.writer.take();
                self.error = Some(e);
            }
        }
        ControlFlow::Continue(())
    }
}

impl JobObserver for TraceWriter {
    fn finish(self: Box<Self>, record: &JobRecord) -> Result<(), ObserverError> {
        self.complete(record).map(|_| ()).map_err(ObserverError::failed)
    }

    fn abandon(self: Box<Self>) {
        self.discard();
    }
}

/// The observer factory for `scheduler::execute`: one [`TraceWriter`] per job in `traces_dir`,
/// at the trace level of the job's problem (`levels`, indexed like the campaign's problems:
/// [`crate::campaign::Campaign::trace_levels`]; a problem beyond it gets the default); none at level
/// `off`.
pub fn trace_observers(
    traces_dir: &Path,
    levels: Vec<TraceLevel>,
) -> impl Fn(&Job) -> Result<Box<dyn JobObserver>, ObserverError> + Sync {
    let dir = traces_dir.to_path_buf();
    move |job: &Job| match levels.get(job.problem).copied().unwrap_or_default().mode() {
        None => no_observers(job),
        Some(mode) => TraceWriter::create(&dir, &job.id.0, mode)
            .map(|w| Box::new(w) as Box<dyn JobObserver>)
            .map_err(ObserverError::failed),
    }
}

/// Per-phase counts in a [`TraceSummary`].
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct PhaseSummary {
    /// Iteration messages of this phase.
    pub messages: usize,
    /// First f of the phase.
    pub first_f: f64,
    /// Last f of the phase.
    pub last_f: f64,
}

/// What `campaign trace FILE` prints.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TraceSummary {
    /// The file.
    pub path: PathBuf,
    /// Iteration messages in the file (at level `full`: one per optimiser step plus one for the
    /// starting point of every optimiser run, which has `iteration` 0; at level `sparse`: those
    /// kept).
    pub messages: usize,
    /// Iteration messages the optimiser produced, kept or not: one more than the last message's
    /// sequence number (the result's, else the last iteration's). Equals `messages` in a full
    /// trace.
    pub offered: usize,
    /// Optimiser steps. Counted per run (the messages of one local search in one phase, as
    /// [`SparseFilter`] delimits them) as the iteration count of its last message, kept at every
    /// level (a run counts from iteration 0, its starting point, or from 1 where the starting
    /// point is not reported), so a sparse trace, which keeps few runs' first messages, counts
    /// what a full one does. Equals the journal's `iterations`.
    pub iterations: usize,
    /// Per phase (by name, in first-seen order).
    pub phases: Vec<(String, PhaseSummary)>,
    /// First f of the trace.
    pub first_f: f64,
    /// Last f of the trace.
    pub last_f: f64,
    /// Smallest finite ‖Tzw‖∞ seen at an iterate (NaN if none).
    pub best_gamma: f64,
    /// Evaluations at the last iteration.
    pub evaluations: usize,
    /// Elapsed CPU seconds at the last iteration.
    pub elapsed_cpu_s: f64,
    /// Final status kind from the result message (`None` if the trace has none).
    pub final_status: Option<String>,
    /// Recorded γ of the final result.
    pub final_gamma: Option<f64>,
    /// The search summary of the final result (starts, best start, CPU time to best, stop
    /// reason), if the result has one.
    pub search: Option<crate::design::SearchSummary>,
}

/// Calls `f(topic, sequence number, message)` for every message of the trace at `path`, in file
/// order.
fn each_message(path: &Path, f: impl FnMut(&str, u32, Value)) -> Result<(), TraceError> {
    let bytes = crate::input::read_capped(path, crate::input::MAX_TRACE_BYTES, "trace file")
        .map_err(|source| TraceError::Io { path: path.to_path_buf(), source })?;
    each_message_in(&bytes, path, f)
}

/// [`each_message`] on the bytes of a trace (`path` names it in errors). The `mcap` reader takes
/// lengths from the file and indexes with them unchecked in places (a trace with 8 bytes
/// overwritten made it panic), so the parse runs under [`crate::panic_guard::catch_quietly`]:
/// a panic is [`TraceError::Damaged`], never a crash. The messages are collected first, so `f`
/// sees none of a file that turns out damaged.
fn each_message_in(bytes: &[u8], path: &Path, mut f: impl FnMut(&str, u32, Value)) -> Result<(), TraceError> {
    let mcap_err = |source| TraceError::Mcap { path: path.to_path_buf(), source };
    let damaged = |message| TraceError::Damaged { path: path.to_path_buf(), message };
    let parsed = crate::panic_guard::catch_quietly(|| -> Result<Vec<(String, u32, Vec<u8>)>, TraceError> {
        check_chunk_sizes(bytes).map_err(damaged)?;
        read_messages(bytes).map_err(mcap_err)
    })
    .map_err(damaged)??;
    for (index, (topic, sequence, data)) in parsed.into_iter().enumerate() {
        let v: Value = serde_json::from_slice(&data).map_err(|source| TraceError::Json {
            path: path.to_path_buf(),
            topic: topic.clone(),
            index,
            source,
        })?;
        f(&topic, sequence, v);
    }
    Ok(())
}

/// Refuses a trace whose chunk declares more than [`crate::input::MAX_TRACE_BYTES`] of
/// uncompressed data: the `mcap` reader allocates the declared size before decompressing, and a
/// damaged size field (8 bytes overwritten) asked for 2·10¹⁴ bytes, an allocation failure that
/// aborts the process (no panic to catch). The writer's chunks hold at most about 64 KiB. The
/// scan reads the records as they are, without decompressing; a record it cannot read makes the
/// file damaged (the decompressing reader parses chunk headers on a path of its own, and would
/// trust a size that this scan never reached).
fn check_chunk_sizes(bytes: &[u8]) -> Result<(), String> {
    let records = mcap::read::LinearReader::new(bytes).map_err(|e| e.to_string())?;
    for record in records {
        match record {
            Ok(mcap::records::Record::Chunk { header, .. })
                if header.uncompressed_size > crate::input::MAX_TRACE_BYTES =>
            {
                return Err(format!(
                    "a chunk declares {} uncompressed bytes, more than the trace limit of {}",
                    header.uncompressed_size,
                    crate::input::MAX_TRACE_BYTES
                ));
            }
            Ok(_) => {}
            Err(e) => return Err(e.to_string()),
        }
    }
    Ok(())
}

/// The trace's messages as (topic, sequence number, data), in file order, with every record's
/// length bounded by [`crate::input::MAX_TRACE_BYTES`] — inside decompressed chunks too, where
/// `mcap::MessageStream` sets no bound and reserves whatever length a damaged record declares
/// (8·10¹⁸ bytes from garbage that zstd decoded: an allocation failure, which aborts).
fn read_messages(bytes: &[u8]) -> Result<Vec<(String, u32, Vec<u8>)>, mcap::McapError> {
    use mcap::records::Record;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let limit = usize::try_from(crate::input::MAX_TRACE_BYTES).unwrap_or(usize::MAX);
    let mut reader = LinearReader::new_with_options(LinearReaderOptions::default().with_record_length_limit(limit));
    let (mut rest, mut topics, mut out) = (bytes, BTreeMap::new(), Vec::new());
    while let Some(event) = reader.next_event() {
        match event? {
            LinearReadEvent::ReadRequest(need) => {
                let len = need.min(rest.len());
                reader.insert(len).copy_from_slice(&rest[..len]);
                reader.notify_read(len);
                rest = &rest[len..];
            }
            LinearReadEvent::Record { data, opcode } => match mcap::parse_record(opcode, data)? {
                Record::Channel(c) => {
                    topics.insert(c.id, c.topic);
                }
                Record::Message { header, data } => {
                    let topic = topics
                        .get(&header.channel_id)
                        .ok_or(mcap::McapError::UnknownChannel(header.sequence, header.channel_id))?;
                    out.push((topic.clone(), header.sequence, data.into_owned()));
                }
                _ => {}
            },
        }
    }
    Ok(out)
}

/// One [`ITER_TOPIC`] message, as read back (the fields the convergence plot needs).
#[derive(Debug, Clone, PartialEq)]
pub struct TraceIteration {
    /// Phase name (`stabilisation`, `optimisation`, `gradient_sampling`, …).
    pub phase: String,
    /// Index of the starting point.
    pub start: usize,
    /// Iteration within the start and phase.
    pub iteration: usize,
    /// Objective value.
    pub f: f64,
    /// CPU seconds since the run started.
    pub elapsed_cpu_s: f64,
}

/// The result message of a trace: the job it is of and the γ its run returned (`None` when the
/// trace has no result message).
#[derive(Debug, Clone, PartialEq)]
pub struct TraceResult {
    /// The job id.
    pub job_id: String,
    /// γ of the returned controller, as the run journaled it.
    pub gamma: f64,
}

/// Every iteration message of a trace, in order.
pub fn read_iterations(path: &Path) -> Result<Vec<TraceIteration>, TraceError> {
    read_run(path).map(|(iterations, _)| iterations)
}

/// [`read_iterations`] with the trace's [`TraceResult`]: whoever draws a trace beside a journal
/// record checks with it that the trace is of that record's run (a rerun journals the job
/// again, and a trace left from an earlier run keeps its name).
pub fn read_run(path: &Path) -> Result<(Vec<TraceIteration>, Option<TraceResult>), TraceError> {
    let mut out = Vec::new();
    let mut result = None;
    each_message(path, |topic, _, v| {
        if topic == RESULT_TOPIC {
            result = v["job_id"]
                .as_str()
                .map(|id| TraceResult { job_id: id.to_string(), gamma: f64_from_json(&v["gamma"]) });
        }
        if topic == ITER_TOPIC {
            out.push(TraceIteration {
                phase: v["phase"].as_str().unwrap_or("?").to_string(),
                start: v["start"].as_u64().unwrap_or(0) as usize,
                iteration: v["iteration"].as_u64().unwrap_or(0) as usize,
                f: f64_from_json(&v["f"]),
                elapsed_cpu_s: f64_from_json(&v["elapsed_cpu_s"]),
            });
        }
    })?;
    Ok((out, result))
}

/// Reads a trace and summarises it.
pub fn summarise(path: &Path) -> Result<TraceSummary, TraceError> {
    let bytes = crate::input::read_capped(path, crate::input::MAX_TRACE_BYTES, "trace file")
        .map_err(|source| TraceError::Io { path: path.to_path_buf(), source })?;
    summarise_bytes(&bytes, path)
}

/// [`summarise`] of the bytes of a trace; `path` names it (in the summary and in errors).
pub fn summarise_bytes(bytes: &[u8], path: &Path) -> Result<TraceSummary, TraceError> {
    let mut s = TraceSummary {
        path: path.to_path_buf(),
        messages: 0,
        offered: 0,
        iterations: 0,
        phases: Vec::new(),
        first_f: f64::NAN,
        last_f: f64::NAN,
        best_gamma: f64::NAN,
        evaluations: 0,
        elapsed_cpu_s: f64::NAN,
        final_status: None,
        final_gamma: None,
        search: None,
    };
    let mut last: Option<(String, u64, u64)> = None; // phase, start, iteration
    each_message_in(bytes, path, |topic, seq, v| {
        s.offered = seq as usize + (topic == ITER_TOPIC) as usize;
        if topic == ITER_TOPIC {
            let f = f64_from_json(&v["f"]);
            if s.messages == 0 {
                s.first_f = f;
            }
            s.messages += 1;
            let phase = v["phase"].as_str().unwrap_or("?").to_string();
            let (start, iteration) = (v["start"].as_u64().unwrap_or(0), v["iteration"].as_u64().unwrap_or(0));
            s.iterations += match &last {
                Some((p, st, i)) if *p == phase && *st == start && iteration > *i => (iteration - i) as usize,
                // A new run: the steps up to this message (its earlier messages may be left out).
                _ => iteration as usize,
            };
            last = Some((phase.clone(), start, iteration));
            s.last_f = f;
            let h = f64_from_json(iter_field(&v, "gamma"));
            if h.is_finite() && !(h >= s.best_gamma) {
                s.best_gamma = h;
            }
            s.evaluations = v["evaluations"].as_u64().unwrap_or(0) as usize;
            s.elapsed_cpu_s = f64_from_json(&v["elapsed_cpu_s"]);
            let idx = match s.phases.iter().position(|(p, _)| *p == phase) {
                Some(i) => i,
                None => {
                    s.phases.push((phase, PhaseSummary { messages: 0, first_f: f, last_f: f }));
                    s.phases.len() - 1
                }
            };
            let ps = &mut s.phases[idx].1;
            ps.messages += 1;
            ps.last_f = f;
        } else if topic == RESULT_TOPIC {
            s.final_status = v["status"]["kind"].as_str().map(str::to_string);
            s.final_gamma = Some(f64_from_json(&v["gamma"]));
            s.search = serde_json::from_value(v["search"].clone()).ok();
        }
    })?;
    Ok(s)
}

impl fmt::Display for TraceSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "trace {}", self.path.display())?;
        let kept = if self.offered > self.messages {
            format!("{} of {} iteration messages kept (sparse)", self.messages, self.offered)
        } else {
            format!("{} messages with the starting points", self.messages)
        };
        writeln!(
            f,
            "  iterations {} ({kept})  evaluations {}  cpu {:.2} s",
            self.iterations, self.evaluations, self.elapsed_cpu_s
        )?;
        writeln!(f, "  f: first {:.6e}  last {:.6e}  best ‖Tzw‖∞ {:.6}", self.first_f, self.last_f, self.best_gamma)?;
        for (name, p) in &self.phases {
            writeln!(f, "  {name:<16} {:>6} msgs  f {:.6e} → {:.6e}", p.messages, p.first_f, p.last_f)?;
        }
        match (&self.final_status, self.final_gamma) {
            (Some(st), Some(g)) => writeln!(f, "  final: {st}  γ = {g:.6}")?,
            (Some(st), None) => writeln!(f, "  final: {st}")?,
            _ => writeln!(f, "  final: none (incomplete trace)")?,
        }
        if let Some(s) = &self.search {
            writeln!(
                f,
                "  search: {} starts, best from start {}, CPU to best {:.2} s ({} evaluations), stopped: {}",
                s.starts,
                s.best_start_label(),
                s.cpu_to_best_s,
                s.evals_to_best,
                s.stop.name()
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Messages carry Unix epoch times (ns), not nanoseconds since the writer started.
    #[test]
    fn log_times_are_unix_epoch_times() {
        let dir = tempfile::tempdir().unwrap();
        let before = unix_now_ns();
        let mut w = TraceWriter::create(dir.path(), "job", ObserverMode::Always).unwrap();
        let (_, t0) = w.stamp();
        let (_, t1) = w.stamp();
        let after = unix_now_ns();
        // (1 ms of slack: the two clocks are read at different moments)
        assert!(before <= t0 && t0 <= t1 && t1 <= after + 1_000_000, "{before} {t0} {t1} {after}");
        assert!(t0 > 1_700_000_000 * 1_000_000_000, "{t0} is not a Unix time in ns (2023 or later)");
        Box::new(w).abandon();
    }
}
