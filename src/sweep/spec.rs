//! The sweep spec a user writes (TOML): stages of mbrl commands, each with a grid of values, and the Slurm
//! resources every task asks for. Unknown keys are refused with their name, so a typo never silently drops
//! a grid axis.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Specs are a few kilobytes; anything larger is not a spec.
const MAX_SPEC_BYTES: u64 = 1 << 20;

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Spec {
    #[serde(default)]
    pub sweep: SweepSection,
    #[serde(rename = "stage", default)]
    pub stages: Vec<StageSpec>,
    #[serde(default)]
    pub slurm: SlurmSpec,
    #[serde(rename = "compare", default)]
    pub compares: Vec<CompareSpec>,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepSection {
    /// Names the Slurm jobs (`mbrl-<name>-<stage>`).
    #[serde(default = "default_name")]
    pub name: String,
    /// Every job's `--threads`: the same count locally and on the cluster, so both give the same bytes.
    #[serde(default = "default_threads")]
    pub threads: u32,
}

impl Default for SweepSection {
    fn default() -> Self {
        SweepSection { name: default_name(), threads: default_threads() }
    }
}

fn default_name() -> String {
    "sweep".to_string()
}

fn default_threads() -> u32 {
    1
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    pub name: String,
    /// The mbrl command without `mbrl`, `--out`, `--seed` or `--threads` (the sweep sets those); `{stage}`
    /// stands for the output of that earlier stage's run this job follows.
    pub command: String,
    /// The stage whose every run this stage follows, once per run (and per value of its own grid).
    pub after: Option<String>,
    /// The name of the command's output inside the job's directory (default by subcommand: `data.mcap`,
    /// `model`, `report`, `calibration.mcap`, `rollout.mcap`).
    pub output: Option<String>,
    /// Axis → values. `seed` sets `--seed`; a key starting with `--` is that flag (true/false: present or
    /// absent); any other key is a trailing `key=value` override.
    #[serde(default)]
    pub grid: BTreeMap<String, Vec<GridValue>>,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum GridValue {
    Bool(bool),
    Int(i64),
    Float(f64),
    Text(String),
}

impl GridValue {
    /// The value as it goes on a command line (floats keep their shortest round-trip form).
    pub fn render(&self) -> String {
        match self {
            GridValue::Bool(b) => b.to_string(),
            GridValue::Int(i) => i.to_string(),
            GridValue::Float(f) => format!("{f:?}"),
            GridValue::Text(s) => s.clone(),
        }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SlurmSpec {
    /// `--cpus-per-task` (default: the sweep's threads).
    pub cpus: Option<u32>,
    /// `--mem`, as Slurm reads it (`2G`, `500M`).
    #[serde(default = "default_memory")]
    pub memory: String,
    /// `--time`, as Slurm reads it (`MM`, `HH:MM:SS`, `D-HH`).
    #[serde(default = "default_time")]
    pub time: String,
    /// At most this many tasks of one array at once (`--array=0-N%M`).
    pub max_running: Option<u32>,
    pub partition: Option<String>,
    /// Seconds before the time limit at which Slurm warns the task, which then stops mbrl (keeping its
    /// checkpoint) and requeues itself to resume.
    #[serde(default = "default_warning")]
    pub warning_seconds: u32,
    /// Further `#SBATCH` options, verbatim (`--account=…`, `--qos=…`).
    #[serde(default)]
    pub options: Vec<String>,
}

impl Default for SlurmSpec {
    fn default() -> Self {
        SlurmSpec {
            cpus: None,
            memory: default_memory(),
            time: default_time(),
            max_running: None,
            partition: None,
            warning_seconds: default_warning(),
            options: Vec::new(),
        }
    }
}

fn default_memory() -> String {
    "4G".to_string()
}

fn default_time() -> String {
    "04:00:00".to_string()
}

fn default_warning() -> u32 {
    120
}

/// A test between two cells of a stage that the report makes (the thesis' comparisons).
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CompareSpec {
    pub stage: String,
    /// A scalar of the runs' summaries, as the report names it (`mean_mse[0]`, `final.loss`).
    pub metric: String,
    /// The cells' grid values; axes left out must have one value in the stage.
    pub a: BTreeMap<String, GridValue>,
    pub b: BTreeMap<String, GridValue>,
    #[serde(default)]
    pub test: TestKind,
    /// The direction tested: a less than b, a greater than b, or either.
    #[serde(default)]
    pub alternative: Direction,
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum TestKind {
    /// Unpaired: Mann-Whitney U.
    #[default]
    MannWhitney,
    /// Paired by seed: Wilcoxon signed rank.
    Wilcoxon,
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    Less,
    Greater,
    #[default]
    TwoSided,
}

impl Spec {
    pub fn read(path: &Path) -> Result<Spec> {
        let bytes = crate::util::bounded_read::read_bounded(path, MAX_SPEC_BYTES)?;
        let text = String::from_utf8(bytes)
            .map_err(|_| Error::bad_file(path, "is not UTF-8 text; expected a TOML sweep spec"))?;
        Spec::parse(&text).map_err(|e| e.at(path))
    }

    pub fn parse(text: &str) -> Result<Spec> {
        let spec: Spec = toml::from_str(text).map_err(|e| {
            let line = e.span().map(|span| 1 + text[..span.start.min(text.len())].matches('\n').count());
            let message = e.message().trim().replace('\n', " ");
            Error::config(match line {
                Some(line) => format!("line {line}: {message}"),
                None => message,
            })
        })?;
        spec.check()?;
        Ok(spec)
    }

    fn check(&self) -> Result<()> {
        let field = |f: String, m: String| Err(Error::config(format!("{f}: {m}")));
        if self.stages.is_empty() {
            return field("stage".into(), "the spec has no [[stage]]; expected at least one".into());
        }
        if !is_name(&self.sweep.name) {
            return field("sweep.name".into(), "expected letters, digits, '-', '_' or '.'".into());
        }
        if self.sweep.threads == 0 || self.sweep.threads > 1024 {
            return field(
                "sweep.threads".into(),
                format!("{} is out of range; expected 1 to 1024", self.sweep.threads),
            );
        }
        for (i, stage) in self.stages.iter().enumerate() {
            let at = format!("stage[{i}]");
            if !is_name(&stage.name) {
                return field(
                    format!("{at}.name"),
                    format!("'{}': expected letters, digits, '-', '_' or '.'", stage.name),
                );
            }
            if self.stages[..i].iter().any(|s| s.name == stage.name) {
                return field(
                    format!("{at}.name"),
                    format!("'{}' names two stages; stage names must differ", stage.name),
                );
            }
            if let Some(after) = &stage.after {
                if !self.stages[..i].iter().any(|s| &s.name == after) {
                    let earlier: Vec<&str> = self.stages[..i].iter().map(|s| s.name.as_str()).collect();
                    return field(
                        format!("{at}.after"),
                        format!("'{after}' is not an earlier stage; expected one of: {}", list_or_none(&earlier)),
                    );
                }
            }
            if let Some(output) = &stage.output {
                if !is_name(output) {
                    return field(format!("{at}.output"), "expected a plain file or directory name".into());
                }
            }
            for (key, values) in &stage.grid {
                if values.is_empty() {
                    return field(format!("{at}.grid.{key}"), "is an empty list; expected at least one value".into());
                }
                if key == "seed" && values.iter().any(|v| !matches!(v, GridValue::Int(i) if *i >= 0)) {
                    return field(format!("{at}.grid.seed"), "expected whole numbers ≥ 0".into());
                }
                if key.is_empty() || key.chars().any(|c| c.is_whitespace() || c == '=') {
                    return field(format!("{at}.grid"), format!("'{key}' is no flag or config key"));
                }
                if let Some(v) = values.iter().find(|v| matches!(v, GridValue::Float(f) if !f.is_finite())) {
                    return field(format!("{at}.grid.{key}"), format!("{} is not a finite number", v.render()));
                }
            }
        }
        let slurm = &self.slurm;
        if slurm.cpus.is_some_and(|c| c == 0 || c > 4096) {
            return field("slurm.cpus".into(), "expected 1 to 4096".into());
        }
        if slurm.max_running == Some(0) {
            return field("slurm.max_running".into(), "expected at least 1".into());
        }
        for (name, value) in [("slurm.memory", &slurm.memory), ("slurm.time", &slurm.time)] {
            if value.is_empty() || !value.chars().all(|c| c.is_ascii_alphanumeric() || c == ':' || c == '-') {
                return field(name.into(), format!("'{value}': expected a Slurm value such as 4G or 04:00:00"));
            }
        }
        if let Some(p) = &slurm.partition {
            if !is_name(p) {
                return field("slurm.partition".into(), format!("'{p}': expected a partition name"));
            }
        }
        if slurm.warning_seconds > 65_535 {
            return field("slurm.warning_seconds".into(), "expected at most 65535 (Slurm's limit)".into());
        }
        for (i, option) in slurm.options.iter().enumerate() {
            if !option.starts_with("--") || option.contains('\n') {
                return field(
                    format!("slurm.options[{i}]"),
                    format!("'{option}': expected one sbatch option like --qos=normal"),
                );
            }
        }
        for (i, compare) in self.compares.iter().enumerate() {
            if !self.stages.iter().any(|s| s.name == compare.stage) {
                return field(
                    format!("compare[{i}].stage"),
                    format!("'{}' is not a stage of this spec", compare.stage),
                );
            }
        }
        Ok(())
    }
}

/// A name that is safe as a path component and in a Slurm job name.
pub fn is_name(text: &str) -> bool {
    !text.is_empty()
        && text.len() <= 64
        && text != "."
        && text != ".."
        && text.chars().all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
}

fn list_or_none(names: &[&str]) -> String {
    if names.is_empty() {
        "none (it is the first stage)".to_string()
    } else {
        names.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_are_named() {
        let err = Spec::parse("[[stage]]\nname = \"a\"\ncommand = \"train context\"\ngird = {}\n").unwrap_err();
        assert!(err.to_string().contains("gird"), "{err}");
        assert!(err.to_string().contains("line 4"), "{err}");
    }

    #[test]
    fn empty_axes_and_forward_references_are_refused() {
        let empty = Spec::parse("[[stage]]\nname = \"a\"\ncommand = \"x\"\n[stage.grid]\nseed = []\n").unwrap_err();
        assert!(empty.to_string().contains("stage[0].grid.seed"), "{empty}");
        let forward = Spec::parse("[[stage]]\nname = \"a\"\ncommand = \"x\"\nafter = \"b\"\n").unwrap_err();
        assert!(forward.to_string().contains("stage[0].after"), "{forward}");
        assert!(Spec::parse("").unwrap_err().to_string().contains("no [[stage]]"));
    }

    #[test]
    fn grid_values_render_as_typed() {
        let spec = Spec::parse(
            "[[stage]]\nname = \"a\"\ncommand = \"x\"\n[stage.grid]\nseed = [0, 2]\nlr = [1e-3, 0.5]\n\"--flag\" = [true, false]\n",
        )
        .unwrap();
        let grid = &spec.stages[0].grid;
        assert_eq!(grid["lr"].iter().map(GridValue::render).collect::<Vec<_>>(), ["0.001", "0.5"]);
        assert_eq!(grid["--flag"][1].render(), "false");
        assert_eq!(grid["seed"][1].render(), "2");
    }
}
