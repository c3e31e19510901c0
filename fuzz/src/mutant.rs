//! One mutant of a target, written to disk: deterministic in the target, the mutant index and `--seed`.

use std::ffi::OsString;
use std::fs;
use std::os::unix::ffi::OsStringExt;
use std::path::{Path, PathBuf};

use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::mcap_doc::mutate_mcap;
use crate::mutators::{mutate_argument, mutate_document, mutate_png, mutate_safetensors, stacked};
use crate::seeds::copy_dir;
use crate::targets::{Input, Kind, Target};

/// A prepared mutant: where it lives, what its `{in}` is, and what was done to it.
pub(crate) struct Mutant {
    /// File or directory holding the mutant (removed after a clean run, saved after a failure).
    pub(crate) path: PathBuf,
    /// The `{in}` of the command: the mutant's path, or the mutated argument's bytes.
    pub(crate) input: OsString,
    pub(crate) description: String,
    /// A numeric flag set to an extreme (`--steps`, `1e19`): it replaces the flag's value in the command, or is
    /// added to it.
    pub(crate) flag: Option<(String, String)>,
}

/// The generator of mutant `index` of `target`: the same for every run with the same `MBRL_FUZZ_SEED`.
pub(crate) fn mutant_rng(target: &str, index: u64, campaign: u64) -> ChaCha8Rng {
    // FNV-1a: a stable hash of the name, so adding a target changes no other target's mutants.
    let name = target.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
    ChaCha8Rng::seed_from_u64(name ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ campaign.rotate_left(32))
}

/// Writes mutant `index` (or the unmutated seed, for `None`) of `target` into `work`.
pub(crate) fn prepare(target: &Target, seeds: &Path, work: &Path, index: Option<u64>, campaign: u64) -> Mutant {
    let label = index.map_or("seed".to_string(), |i| i.to_string());
    prepare_as(target, seeds, work, index, campaign, &label)
}

/// An unmutated copy of the seed under the name `label`, for a mutant that changes it afterwards: each mutant
/// its own name, so that mutants of one target prepared side by side never share a path.
pub(crate) fn unmutated_copy(target: &Target, seeds: &Path, work: &Path, label: &str) -> Mutant {
    prepare_as(target, seeds, work, None, 0, label)
}

fn prepare_as(target: &Target, seeds: &Path, work: &Path, index: Option<u64>, campaign: u64, label: &str) -> Mutant {
    let mut rng = mutant_rng(target.name, index.unwrap_or(u64::MAX), campaign);
    match target.input {
        Input::File { seed, kind } => {
            let seed_path = seeds.join(seed);
            let ext = seed_path.extension().map_or("bin".into(), |e| e.to_string_lossy().into_owned());
            let (bytes, description) = match (index, kind) {
                (None, _) => (fs::read(&seed_path).unwrap(), "unmutated seed".into()),
                (Some(_), Kind::Mcap) => mutate_mcap(&mut rng, &seed_path),
                (Some(_), Kind::Text) => {
                    let mut bytes = fs::read(&seed_path).unwrap();
                    let what = mutate_document(&mut rng, &mut bytes);
                    (bytes, what)
                }
                (Some(_), Kind::Png) => {
                    let mut bytes = fs::read(&seed_path).unwrap();
                    let what = mutate_png(&mut rng, &mut bytes);
                    (bytes, what)
                }
            };
            let path = work.join(format!("{label}.{ext}"));
            fs::write(&path, bytes).unwrap();
            Mutant { input: path.clone().into_os_string(), path, description, flag: None }
        }
        Input::Checkpoint { dir, files } => {
            let path = work.join(format!("{label}.ckpt"));
            // A fresh copy per mutant: `train --resume` writes into the directory.
            copy_checkpoint(&seeds.join(dir), &path);
            let description = match index {
                None => "unmutated seed".into(),
                Some(_) => {
                    let file = *files.choose(&mut rng).unwrap();
                    mutate_checkpoint(&mut rng, &path, file)
                }
            };
            Mutant { input: path.clone().into_os_string(), path, description, flag: None }
        }
        Input::Arg { seed } => {
            let mut bytes = seed.as_bytes().to_vec();
            let description = match index {
                None => "unmutated seed".into(),
                Some(_) => stacked(&mut rng, &mut bytes, mutate_argument),
            };
            // An argument cannot hold NUL.
            bytes.iter_mut().filter(|b| **b == 0).for_each(|b| *b = 1);
            let path = work.join(format!("{label}.arg"));
            fs::write(&path, &bytes).unwrap();
            Mutant { input: OsString::from_vec(bytes), path, description, flag: None }
        }
    }
}

/// Copies a checkpoint without the loss plot and table, which no reader opens.
pub(crate) fn copy_checkpoint(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let name = entry.file_name();
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &to.join(&name));
        } else if name != "loss.png" && name != "losses.csv" {
            fs::copy(entry.path(), to.join(&name)).unwrap();
        }
    }
}

/// Mutates `file` of the checkpoint in `dir` and, unless it is the manifest, makes the manifest vouch for it.
pub(crate) fn mutate_checkpoint(rng: &mut ChaCha8Rng, dir: &Path, file: &str) -> String {
    let path = dir.join(file);
    let mut bytes = fs::read(&path).unwrap();
    let what = if file.ends_with(".safetensors") {
        mutate_safetensors(rng, &mut bytes)
    } else if file.ends_with(".png") {
        mutate_png(rng, &mut bytes)
    } else {
        mutate_document(rng, &mut bytes)
    };
    fs::write(&path, &bytes).unwrap();
    // A map set's manifest vouches by pixel CRC, which a fuzzer cannot forge without decoding: left as is.
    if file == "checkpoint.json" || !dir.join("checkpoint.json").exists() {
        return format!("{file}: {what}");
    }
    // The manifest records how much of the metrics log belongs to the checkpoint; mostly keep it consistent,
    // sometimes leave the old length to exercise the cut-back on resume.
    let metrics_length = file == "metrics.jsonl" && rng.random_bool(0.8);
    vouch(dir, file, &bytes, metrics_length);
    format!("{file} (manifest updated): {what}")
}

/// Makes the manifest of the checkpoint in `dir` vouch for `bytes` as `file` (size and CRC-32, and with
/// `metrics_length` the length of `metrics.jsonl` it owns).
pub(crate) fn vouch(dir: &Path, file: &str, bytes: &[u8], metrics_length: bool) {
    let manifest_path = dir.join("checkpoint.json");
    let Ok(manifest) = fs::read(&manifest_path) else { return };
    let mut manifest: serde_json::Value = serde_json::from_slice(&manifest).unwrap();
    if let Some(entry) = manifest["files"].get_mut(file) {
        entry["bytes"] = bytes.len().into();
        entry["crc32"] = crc32fast::hash(bytes).into();
    }
    if file == "metrics.jsonl" && metrics_length {
        manifest["metrics_bytes"] = bytes.len().into();
    }
    fs::write(&manifest_path, serde_json::to_vec_pretty(&manifest).unwrap()).unwrap();
}
