//! The campaign: settings, the seeds checked, every mutant of every chosen target run over the workers.

use std::collections::BTreeSet;
use std::ffi::OsStr;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::garbage;
use crate::mutant::{prepare, Mutant};
use crate::report::{failures_dir, print_table, save_failure, shown, Counts, Failure};
use crate::runner::{run_bounded, Run, Verdict};
use crate::seeds::{copy_dir, seeds};
use crate::targets::{Input, Target};
use crate::{Cli, DEFAULT_MUTANTS};

pub(crate) struct Settings {
    pub(crate) mutants: u64,
    pub(crate) campaign: u64,
    pub(crate) jobs: usize,
    pub(crate) only: Vec<String>,
    /// Print every run's outcome and first stderr line.
    pub(crate) verbose: bool,
    pub(crate) binary: PathBuf,
    /// The structure-aware extremes mode instead of random mutations.
    pub(crate) extremes: bool,
}

/// The flags, else the environment, else the defaults; the message of an `Err` names the bad variable.
pub(crate) fn settings(cli: &Cli) -> Result<Settings, String> {
    let number = |flag: Option<u64>, name: &str, default: u64| -> Result<u64, String> {
        match (flag, std::env::var(name)) {
            (Some(n), _) => Ok(n),
            (None, Ok(v)) => v.trim().parse().map_err(|_| format!("{name}={v}: not a number")),
            (None, Err(_)) => Ok(default),
        }
    };
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get()) as u64;
    let only = cli.targets.clone().or_else(|| std::env::var("MBRL_FUZZ_TARGETS").ok()).unwrap_or_default();
    let binary = cli
        .bin
        .clone()
        .or_else(|| std::env::var_os("MBRL_FUZZ_BIN").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("target/release/mbrl"));
    Ok(Settings {
        mutants: number(cli.mutants, "MBRL_FUZZ_MUTANTS", DEFAULT_MUTANTS)?,
        campaign: number(cli.seed, "MBRL_FUZZ_SEED", 0)?,
        jobs: number(cli.jobs.map(|j| j as u64), "MBRL_FUZZ_JOBS", cores)?.max(1) as usize,
        only: only.split(',').map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect(),
        verbose: cli.verbose || std::env::var_os("MBRL_FUZZ_VERBOSE").is_some(),
        binary,
        extremes: cli.extremes || std::env::var_os("MBRL_FUZZ_EXTREMES").is_some(),
    })
}

/// Runs mutant `index` (or the seed) of a target and cleans up after it; a failure is saved first. In the
/// extremes mode a clean exit is also checked for silent garbage against the seed's run.
pub(crate) fn run_one(
    target: &Target,
    seeds: &Path,
    index: Option<u64>,
    campaign: u64,
    extremes: bool,
) -> (Run, Option<Mutant>) {
    let work = seeds.join("work").join(target.name);
    fs::create_dir_all(&work).unwrap();
    let mutant = match (extremes, index) {
        (true, Some(index)) => crate::extremes::prepare(target, seeds, &work, index, campaign),
        _ => prepare(target, seeds, &work, index, campaign),
    };
    let label = index.map_or("seed".to_string(), |i| i.to_string());
    let out = work.join(format!("{label}.out"));
    let stdout = work.join(format!("{label}.stdout"));
    let mut run = run_bounded(target, &mutant, seeds, &out, [&stdout, &work.join(format!("{label}.stderr"))]);
    if extremes && run.verdict == Verdict::Ok {
        let mut found = BTreeSet::new();
        garbage::markers(&out, &mut found);
        garbage::markers(&stdout, &mut found);
        if let Input::Checkpoint { .. } = target.input {
            garbage::markers(&mutant.path, &mut found);
        }
        if let Some(new) = garbage::judge(target.name, index.is_none(), found) {
            run.verdict = Verdict::Garbage;
            run.stderr = format!("non-finite numbers in the outputs: {new}\n{}", run.stderr);
        }
    }
    remove(&out);
    remove(&stdout);
    if run.verdict.is_failure() {
        return (run, Some(mutant));
    }
    remove(&mutant.path);
    (run, None)
}

pub(crate) fn remove(path: &Path) {
    let _ = fs::remove_dir_all(path).or_else(|_| fs::remove_file(path));
}

