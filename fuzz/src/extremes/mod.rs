//! The structure-aware "extremes" mode (`--extremes`): every numeric field of a target's input (and every
//! numeric flag of its command) is a site; mutant `i` writes one extreme into one site, the file otherwise kept
//! well-formed. The (site, extreme) pairs are enumerated, and consecutive mutant indices walk them with a stride
//! coprime to their number: `--mutants N` with N at least the target's pair count covers every pair once, and a
//! small slice touches many different sites.

pub(crate) mod fields;
mod flags;

use std::collections::BTreeMap;
use std::ffi::OsString;
use std::fs;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use fields::{Field, Format, Place};

use crate::mutant::{vouch, Mutant};
use crate::targets::{Input, Program, Target};

/// A scalar extreme as written: `text` goes into the file or flag as it is.
pub(crate) struct Scalar {
    pub(crate) text: &'static str,
    /// JSON's grammar has it (NaN and infinities have no JSON spelling; TOML, CSV and flags take them).
    pub(crate) in_json: bool,
}

const fn scalar(text: &'static str, in_json: bool) -> Scalar {
    Scalar { text, in_json }
}

/// ±1.8e308 overflows an f64 when read; the largest and smallest f64; zero of both signs; −1; past u64 as a
/// float and u64's maximum as an integer; NaN and the infinities where the syntax allows them.
pub(crate) const SCALARS: [Scalar; 13] = [
    scalar("1.8e308", true),
    scalar("-1.8e308", true),
    scalar("1.7976931348623157e308", true),
    scalar("5e-324", true),
    scalar("0", true),
    scalar("-0", true),
    scalar("-1", true),
    scalar("1e19", true),
    scalar("18446744073709551615", true),
    scalar("4294967296", true),
    scalar("NaN", false),
    scalar("inf", false),
    scalar("-inf", false),
];

/// What an array of numbers becomes.
pub(crate) const ARRAYS: [&str; 4] = ["empty", "a million elements", "one element more", "one element fewer"];

#[derive(Clone, Copy, Debug)]
pub(crate) enum Extreme {
    Scalar(usize),
    Array(usize),
}

impl Extreme {
    pub(crate) fn scalar(self) -> Option<&'static Scalar> {
        match self {
            Extreme::Scalar(i) => Some(&SCALARS[i]),
            Extreme::Array(_) => None,
        }
    }

    pub(crate) fn array(self) -> Option<usize> {
        match self {
            Extreme::Array(i) => Some(i),
            Extreme::Scalar(_) => None,
        }
    }

    fn shown(self) -> String {
        match self {
            Extreme::Scalar(i) => SCALARS[i].text.to_string(),
            Extreme::Array(i) => ARRAYS[i].to_string(),
        }
    }
}

/// Where one extreme goes.
enum Site {
    /// A field of the input file, or of `file` in the input checkpoint directory.
    Field { file: Option<&'static str>, format: Format, field: Field },
    /// A numeric flag of the target's command (`--steps`), set or added.
    Flag(String),
}

impl Site {
    /// The extremes this site can hold.
    fn extremes(&self) -> Vec<Extreme> {
        let json = matches!(self, Site::Field { field: Field { place: Place::Json { .. }, .. }, .. });
        match self {
            Site::Field { field, .. } if field.array => (0..ARRAYS.len()).map(Extreme::Array).collect(),
            _ => (0..SCALARS.len()).filter(|&i| !json || SCALARS[i].in_json).map(Extreme::Scalar).collect(),
        }
    }

    fn shown(&self) -> String {
        match self {
            Site::Field { file: Some(file), field, .. } => format!("{file}: {}", field.shown),
            Site::Field { field, .. } => field.shown.clone(),
            Site::Flag(flag) => format!("flag {flag}"),
        }
    }
}

/// `--fields`: only the sites whose name contains one of these (`metadata.dt`, `--steps`); all when empty.
pub(crate) static FIELDS: OnceLock<Vec<String>> = OnceLock::new();

/// A target's sites with the extremes each holds, read from its seed once per process.
struct Plan {
    sites: Vec<Site>,
    extremes: Vec<Vec<Extreme>>,
    pairs: u64,
}

fn plan(target: &Target, seeds: &Path) -> Arc<Plan> {
    static CACHE: OnceLock<Mutex<BTreeMap<&'static str, Arc<Plan>>>> = OnceLock::new();
    let mut cache = CACHE.get_or_init(Default::default).lock().unwrap();
    cache.entry(target.name).or_insert_with(|| Arc::new(make_plan(target, seeds))).clone()
}

fn make_plan(target: &Target, seeds: &Path) -> Plan {
    let mut sites = Vec::new();
    let mut file_sites = |file: Option<&'static str>, name: &str, path: &Path| {
        if let Some(format) = Format::of(name) {
            let bytes = fs::read(path).unwrap();
            sites.extend(fields::fields(format, &bytes).into_iter().map(|field| Site::Field { file, format, field }));
        }
    };
    match target.input {
        Input::File { seed, .. } => file_sites(None, seed, &seeds.join(seed)),
        Input::Checkpoint { dir, files } => {
            for &file in files {
                file_sites(Some(file), file, &seeds.join(dir).join(file));
            }
        }
        Input::Arg { seed } => {
            let fields = fields::fields(Format::List, seed.as_bytes());
            sites.extend(fields.into_iter().map(|field| Site::Field { file: None, format: Format::List, field }));
        }
    }
    if target.program == Program::Mbrl {
        sites.extend(flags::numeric_flags(target.args).into_iter().map(Site::Flag));
    }
    if let Some(only) = FIELDS.get().filter(|only| !only.is_empty()) {
        sites.retain(|site| only.iter().any(|o| site.shown().contains(o.as_str())));
    }
    let extremes: Vec<Vec<Extreme>> = sites.iter().map(Site::extremes).collect();
    let pairs = extremes.iter().map(|e| e.len() as u64).sum();
    Plan { sites, extremes, pairs }
}

