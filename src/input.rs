//! Bounded reading of input files. Every file the program reads (plant, controller, campaign,
//! journal, trace) goes through [`read_capped`] with a documented limit, so a wrong argument
//! such as `/dev/zero` or a huge file is a clear error instead of reading until memory runs out.
//! The limits are far above any real file of their kind (the largest shipped plant file is a
//! few hundred kB).

use std::io::{self, Read};
use std::path::Path;

const MIB: u64 = 1 << 20;

/// Largest plant file: 256 MiB (a dense n = 2 500 plant is about 130 MB of JSON).
pub const MAX_PLANT_BYTES: u64 = 256 * MIB;
/// Largest controller file: 64 MiB.
pub const MAX_CONTROLLER_BYTES: u64 = 64 * MIB;
/// Largest controller-structure file (`--structure`, a campaign's `structure`): 64 MiB, as a
/// controller file.
pub const MAX_STRUCTURE_BYTES: u64 = MAX_CONTROLLER_BYTES;
/// Largest campaign file: 1 MiB.
pub const MAX_CAMPAIGN_BYTES: u64 = MIB;
/// Largest journal `runs.jsonl`: 1 GiB (a few hundred thousand records with their controllers).
pub const MAX_JOURNAL_BYTES: u64 = 1024 * MIB;
/// Largest trace file read by `campaign trace`: 256 MiB (a trace holds about 300 bytes per
/// iteration).
pub const MAX_TRACE_BYTES: u64 = 256 * MIB;

/// Reads at most `limit` bytes of `path`; a longer file (or an endless device) is an
/// `InvalidData` error saying so. `what` names the kind of file in that message.
pub fn read_capped(path: &Path, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, "is a directory, not a file"));
    }
    if meta.is_file() && meta.len() > limit {
        return Err(too_large(limit, what));
    }
    let mut buf = Vec::new();
    file.take(limit.saturating_add(1)).read_to_end(&mut buf)?;
    if buf.len() as u64 > limit {
        return Err(match meta.is_file() {
            true => too_large(limit, what),
            // say what it is: `/dev/zero` is a character device, not a huge file
            false => io::Error::new(
                io::ErrorKind::InvalidData,
                format!("is {}, not a regular file, and gave more than the limit for a {what}", kind_of(&meta)),
            ),
        });
    }
    Ok(buf)
}

/// What kind of file system object `meta` describes, for messages: "a directory", "a character
/// device", …
pub fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    match () {
        _ if t.is_dir() => "a directory",
        _ if t.is_file() => "a regular file",
        _ if t.is_char_device() => "a character device",
        _ if t.is_block_device() => "a block device",
        _ if t.is_fifo() => "a FIFO (named pipe)",
        _ if t.is_socket() => "a socket",
        _ => "not a regular file",
    }
}

/// Why `path` cannot be an input file: `None` for a regular file (or a symlink to one), else
/// "does not exist", "is a directory, not a file", "is a character device, not a file", ….
pub fn not_a_file(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => None,
        Ok(m) => Some(format!("is {}, not a file", kind_of(&m))),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Some("does not exist".into()),
        Err(e) => Some(format!("cannot be read: {e}")),
    }
}

/// As [`read_capped`], as UTF-8 text. A leading UTF-8 byte-order mark (which some Windows
/// editors write) is accepted and dropped: JSON and TOML parsers would refuse it with a message
/// that does not name it.
pub fn read_capped_string(path: &Path, limit: u64, what: &str) -> io::Result<String> {
    let mut bytes = read_capped(path, limit, what)?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    String::from_utf8(bytes)
        .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("not UTF-8 text ({})", e.utf8_error())))
}

/// Parses JSON text as `serde_json::from_str` does, but a key that appears twice in one object is
/// an error naming it (at its line and column): serde_json keeps the last value silently, and a
/// structure or plant file with a block given twice must not lose the first one unnoticed.
pub fn parse_json_unique_keys(text: &str) -> Result<serde_json::Value, serde_json::Error> {
    serde_json::from_str::<UniqueKeys>(text).map(|u| u.0)
}

/// A JSON value whose objects have no repeated key ([`parse_json_unique_keys`]).
struct UniqueKeys(serde_json::Value);

impl<'de> serde::Deserialize<'de> for UniqueKeys {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UniqueKeysVisitor).map(UniqueKeys)
    }
}

struct UniqueKeysVisitor;

impl<'de> serde::de::Visitor<'de> for UniqueKeysVisitor {
    type Value = serde_json::Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_i64<E>(self, v: i64) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> Result<Self::Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number))
    }
    fn visit_str<E>(self, v: &str) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_string<E>(self, v: String) -> Result<Self::Value, E> {
        Ok(v.into())
    }
    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }
    fn visit_none<E>(self) -> Result<Self::Value, E> {
        Ok(serde_json::Value::Null)
    }
    fn visit_some<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_any(self)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(UniqueKeys(v)) = seq.next_element()? {
            out.push(v);
        }
        Ok(serde_json::Value::Array(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let mut out = serde_json::Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                return Err(serde::de::Error::custom(format!("the key \"{key}\" is given twice in one object")));
            }
            let UniqueKeys(v) = map.next_value()?;
            out.insert(key, v);
        }
        Ok(serde_json::Value::Object(out))
    }
}

/// The UTF-8 byte-order mark.
const UTF8_BOM: &[u8] = b"\xef\xbb\xbf";

fn too_large(limit: u64, what: &str) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, format!("larger than {} MiB, the limit for a {what}", limit / MIB))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endless_device_and_large_file_are_refused() {
        if Path::new("/dev/zero").exists() {
            let e = read_capped(Path::new("/dev/zero"), 1000, "plant file").unwrap_err();
            assert!(e.to_string().contains("limit for a plant file"), "{e}");
        }
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f");
        std::fs::write(&p, vec![b'x'; 2 * MIB as usize]).unwrap();
        assert!(read_capped(&p, MIB, "campaign file").unwrap_err().to_string().contains("1 MiB"));
        assert_eq!(read_capped(&p, 2 * MIB, "x").unwrap().len(), 2 * MIB as usize);
        assert!(read_capped(dir.path(), MIB, "x").unwrap_err().to_string().contains("directory"));
        std::fs::write(&p, [0xff, 0xfe]).unwrap();
        assert!(read_capped_string(&p, MIB, "x").unwrap_err().to_string().contains("UTF-8"));
    }

    #[test]
    fn a_byte_order_mark_is_dropped_and_non_files_are_named() {
        // A BOM made the JSON error unclear; a directory or /dev/zero as a plant
        // was said not to exist.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.json");
        std::fs::write(&p, b"\xef\xbb\xbf{\"a\": 1}").unwrap();
        assert_eq!(read_capped_string(&p, MIB, "x").unwrap(), "{\"a\": 1}");
        assert_eq!(not_a_file(&p), None);
        assert_eq!(not_a_file(dir.path()).unwrap(), "is a directory, not a file");
        assert_eq!(not_a_file(&dir.path().join("nope")).unwrap(), "does not exist");
        if Path::new("/dev/zero").exists() {
            assert_eq!(not_a_file(Path::new("/dev/zero")).unwrap(), "is a character device, not a file");
            let e = read_capped(Path::new("/dev/zero"), 1000, "plant file").unwrap_err().to_string();
            assert!(e.contains("is a character device") && e.contains("limit for a plant file"), "{e}");
        }
    }
}
