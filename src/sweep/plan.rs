//! A spec expanded into jobs: every stage's grid crossed with the runs it follows, each job with its own
//! directory and one complete `mbrl` command. The plan is saved as `sweep.json`, the one file `status` and
//! `report` read to find the runs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::spec::{GridValue, Spec, StageSpec};
use crate::error::{Error, Result};

pub const PLAN_FILE: &str = "sweep.json";
pub const PLAN_VERSION: u32 = 1;
/// Above this many jobs `plan` asks for `--allow-large`: a typo in a grid multiplies quickly.
pub const LARGE_SWEEP: u64 = 10_000;
/// Never expanded, whatever the flags: the job list alone would be gigabytes.
const MAX_JOBS: u64 = 1_000_000;

/// The subcommands a sweep runs, each with the name its output gets inside the job's directory.
pub const SUBCOMMANDS: &[(&str, Option<&str>)] = &[
    ("collect", Some("data.mcap")),
    ("train", Some("model")),
    ("eval", Some("report")),
    ("calibrate", Some("calibration.mcap")),
    ("plan", Some("rollout.mcap")),
    ("filter", None),
    ("predict", None),
];

/// Flags the sweep sets on every line itself.
const OWNED_FLAGS: &[&str] =
    &["--out", "--seed", "--threads", "--job-dir", "--force", "--resume", "--resume-if-stopped", "--tui", "--hold"];

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct Plan {
    pub version: u32,
    pub spec: Spec,
    /// The sweep directory, absolute, as every line names it.
    pub dir: PathBuf,
    /// The binary every line runs.
    pub mbrl: PathBuf,
    pub stages: Vec<StagePlan>,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct StagePlan {
    pub name: String,
    pub after: Option<String>,
    /// `train`, `eval`, …
    pub subcommand: String,
    /// Job i follows job i of `after` (one job per upstream run): Slurm's `aftercorr` applies.
    pub one_to_one: bool,
    pub jobs: Vec<JobPlan>,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct JobPlan {
    /// Unique within the stage; the directory name under `runs/<stage>/`.
    pub name: String,
    /// The grid values this job runs with, its upstream's first, in naming order (`seed` included).
    pub cell: Vec<(String, String)>,
    pub seed: Option<u64>,
    /// Holds `job.json` (the outcome) and the command's output.
    pub run_dir: PathBuf,
    /// What the command's `--out` names.
    pub output: PathBuf,
    /// Index of the job this one follows in the `after` stage.
    pub upstream: Option<usize>,
    /// The complete command, shell-quoted.
    pub line: String,
}

impl JobPlan {
    /// The grid values without the seed: runs that differ only in seed form one cell of the report.
    pub fn cell_label(&self) -> String {
        let parts: Vec<String> = self
            .cell
            .iter()
            .filter(|(k, _)| k != "seed")
            .map(|(k, v)| format!("{}={v}", k.trim_start_matches('-')))
            .collect();
        if parts.is_empty() {
            "all".to_string()
        } else {
            parts.join(" ")
        }
    }
}

impl Plan {
    pub fn stage(&self, name: &str) -> Option<&StagePlan> {
        self.stages.iter().find(|s| s.name == name)
    }

    pub fn job_count(&self) -> usize {
        self.stages.iter().map(|s| s.jobs.len()).sum()
    }

    pub fn read(dir: &Path) -> Result<Plan> {
        let path = dir.join(PLAN_FILE);
        if !path.is_file() {
            return Err(Error::bad_file(
                dir,
                format!("holds no {PLAN_FILE}; expected a directory made by `mbrl sweep plan`"),
            ));
        }
        let bytes = crate::util::bounded_read::read_bounded(&path, 1 << 30)?;
        let plan: Plan =
            serde_json::from_slice(&bytes).map_err(|e| Error::bad_file(&path, format!("is not a sweep plan: {e}")))?;
        if plan.version != PLAN_VERSION {
            return Err(Error::bad_file(
                &path,
                format!("version {} is not {PLAN_VERSION}, the one this mbrl reads", plan.version),
            ));
        }
        let here = dir.canonicalize().map_err(|e| Error::bad_file(dir, e.to_string()))?;
        Ok(plan.moved_to(&here))
    }

    /// The plan of a sweep directory that now lies at `here` (results copied back from a cluster, a sweep
    /// moved or archived): the run directories and outputs under the recorded directory are read where they
    /// lie now. The job lines keep the paths they were planned with, since they run where they were planned.
    fn moved_to(mut self, here: &Path) -> Plan {
        if self.dir == here {
            return self;
        }
        let rebase = |path: &mut PathBuf| {
            if let Ok(rest) = path.strip_prefix(&self.dir) {
                *path = here.join(rest);
            }
        };
        for job in self.stages.iter_mut().flat_map(|stage| stage.jobs.iter_mut()) {
            rebase(&mut job.run_dir);
            rebase(&mut job.output);
        }
        self.dir = here.to_path_buf();
        self
    }
}

/// Checks one job's command (without the binary) as the command line would parse it; the message on failure.
pub type Validate<'a> = &'a dyn Fn(&[String]) -> std::result::Result<(), String>;

/// Expands `spec` into jobs under `dir` (absolute) run by `mbrl`.
pub fn expand(spec: &Spec, dir: &Path, mbrl: &Path, validate: Validate, allow_large: bool) -> Result<Plan> {
    count_jobs(spec, allow_large)?;
    let mut stages: Vec<StagePlan> = Vec::with_capacity(spec.stages.len());
    for (index, stage) in spec.stages.iter().enumerate() {
        let planned = expand_stage(spec, index, stage, &stages, dir, mbrl, validate)?;
        stages.push(planned);
    }
    Ok(Plan { version: PLAN_VERSION, spec: spec.clone(), dir: dir.to_path_buf(), mbrl: mbrl.to_path_buf(), stages })
}

fn count_jobs(spec: &Spec, allow_large: bool) -> Result<()> {
    let mut counts: BTreeMap<&str, u64> = BTreeMap::new();
    let mut total: u64 = 0;
    for (i, stage) in spec.stages.iter().enumerate() {
        let own = stage.grid.values().try_fold(1u64, |n, values| n.checked_mul(values.len() as u64));
        let upstream = stage.after.as_deref().map_or(Some(1), |after| counts.get(after).copied());
        let count = own.zip(upstream).and_then(|(a, b)| a.checked_mul(b)).filter(|&n| n <= MAX_JOBS);
        let Some(count) = count else {
            return Err(Error::config(format!(
                "stage[{i}].grid: expands to more than {MAX_JOBS} jobs; no sweep this large is planned"
            )));
        };
        total = total.saturating_add(count);
        if total > MAX_JOBS {
            return Err(Error::config(format!(
                "stage[{i}].grid: the sweep expands to more than {MAX_JOBS} jobs; no sweep this large is planned"
            )));
        }
        if total > LARGE_SWEEP && !allow_large {
            return Err(Error::config(format!(
                "stage[{i}].grid: the sweep expands to {total} jobs, more than {LARGE_SWEEP}; add --allow-large if that is meant"
            )));
        }
        counts.insert(&stage.name, count);
    }
    Ok(())
}

/// The axes of a grid in naming order: by key, the seed last (names then read `preset-small_seed-0`).
fn axes(grid: &BTreeMap<String, Vec<GridValue>>) -> Vec<(&String, &Vec<GridValue>)> {
    let mut axes: Vec<_> = grid.iter().filter(|(k, _)| k.as_str() != "seed").collect();
    axes.extend(grid.iter().filter(|(k, _)| k.as_str() == "seed"));
    axes
}

/// Every combination of the axes' values, the last axis fastest.
fn combinations(axes: &[(&String, &Vec<GridValue>)]) -> Vec<Vec<(String, GridValue)>> {
    let mut out = vec![Vec::new()];
    for (key, values) in axes {
        out = out
            .into_iter()
            .flat_map(|prefix| {
                values.iter().map(move |v| {
                    let mut next = prefix.clone();
                    next.push(((*key).clone(), v.clone()));
                    next
                })
            })
            .collect();
    }
    out
}

fn expand_stage(
    spec: &Spec,
    index: usize,
    stage: &StageSpec,
    earlier: &[StagePlan],
    dir: &Path,
    mbrl: &Path,
    validate: Validate,
) -> Result<StagePlan> {
    let at = format!("stage[{index}]");
    let tokens = shlex::split(&stage.command)
        .ok_or_else(|| Error::config(format!("{at}.command: unbalanced quotes in '{}'", stage.command)))?;
    let subcommand = tokens.first().cloned().unwrap_or_default();
    let Some((_, default_output)) = SUBCOMMANDS.iter().find(|(name, _)| *name == subcommand) else {
        let names: Vec<&str> = SUBCOMMANDS.iter().map(|(n, _)| *n).collect();
        return Err(Error::config(format!(
            "{at}.command: '{subcommand}' is not a subcommand a sweep runs; expected one of: {}",
            names.join(", ")
        )));
    };
    for token in &tokens {
        let flag = token.split('=').next().unwrap_or(token);
        if OWNED_FLAGS.contains(&flag) {
            return Err(Error::config(format!(
                "{at}.command: the sweep sets {flag} on every job (--out is the job's directory, --seed comes from the grid's `seed`, --threads from sweep.threads); leave it out"
            )));
        }
    }
    let output_name = match (&stage.output, default_output) {
        (Some(name), _) => name.clone(),
        (None, Some(name)) => name.to_string(),
        (None, None) => {
            return Err(Error::config(format!("{at}.output: `{subcommand}` has no default output name; give one")))
        }
    };
    // Split the command where its trailing key=value overrides begin: the sweep's flags go before them.
    let is_override = |t: &String| !t.starts_with('-') && t.contains('=');
    let split = tokens.iter().rposition(|t| !is_override(t)).map_or(0, |p| p + 1);
    let (head, trailing) = tokens.split_at(split);

    let upstream: Option<&StagePlan> = stage.after.as_deref().and_then(|a| earlier.iter().find(|s| s.name == a));
    let own_axes = axes(&stage.grid);
    if let Some(up) = upstream {
        if let Some(job) = up.jobs.first() {
            if let Some((key, _)) = own_axes.iter().find(|(k, _)| job.cell.iter().any(|(uk, _)| uk == *k)) {
                return Err(Error::config(format!(
                    "{at}.grid.{key}: stage '{}' already varies {key}; a stage that follows it runs with its values",
                    up.name
                )));
            }
        }
    }
    let combos = combinations(&own_axes);
    let parents: Vec<Option<(usize, &JobPlan)>> = match upstream {
        Some(up) => up.jobs.iter().enumerate().map(Some).collect(),
        None => vec![None],
    };
    let mut jobs = Vec::with_capacity(parents.len() * combos.len());
    let mut names: BTreeMap<String, usize> = BTreeMap::new();
    for parent in &parents {
        for combo in &combos {
            let mut cell: Vec<(String, String)> = parent.map(|(_, p)| p.cell.clone()).unwrap_or_default();
            cell.extend(combo.iter().map(|(k, v)| (k.clone(), v.render())));
            let seed = match combo.iter().find(|(k, _)| k == "seed") {
                Some((_, GridValue::Int(s))) => Some(*s as u64),
                _ => parent.and_then(|(_, p)| p.seed),
            };
            let name = job_name(&cell);
            if let Some(previous) = names.insert(name.clone(), jobs.len()) {
                return Err(Error::config(format!(
                    "{at}.grid: jobs {previous} and {} both get the directory name '{name}'; make the grid's values differ in letters or digits",
                    jobs.len()
                )));
            }
            let run_dir = dir.join("runs").join(&stage.name).join(&name);
            let output = run_dir.join(&output_name);
            let mut args: Vec<String> = Vec::with_capacity(tokens.len() + 16);
            for token in head {
                args.push(substitute(token, &at, stage, earlier, spec, parent.map(|(i, _)| i), &cell)?);
            }
            for (key, value) in combo {
                if key == "seed" || !key.starts_with("--") {
                    continue;
                }
                match value {
                    GridValue::Bool(true) => args.push(key.clone()),
                    GridValue::Bool(false) => {}
                    other => {
                        args.push(key.clone());
                        args.push(other.render());
                    }
                }
            }
            args.push("--out".into());
            args.push(output.display().to_string());
            if subcommand == "train" {
                args.push("--resume-if-stopped".into());
            }
            if let Some(seed) = seed {
                args.extend(["--seed".to_string(), seed.to_string()]);
            }
            args.extend(["--threads".to_string(), spec.sweep.threads.to_string()]);
            args.extend(["--job-dir".to_string(), run_dir.display().to_string(), "--force".into(), "--no-tui".into()]);
            for token in trailing {
                args.push(substitute(token, &at, stage, earlier, spec, parent.map(|(i, _)| i), &cell)?);
            }
            for (key, value) in combo {
                if key != "seed" && !key.starts_with("--") {
                    args.push(format!("{key}={}", value.render()));
                }
            }
            validate(&args).map_err(|m| Error::config(format!("{at}.command (job {name}): {m}")))?;
            let mut line_tokens = vec![mbrl.display().to_string()];
            line_tokens.extend(args);
            if line_tokens.iter().any(|t| t.contains('\0')) {
                return Err(Error::config(format!("{at}.command: a value holds a NUL byte")));
            }
            // A first word with `=` would be read as a variable assignment, not as the binary.
            let program = match line_tokens[0].contains('=') {
                true => single_quoted(&line_tokens[0]),
                false => shell_word(&line_tokens[0]),
            };
            let line = std::iter::once(program)
                .chain(line_tokens[1..].iter().map(|t| shell_word(t)))
                .collect::<Vec<_>>()
                .join(" ");
            if line.contains('\n') {
                return Err(Error::config(format!(
                    "{at}: a value or path holds a line break; a job list has one job per line"
                )));
            }
            jobs.push(JobPlan { name, cell, seed, run_dir, output, upstream: parent.map(|(i, _)| i), line });
        }
    }
    Ok(StagePlan {
        name: stage.name.clone(),
        after: stage.after.clone(),
        subcommand,
        one_to_one: upstream.is_some() && combos.len() == 1,
        jobs,
    })
}

/// A word as bash reads it back: plain when every character is one the shell gives no meaning to inside a
/// word (so `lambda_kl=1` and paths stay readable), else single-quoted.
fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_./:=,+@%-".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_string()
    } else {
        single_quoted(word)
    }
}