/// The number of (site, extreme) pairs of a target: `--mutants` at least this covers all of them.
pub(crate) fn pairs(target: &Target, seeds: &Path) -> u64 {
    plan(target, seeds).pairs
}

/// Pair `index` of the walk: a stride coprime to the pair count visits each pair once per round, and
/// neighbouring indices land on far-apart sites.
fn pair(index: u64, campaign: u64, pairs: u64) -> u64 {
    let gcd = |mut a: u64, mut b: u64| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let mut stride = (pairs as f64 * 0.618) as u64 | 1;
    while gcd(stride, pairs) != 1 {
        stride += 1;
    }
    let start = (index as u128 + campaign as u128 * 7919) % pairs as u128;
    (start * stride as u128 % pairs as u128) as u64
}

/// Writes extreme mutant `index` of `target` into `work`.
pub(crate) fn prepare(target: &Target, seeds: &Path, work: &Path, index: u64, campaign: u64) -> Mutant {
    let plan = plan(target, seeds);
    let label = index.to_string();
    let mut mutant = crate::mutant::unmutated_copy(target, seeds, work, &label);
    if plan.pairs == 0 {
        mutant.description = "no numeric field or flag: seed unmutated".into();
        return mutant;
    }
    let mut k = pair(index, campaign, plan.pairs);
    let (site, extreme) = plan
        .sites
        .iter()
        .zip(&plan.extremes)
        .find_map(|(site, extremes)| match extremes.get(k as usize) {
            Some(&e) => Some((site, e)),
            None => {
                k -= extremes.len() as u64;
                None
            }
        })
        .unwrap();
    let what = format!("{} = {}", site.shown(), extreme.shown());
    match site {
        Site::Flag(flag) => {
            mutant.flag = Some((flag.clone(), extreme.shown()));
        }
        Site::Field { file, format, field } => {
            let path = match (target.input, file) {
                (Input::Checkpoint { .. }, Some(file)) => mutant.path.join(file),
                _ => mutant.path.clone(),
            };
            let bytes = match target.input {
                Input::Arg { seed } => seed.as_bytes().to_vec(),
                _ => fs::read(&path).unwrap(),
            };
            let Some(new) = fields::apply(*format, &bytes, field, extreme) else {
                mutant.description = format!("{what}: not writable, seed unmutated");
                return mutant;
            };
            match (target.input, file) {
                (Input::Arg { .. }, _) => {
                    mutant.input = OsString::from(String::from_utf8_lossy(&new).into_owned());
                    fs::write(&mutant.path, &new).unwrap();
                }
                (Input::Checkpoint { .. }, Some(file)) => {
                    fs::write(&path, &new).unwrap();
                    if *file != "checkpoint.json" {
                        vouch(&mutant.path, file, &new, true);
                    }
                }
                _ => fs::write(&path, &new).unwrap(),
            }
        }
    }
    mutant.description = what;
    mutant
}

#[cfg(test)]
mod tests {
    use super::*;

    /// As many mutants as pairs visit every pair once, whatever the count and the campaign.
    #[test]
    fn the_walk_covers_every_pair() {
        for pairs in [1u64, 2, 13, 52, 1000, 4096] {
            for campaign in [0, 3] {
                let mut seen: Vec<u64> = (0..pairs).map(|i| pair(i, campaign, pairs)).collect();
                seen.sort();
                assert_eq!(seen, (0..pairs).collect::<Vec<_>>(), "{pairs} pairs, campaign {campaign}");
            }
        }
    }
}
