//! A set of terrain maps on disk: PNG files and a manifest (`terrain.json`) that names each map's split and the
//! CRC-32 of its pixels. Maps 0 .. count/2 train, the rest test (the thesis: 0-49 and 50-99 of 100).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::envs::terrain::{generate_map, TerrainMap, TerrainSplit};
use crate::error::{Error, Result};
use crate::run::Monitor;
use crate::util::atomic::write_text;
use crate::util::bounded_read::read_bounded;

pub const MANIFEST: &str = "terrain.json";
const FORMAT: &str = "mbrl-terrain";
const VERSION: u32 = 1;
const MAX_MANIFEST_BYTES: u64 = 16 << 20;
/// A map set holds at most this many maps (each ≈ 0.6 MB in memory).
pub const MAX_MAPS: usize = 10_000;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    format: String,
    version: u32,
    seed: u64,
    command_line: String,
    maps: Vec<ManifestEntry>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestEntry {
    file: String,
    split: TerrainSplit,
    crc32: u32,
}

fn split_of(index: usize, count: usize) -> TerrainSplit {
    if index < count.div_ceil(2) {
        TerrainSplit::Train
    } else {
        TerrainSplit::Test
    }
}

/// Generates `count` maps under `seed` into the new directory `dir`. The set is written into a hidden sibling
/// directory and renamed into place when whole, so `dir` never holds part of a set.
pub fn write_terrain_set(dir: &Path, count: usize, seed: u64, command_line: &str, monitor: &dyn Monitor) -> Result<()> {
    write_terrain_set_over(dir, count, seed, command_line, false, monitor)
}

/// As [`write_terrain_set`]; with `replace`, a directory that holds a map set (its `terrain.json`) is replaced
/// by the new set once that is complete. Any other non-empty directory is refused either way.
pub fn write_terrain_set_over(
    dir: &Path,
    count: usize,
    seed: u64,
    command_line: &str,
    replace: bool,
    monitor: &dyn Monitor,
) -> Result<()> {
    if count == 0 || count > MAX_MAPS {
        return Err(Error::config(format!("--maps must be 1..={MAX_MAPS}, got {count}")));
    }
    match std::fs::read_dir(dir) {
        Ok(mut entries) => {
            if entries.next().is_some() && !(replace && dir.join(MANIFEST).is_file()) {
                return Err(Error::bad_file(dir, "exists and is not empty; give a new directory for the map set"));
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotADirectory => {
            return Err(Error::bad_file(dir, "is a file; expected a directory for the map set"))
        }
        Err(e) => return Err(Error::io(dir, e)),
    }
    let stage = staging_dir(dir)?;
    let result = fill(&stage, count, seed, command_line, monitor).and_then(|()| {
        if dir.exists() {
            let old_set = replace && dir.join(MANIFEST).is_file();
            let removed = if old_set { std::fs::remove_dir_all(dir) } else { std::fs::remove_dir(dir) };
            removed.map_err(|e| Error::io(dir, e))?;
        }
        std::fs::rename(&stage, dir).map_err(|e| Error::io(dir, e))
    });
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&stage);
    }
    result
}

fn staging_dir(dir: &Path) -> Result<PathBuf> {
    let name = dir.file_name().ok_or_else(|| Error::bad_file(dir, "has no directory name"))?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&parent).map_err(|e| Error::io(&parent, e))?;
    let stage = parent.join(format!(".{}.partial-{}", name.to_string_lossy(), std::process::id()));
    if stage.exists() {
        std::fs::remove_dir_all(&stage).map_err(|e| Error::io(&stage, e))?;
    }
    std::fs::create_dir(&stage).map_err(|e| Error::io(&stage, e))?;
    Ok(stage)
}