/// Single-quoted for bash: a quote inside ends the string, adds an escaped quote and starts a new one.
pub(super) fn single_quoted(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// `preset-small_seed-0`: each axis as key-value, characters a path or a shell would trip on replaced.
fn job_name(cell: &[(String, String)]) -> String {
    if cell.is_empty() {
        return "run".to_string();
    }
    let clean = |s: &str| -> String {
        s.trim_start_matches('-')
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '_' })
            .collect()
    };
    let name = cell.iter().map(|(k, v)| format!("{}-{}", clean(k), clean(v))).collect::<Vec<_>>().join("_");
    if name.len() > 200 {
        // Long names pass the file system's 255-byte limit once suffixed; keep their start and a digest.
        let digest =
            name.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
        format!("{}-{digest:016x}", &name[..120])
    } else {
        name
    }
}

/// Replaces `{stage}` with the output of that earlier stage's run this job descends from, and `{axis}` with
/// this job's value on that grid axis (`{env}` for a `--env` axis of an earlier stage).
fn substitute(
    token: &str,
    at: &str,
    stage: &StageSpec,
    earlier: &[StagePlan],
    spec: &Spec,
    parent: Option<usize>,
    cell: &[(String, String)],
) -> Result<String> {
    let mut out = String::with_capacity(token.len());
    let mut rest = token;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after_open = &rest[open + 1..];
        let Some(close) = after_open.find('}') else {
            return Err(Error::config(format!("{at}.command: '{token}' opens a {{ that does not close")));
        };
        let name = &after_open[..close];
        let axis = cell.iter().find(|(k, _)| k.trim_start_matches('-') == name).map(|(_, v)| v.clone());
        let value = ancestor_output(name, stage, earlier, spec, parent).map(|p| p.display().to_string()).or(axis);
        let value = value.ok_or_else(|| {
            let mut names: Vec<String> = ancestors(stage, spec).into_iter().map(str::to_string).collect();
            names.extend(cell.iter().map(|(k, _)| k.trim_start_matches('-').to_string()));
            Error::config(format!(
                "{at}.command: {{{name}}} names no stage this one follows and no grid axis; expected one of: {}",
                if names.is_empty() {
                    "none (the stage has no `after` and no grid)".to_string()
                } else {
                    names.join(", ")
                }
            ))
        })?;
        out.push_str(&value);
        rest = &after_open[close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

fn ancestors<'a>(stage: &'a StageSpec, spec: &'a Spec) -> Vec<&'a str> {
    let mut chain = Vec::new();
    let mut next = stage.after.as_deref();
    while let Some(name) = next {
        chain.push(name);
        next = spec.stages.iter().find(|s| s.name == name).and_then(|s| s.after.as_deref());
    }
    chain
}

fn ancestor_output(
    name: &str,
    stage: &StageSpec,
    earlier: &[StagePlan],
    spec: &Spec,
    parent: Option<usize>,
) -> Option<PathBuf> {
    let mut stage_name = stage.after.as_deref()?;
    let mut index = parent?;
    loop {
        let plan = earlier.iter().find(|s| s.name == stage_name)?;
        let job = plan.jobs.get(index)?;
        if stage_name == name {
            return Some(job.output.clone());
        }
        stage_name = spec.stages.iter().find(|s| s.name == stage_name)?.after.as_deref()?;
        index = job.upstream?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accept(_: &[String]) -> std::result::Result<(), String> {
        Ok(())
    }

    const SPEC: &str = r#"
[sweep]
name = "toy"
[[stage]]
name = "train"
command = "train context --data d.mcap --steps 50 lambda_kl=1"
[stage.grid]
seed = [0, 1, 2]
"--preset" = ["small", "medium"]
[[stage]]
name = "eval"
after = "train"
command = "eval context --model {train} --env toy:inner"
"#;

    #[test]
    fn a_dependent_stage_follows_each_upstream_run() {
        let spec = Spec::parse(SPEC).unwrap();
        let plan = expand(&spec, Path::new("/s"), Path::new("/bin/mbrl"), &accept, false).unwrap();
        let train = &plan.stages[0];
        assert_eq!(train.jobs.len(), 6);
        assert_eq!(train.jobs[0].name, "preset-small_seed-0");
        assert_eq!(train.jobs[1].name, "preset-small_seed-1");
        assert_eq!(
            train.jobs[0].line,
            "/bin/mbrl train context --data d.mcap --steps 50 --preset small --out /s/runs/train/preset-small_seed-0/model \
             --resume-if-stopped --seed 0 --threads 1 --job-dir /s/runs/train/preset-small_seed-0 --force --no-tui lambda_kl=1"
        );
        let eval = &plan.stages[1];
        assert!(eval.one_to_one);
        assert_eq!(eval.jobs.len(), 6);
        assert_eq!(eval.jobs[4].upstream, Some(4));
        assert!(
            eval.jobs[4].line.contains("--model /s/runs/train/preset-medium_seed-1/model"),
            "{}",
            eval.jobs[4].line
        );
        assert!(eval.jobs[4].line.contains("--seed 1"), "the eval inherits its model's seed");
        assert_eq!(eval.jobs[4].cell_label(), "preset=medium");
    }

    #[test]
    fn sweep_owned_flags_unknown_placeholders_and_huge_grids_are_refused() {
        let owned = SPEC.replace("--steps 50", "--steps 50 --out x");
        let err = expand(&Spec::parse(&owned).unwrap(), Path::new("/s"), Path::new("m"), &accept, false).unwrap_err();
        assert!(err.to_string().contains("stage[0].command") && err.to_string().contains("--out"), "{err}");
        let unknown = SPEC.replace("{train}", "{trian}");
        let err = expand(&Spec::parse(&unknown).unwrap(), Path::new("/s"), Path::new("m"), &accept, false).unwrap_err();
        assert!(err.to_string().contains("{trian}") && err.to_string().contains("train"), "{err}");
        let big = SPEC.replace(
            "seed = [0, 1, 2]",
            &format!("seed = [{}]", (0..6000).map(|i| i.to_string()).collect::<Vec<_>>().join(",")),
        );
        let err = expand(&Spec::parse(&big).unwrap(), Path::new("/s"), Path::new("m"), &accept, false).unwrap_err();
        assert!(err.to_string().contains("--allow-large"), "{err}");
    }

    #[test]
    fn words_are_quoted_only_where_bash_needs_it() {
        assert_eq!(shell_word("lambda_kl=1"), "lambda_kl=1");
        assert_eq!(shell_word("/a/b-c/d.mcap"), "/a/b-c/d.mcap");
        assert_eq!(shell_word("it's here"), r"'it'\''s here'");
        assert_eq!(shell_word(""), "''");
        assert_eq!(shell_word("$HOME"), "'$HOME'");
    }

    #[test]
    fn validation_failures_name_the_stage_and_job() {
        let spec = Spec::parse(SPEC).unwrap();
        let refuse =
            |args: &[String]| if args[0] == "eval" { Err("unexpected argument '--bogus'".to_string()) } else { Ok(()) };
        let err = expand(&spec, Path::new("/s"), Path::new("m"), &refuse, false).unwrap_err();
        assert!(err.to_string().contains("stage[1].command (job preset-small_seed-0)"), "{err}");
    }
}
