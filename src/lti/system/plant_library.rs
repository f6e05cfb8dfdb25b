//! Finding plants: a benchmark name such as `HE1` means the file `HE1.json` in the plant library;
//! anything that names an existing file (or ends in `.json`, `.json.gz` or `.mat`) is a path.
//!
//! The library directory is, in order: the environment variable `HINFIX_PLANTS`, `./plants` if it
//! exists (running from a project checkout), else the `plants/` folder of the source tree the
//! binary was built from. Adding a plant is dropping its JSON file into that folder.
//!
//! The library is that folder and its direct subfolders (collections such as `compleib/`): a
//! plant is `NAME.json`, or `NAME.json.gz` (the same JSON, gzip-compressed; the large COMPleib
//! plants are stored so). A name in the top folder comes first; two plants of one name in two
//! subfolders are an error when that name is asked for, never a silent choice.

use std::path::{Path, PathBuf};

use super::plant::{is_gzip_json_path, PlantError, PlantErrorKind};

/// Environment variable that overrides the plant library directory.
pub const PLANTS_ENV: &str = "HINFIX_PLANTS";

/// File name endings of library plants: plain and gzip-compressed JSON.
const PLANT_SUFFIXES: [&str; 2] = [".json", ".json.gz"];

/// The plant library directory (see the module docs for the lookup order).
pub fn plants_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os(PLANTS_ENV) {
        return PathBuf::from(dir);
    }
    let local = Path::new("plants");
    if local.is_dir() {
        return local.to_path_buf();
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("plants")
}

/// One plant file of the library.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LibraryPlant {
    /// The name asked for (`AC8`): the file name without `.json` or `.json.gz`.
    pub name: String,
    /// The subfolder it lives in (`compleib`), or `None` for the top folder.
    pub collection: Option<String>,
    /// The file.
    pub path: PathBuf,
}

/// Every plant of the library: the top folder first, then each subfolder, each sorted by name.
pub fn library_plants() -> std::io::Result<Vec<LibraryPlant>> {
    let dir = plants_dir();
    let mut all = plants_in(&dir, None)?;
    for (name, path) in collections(&dir)? {
        all.extend(plants_in(&path, Some(&name))?);
    }
    Ok(all)
}

/// The collections of the library folder `dir` (its direct subfolders), as (name, path), sorted.
fn collections(dir: &Path) -> std::io::Result<Vec<(String, PathBuf)>> {
    let mut subdirs: Vec<(String, PathBuf)> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .filter_map(|p| Some((p.file_name()?.to_str()?.to_string(), p)))
        .collect();
    subdirs.sort();
    Ok(subdirs)
}

/// The plant files directly in `dir`, sorted by name.
fn plants_in(dir: &Path, collection: Option<&str>) -> std::io::Result<Vec<LibraryPlant>> {
    let mut found: Vec<LibraryPlant> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .filter_map(|path| {
            let file = path.file_name()?.to_str()?;
            let name = PLANT_SUFFIXES.iter().find_map(|s| file.strip_suffix(s))?.to_string();
            Some(LibraryPlant { name, collection: collection.map(str::to_string), path })
        })
        .collect();
    found.sort_by(|a, b| a.name.cmp(&b.name).then(a.path.cmp(&b.path)));
    Ok(found)
}

/// Resolves a plant argument: an existing file or a `.json`/`.json.gz`/`.mat` path as given, else
/// the library plant of that name. An unknown name is an error that lists the library's plants.
pub fn resolve_plant(name_or_path: &str) -> Result<PathBuf, PlantError> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file()
        || name_or_path.ends_with(".json")
        || is_gzip_json_path(as_path)
        || name_or_path.ends_with(".mat")
        || name_or_path.contains('/')
    {
        return Ok(as_path.to_path_buf());
    }
    let file = plants_dir().join(format!("{name_or_path}.json"));
    if file.is_file() {
        return Ok(file);
    }
    let all = library_plants().unwrap_or_default();
    let matches: Vec<&LibraryPlant> = all.iter().filter(|p| p.name == name_or_path).collect();
    match matches.as_slice() {
        [one] => return Ok(one.path.clone()),
        [first, ..] if first.collection.is_none() => return Ok(first.path.clone()),
        [] => {}
        several => {
            let files: Vec<String> = several.iter().map(|p| p.path.display().to_string()).collect();
            return Err(PlantError {
                file,
                kind: PlantErrorKind::AmbiguousName { name: name_or_path.to_string(), files: files.join(", ") },
            });
        }
    }
    let mut names: Vec<String> = all.into_iter().map(|p| p.name).collect();
    names.sort();
    names.dedup();
    let hint = names
        .iter()
        .find(|k| k.eq_ignore_ascii_case(name_or_path))
        .map(|k| format!("did you mean `{k}`? "))
        .or_else(|| {
            listed_as_missing(name_or_path).map(|list| {
                format!("`{name_or_path}` is listed in {} as a plant whose data do not ship; ", list.display())
            })
        })
        .unwrap_or_default();
    // The whole list only while it is short: the library holds about 150 plants.
    let dir = plants_dir();
    let known = match names.len() {
        // a library folder that is not there (HINFIX_PLANTS pointing nowhere) is named as such
        0 if !dir.is_dir() => format!(
            "none: the library folder {} is not a folder{}",
            dir.display(),
            if std::env::var_os(PLANTS_ENV).is_some() { format!(" (from {PLANTS_ENV})") } else { String::new() }
        ),
        0..=KNOWN_LISTED => names.join(", "),
        n => format!("{n} plants, listed by `campaign plants`"),
    };
    Err(PlantError { file, kind: PlantErrorKind::UnknownName { name: name_or_path.to_string(), hint, known } })
}

/// The `MISSING.md` of the library folder or of one of its collections that names `name` as a
/// whole word (letters, digits and `_` around it do not count), if any: the plants the library
/// lists as missing (no public data, or left out for size) are explained there.
fn listed_as_missing(name: &str) -> Option<PathBuf> {
    let dir = plants_dir();
    let folders = std::iter::once(dir.clone()).chain(collections(&dir).ok()?.into_iter().map(|(_, path)| path));
    folders
        .map(|folder| folder.join(MISSING_LIST))
        .find(|list| std::fs::read_to_string(list).is_ok_and(|text| names_word(&text, name)))
}

/// The file of a library folder that lists its missing plants.
const MISSING_LIST: &str = "MISSING.md";

/// Whether `text` holds `word` with no letter, digit or `_` right before or after it.
fn names_word(text: &str, word: &str) -> bool {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    !word.is_empty()
        && text.match_indices(word).any(|(i, _)| {
            !text[..i].chars().next_back().is_some_and(is_word)
                && !text[i + word.len()..].chars().next().is_some_and(is_word)
        })
}

/// Up to this many library names are listed in an unknown-name error.
const KNOWN_LISTED: usize = 20;

/// Names of the plants in the library (top folder and collections), sorted, each once.
pub fn shipped_plants() -> std::io::Result<Vec<String>> {
    let mut names: Vec<String> = library_plants()?.into_iter().map(|p| p.name).collect();
    names.sort();
    names.dedup();
    Ok(names)
}
