//! Finding plants: a benchmark name such as `HE1` means the file `HE1.json` in the plant library;
//! anything that names an existing file (or ends in `.json` or `.mat`) is a path.
//!
//! The library directory is, in order: the environment variable `HINFIX_PLANTS`, `./plants` if it
//! exists (running from a project checkout), else the `plants/` folder of the source tree the
//! binary was built from. Adding a plant is dropping its JSON file into that folder.

use std::path::{Path, PathBuf};

use super::plant::{PlantError, PlantErrorKind};

/// Environment variable that overrides the plant library directory.
pub const PLANTS_ENV: &str = "HINFIX_PLANTS";

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

/// Resolves a plant argument: an existing file or a `.json`/`.mat` path as given, else
/// `<plants_dir>/NAME.json`. An unknown name is an error that lists the shipped plants.
pub fn resolve_plant(name_or_path: &str) -> Result<PathBuf, PlantError> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file()
        || name_or_path.ends_with(".json")
        || name_or_path.ends_with(".mat")
        || name_or_path.contains('/')
    {
        return Ok(as_path.to_path_buf());
    }
    let file = plants_dir().join(format!("{name_or_path}.json"));
    if file.is_file() {
        return Ok(file);
    }
    let names = shipped_plants().unwrap_or_default();
    let hint = names
        .iter()
        .find(|k| k.eq_ignore_ascii_case(name_or_path))
        .map(|k| format!("did you mean `{k}`? "))
        .unwrap_or_default();
    Err(PlantError {
        file,
        kind: PlantErrorKind::UnknownName { name: name_or_path.to_string(), hint, known: names.join(", ") },
    })
}

/// Names of the plants in the library (file stems of `*.json`), sorted.
pub fn shipped_plants() -> std::io::Result<Vec<String>> {
    let mut names: Vec<String> = std::fs::read_dir(plants_dir())?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
}