/// Every unmutated seed must be read as intended under the same limits; otherwise the mutants test nothing
/// (and a 4 GiB limit that breaks normal runs is itself a finding).
pub(crate) fn check_seeds(targets: &[&Target], seeds: &Path, extremes: bool) -> Result<(), String> {
    for target in targets {
        let (run, failed) = run_one(target, seeds, None, 0, extremes);
        let expected = if target.seed_is_refused { Verdict::CleanError } else { Verdict::Ok };
        if let Some(mutant) = failed {
            remove(&mutant.path);
        }
        if run.verdict != expected {
            return Err(format!(
                "the unmutated seed of '{}' gave {} instead of {}: {}\n{}",
                target.name,
                run.verdict.describe(),
                expected.describe(),
                shown(target, OsStr::new("<seed>"), None),
                run.stderr
            ));
        }
    }
    Ok(())
}

/// Runs every mutant of the chosen targets on the seeds; `Err` holds the report of the failures.
pub(crate) fn fuzz_every_reader(settings: &Settings, targets: &[&Target]) -> Result<(), String> {
    let seeds = seeds();
    check_seeds(targets, seeds, settings.extremes)?;
    if settings.extremes {
        let pairs: u64 = targets.iter().map(|t| crate::extremes::pairs(t, seeds)).sum();
        eprintln!("fuzz: extremes: {pairs} (field or flag, extreme) pairs over the chosen targets");
    }
    for target in targets {
        remove(&failures_dir().join(target.name));
    }

    // Interleaved so that slow targets spread over the whole run and over the workers.
    let jobs: Vec<(usize, u64)> = (0..settings.mutants).flat_map(|i| (0..targets.len()).map(move |t| (t, i))).collect();
    let next = AtomicUsize::new(0);
    let counts = Mutex::new(vec![Counts::default(); targets.len()]);
    let failures = Mutex::new(Vec::new());
    let start = Instant::now();
    eprintln!(
        "fuzz: {} targets × {} {}mutants, {} parallel runs, --seed {}",
        targets.len(),
        settings.mutants,
        if settings.extremes { "extreme " } else { "" },
        settings.jobs,
        settings.campaign
    );
    std::thread::scope(|scope| {
        for _ in 0..settings.jobs {
            scope.spawn(|| {
                while let Some(&(t, index)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let target = targets[t];
                    let (run, failed) = run_one(target, seeds, Some(index), settings.campaign, settings.extremes);
                    if let Some(mutant) = failed {
                        let saved = save_failure(target, &mutant, index, run.verdict, settings.campaign);
                        remove(&mutant.path);
                        // The command as it reads the saved copy (arguments are their own copy).
                        let input = match target.input {
                            Input::Arg { .. } => mutant.input.clone(),
                            _ => saved.clone().into_os_string(),
                        };
                        let command = shown(target, &input, mutant.flag.as_ref());
                        let stderr = run.stderr.clone();
                        let description = mutant.description;
                        failures.lock().unwrap().push(Failure {
                            target: t,
                            index,
                            verdict: run.verdict,
                            description,
                            command,
                            stderr,
                            saved,
                        });
                    }
                    if settings.verbose {
                        let first = run.stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
                        eprintln!("{} #{index}: {}: {}", target.name, run.verdict.describe(), first);
                    }
                    let mut counts = counts.lock().unwrap();
                    counts[t].add(&run);
                    let done: u64 = counts.iter().map(|c| c.runs).sum();
                    if done.is_multiple_of(500) {
                        eprintln!("fuzz: {done}/{} runs, {:.0} s", jobs.len(), start.elapsed().as_secs_f64());
                    }
                }
            });
        }
    });
    let counts = counts.into_inner().unwrap();
    print_table(targets, &counts);
    eprintln!("fuzz: {} runs in {:.1} s", jobs.len(), start.elapsed().as_secs_f64());

    let mut failures = failures.into_inner().unwrap();
    failures.sort_by_key(|f| (f.target, f.index));
    if failures.is_empty() {
        return Ok(());
    }
    // The reproducers run in a copy of the seeds, which a later campaign regenerates.
    let seeds_copy = failures_dir().join("seeds");
    remove(&seeds_copy);
    copy_dir(seeds, &seeds_copy);
    remove(&seeds_copy.join("work"));
    let report: Vec<String> = failures
        .iter()
        .map(|f| {
            let head: Vec<&str> = f.stderr.lines().filter(|l| !l.trim().is_empty()).take(4).collect();
            format!(
                "{} #{}: {}\n  mutation: {}\n  command:  {}\n  stderr:   {}\n  saved:    {} (rerun: {}.cmd)",
                targets[f.target].name,
                f.index,
                f.verdict.describe(),
                f.description,
                f.command,
                head.join("\n            "),
                f.saved.display(),
                f.saved.with_file_name(f.index.to_string()).display()
            )
        })
        .collect();
    Err(format!("{} of {} mutants failed:\n\n{}", failures.len(), jobs.len(), report.join("\n\n")))
}