fn fill(stage: &Path, count: usize, seed: u64, command_line: &str, monitor: &dyn Monitor) -> Result<()> {
    let mut maps = Vec::with_capacity(count);
    for index in 0..count {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        let map = generate_map(seed, index as u64);
        let path = stage.join(&map.name);
        std::fs::write(&path, map.png_bytes()?).map_err(|e| Error::io(&path, e))?;
        maps.push(ManifestEntry { file: map.name.clone(), split: split_of(index, count), crc32: map.crc32 });
        monitor.progress("terrain maps", index as u64 + 1, count as u64);
    }
    let manifest = Manifest { format: FORMAT.into(), version: VERSION, seed, command_line: command_line.into(), maps };
    let text = serde_json::to_string_pretty(&manifest).map_err(|e| Error::data(e.to_string()))?;
    write_text(&stage.join(MANIFEST), &(text + "\n"))
}

/// The maps of a set, in manifest order, optionally only one split. Every map's pixels must match the CRC the
/// manifest recorded, so a set whose files were replaced or mixed with another set's is refused.
pub fn read_terrain_set(dir: &Path, split: Option<TerrainSplit>) -> Result<Vec<TerrainMap>> {
    let manifest_path = dir.join(MANIFEST);
    if !manifest_path.exists() {
        return Err(Error::bad_file(
            dir,
            format!("no {MANIFEST}: not a terrain map set (make one with `mbrl collect --env terrain --maps 100 --out DIR`)"),
        ));
    }
    let bytes = read_bounded(&manifest_path, MAX_MANIFEST_BYTES)?;
    let manifest: Manifest = serde_json::from_slice(&bytes)
        .map_err(|e| Error::bad_file(&manifest_path, format!("not a terrain manifest: {e}")))?;
    if manifest.format != FORMAT || manifest.version != VERSION {
        return Err(Error::bad_file(
            &manifest_path,
            format!("format {} version {}; expected {FORMAT} version {VERSION}", manifest.format, manifest.version),
        ));
    }
    if manifest.maps.is_empty() || manifest.maps.len() > MAX_MAPS {
        return Err(Error::bad_file(
            &manifest_path,
            format!("lists {} maps; expected 1..={MAX_MAPS}", manifest.maps.len()),
        ));
    }
    let mut maps = Vec::new();
    for entry in manifest.maps.iter().filter(|e| split.is_none_or(|s| s == e.split)) {
        // A manifest names files inside its own directory only.
        if entry.file.contains(['/', '\\']) || entry.file.starts_with('.') {
            return Err(Error::bad_file(&manifest_path, format!("map file '{}' is not a plain file name", entry.file)));
        }
        let map = TerrainMap::read_png(&dir.join(&entry.file))?;
        if map.crc32 != entry.crc32 {
            return Err(Error::bad_file(
                &dir.join(&entry.file),
                format!(
                    "pixels do not match the CRC-32 in {MANIFEST} (the file was changed or belongs to another set)"
                ),
            ));
        }
        maps.push(map);
    }
    if maps.is_empty() {
        let which = split.map_or("any".to_string(), |s| s.name().to_string());
        return Err(Error::bad_file(&manifest_path, format!("has no maps of the {which} split")));
    }
    Ok(maps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::NullMonitor;

    #[test]
    fn a_set_round_trips_by_split_and_refuses_tampered_maps() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("maps");
        write_terrain_set(&dir, 4, 3, "test", &NullMonitor).unwrap();
        let train = read_terrain_set(&dir, Some(TerrainSplit::Train)).unwrap();
        let test = read_terrain_set(&dir, Some(TerrainSplit::Test)).unwrap();
        assert_eq!((train.len(), test.len()), (2, 2));
        assert_eq!(train[0], generate_map(3, 0));
        assert_eq!(test[1].name, "map003.png");
        assert_eq!(read_terrain_set(&dir, None).unwrap().len(), 4);

        let err = write_terrain_set(&dir, 4, 3, "test", &NullMonitor).unwrap_err().to_string();
        assert!(err.contains("not empty"), "{err}");

        std::fs::copy(dir.join("map000.png"), dir.join("map003.png")).unwrap();
        let err = read_terrain_set(&dir, Some(TerrainSplit::Test)).unwrap_err().to_string();
        assert!(err.contains("map003.png") && err.contains("CRC"), "{err}");
        let err = read_terrain_set(tmp.path(), None).unwrap_err().to_string();
        assert!(err.contains("terrain.json"), "{err}");
        let leftovers: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "no staging directory is left behind");
    }
}
