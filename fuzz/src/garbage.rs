//! The "silent garbage" check of the extremes mode: a run that exits 0 on an absurd input must not have written
//! non-finite numbers, nor a dataset that mbrl's own readers refuse. Outputs are scanned for the spellings of NaN
//! and infinity, and the MCAP messages (JSON) for a float beyond the ±1e9 every dataset reader accepts (states,
//! actions, rewards, times: no recording holds such a value); what the unmutated seed's run writes too is not
//! counted. JSON's `null` (what serde writes for a non-finite float) is not counted: too many
//! fields are legitimately absent (no validation split, no best step), and a NaN would be caught as a diverged
//! loss or in the CSV tables and reports beside it.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

/// Records the seed run's markers (`seed`), or returns the markers of a mutant's run that its seed's run had
/// not, as a list.
pub(crate) fn judge(target: &'static str, seed: bool, found: BTreeSet<String>) -> Option<String> {
    static BASELINE: OnceLock<Mutex<BTreeMap<&'static str, BTreeSet<String>>>> = OnceLock::new();
    let mut baseline = BASELINE.get_or_init(Default::default).lock().unwrap();
    if seed {
        baseline.insert(target, found);
        return None;
    }
    let seen = baseline.get(target).cloned().unwrap_or_default();
    let new: Vec<String> = found.difference(&seen).cloned().collect();
    (!new.is_empty()).then(|| new.join(", "))
}

/// The non-finite spellings found in the files under `path` (text formats and MCAP messages and metadata).
pub(crate) fn markers(path: &Path, found: &mut BTreeSet<String>) {
    if path.is_dir() {
        let Ok(entries) = fs::read_dir(path) else { return };
        for entry in entries.flatten() {
            markers(&entry.path(), found);
        }
        return;
    }
    let ext = path.extension().map_or(String::new(), |e| e.to_string_lossy().into_owned());
    match ext.as_str() {
        "csv" | "json" | "jsonl" | "md" | "txt" | "toml" | "tsv" => {
            if let Ok(bytes) = fs::read(path) {
                scan(&String::from_utf8_lossy(&bytes), found);
            }
        }
        "mcap" => {
            if let Ok(bytes) = fs::read(path) {
                scan_mcap(&bytes, found);
            }
        }
        _ => {}
    }
}

fn scan_mcap(bytes: &[u8], found: &mut BTreeSet<String>) {
    use mcap::records::Record;
    let Ok(records) = mcap::read::ChunkFlattener::new(bytes) else { return };
    for record in records {
        match record {
            Ok(Record::Message { data, .. }) => {
                let text = String::from_utf8_lossy(&data);
                scan(&text, found);
                if let Ok(value) = serde_json::from_str::<serde_json::Value>(&text) {
                    scan_magnitudes(&value, found);
                }
            }
            Ok(Record::Metadata(m)) => m.metadata.values().for_each(|v| scan(v, found)),
            Ok(_) => {}
            Err(_) => return,
        }
    }
}

/// The largest magnitude a dataset reader accepts in a recorded value.
const RECORDED_LIMIT: f64 = mbrl::data::dataset::RECORDED.hi;

/// Marks a float (not an integer: ids, steps and seeds may be large) beyond [`RECORDED_LIMIT`] anywhere in a
/// message.
fn scan_magnitudes(value: &serde_json::Value, found: &mut BTreeSet<String>) {
    match value {
        serde_json::Value::Number(n) if n.is_f64() && n.as_f64().is_some_and(|x| x.abs() > RECORDED_LIMIT) => {
            found.insert(format!("a dataset value beyond ±{RECORDED_LIMIT:e}"));
        }
        serde_json::Value::Array(items) => items.iter().for_each(|v| scan_magnitudes(v, found)),
        serde_json::Value::Object(fields) => fields.values().for_each(|v| scan_magnitudes(v, found)),
        _ => {}
    }
}

/// Words spelling a non-finite number (`NaN`, `-inf`, `Infinity`).
pub(crate) fn scan(text: &str, found: &mut BTreeSet<String>) {
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
    for token in text.split(|c: char| !word(c)) {
        let lower = token.to_ascii_lowercase();
        if matches!(lower.as_str(), "nan" | "inf" | "infinity") {
            found.insert(lower);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_spellings() {
        let mut found = BTreeSet::new();
        scan("step,loss\n1,NaN\n2,-inf\n", &mut found);
        assert_eq!(found.iter().collect::<Vec<_>>(), ["inf", "nan"]);
        let mut found = BTreeSet::new();
        scan("{\"information\":1,\"nano\":2,\"x\":null,\"y\":\"a.inf\"}", &mut found);
        assert!(found.is_empty(), "{found:?}");
    }

    /// The whole path: a dataset mbrl writes with one absurd action is marked, the same dataset without it not.
    #[test]
    fn an_absurd_recorded_value_in_a_written_dataset_is_marked() {
        use mbrl::data::collect::{replay, ReplaySettings};
        let dir = std::env::temp_dir().join(format!("mbrl-fuzz-garbage-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        let found_in = |action: f64| {
            let settings = ReplaySettings {
                env: mbrl::envs::parse_env("pendulum").unwrap(),
                actions: vec![vec![0.5], vec![action]],
                init_state: None,
                instance_seed: None,
                seed: 0,
                command_line: String::new(),
            };
            let path = dir.join(format!("{action:e}.mcap"));
            mbrl::data::write_dataset(&path, &replay(&settings).unwrap()).unwrap();
            let mut found = BTreeSet::new();
            markers(&path, &mut found);
            found
        };
        assert_eq!(found_in(1e300).len(), 1);
        assert!(found_in(1.5).is_empty());
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn absurd_floats_in_messages_but_not_large_integers() {
        let mut found = BTreeSet::new();
        scan_magnitudes(&serde_json::json!({"t": 18446744073709551615u64, "state": [0.5, -2e9]}), &mut found);
        assert_eq!(found.len(), 1, "{found:?}");
        let mut found = BTreeSet::new();
        scan_magnitudes(&serde_json::json!({"t": 18446744073709551615u64, "state": [0.5, 1e9]}), &mut found);
        assert!(found.is_empty(), "{found:?}");
    }
}
