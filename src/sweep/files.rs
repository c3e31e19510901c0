//! The files a plan leaves in its directory: the job lists (all jobs, and one per stage), a Slurm batch
//! script per stage (a job array over its list), `submit.sh` that chains the stages by dependency, and
//! `run-local.sh` for a machine without Slurm. The scripts only read the lists; editing a line edits the job.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::plan::{Plan, StagePlan, PLAN_FILE};
use crate::error::{Error, Result};
use crate::util::atomic::write_atomic;

pub const JOBS_FILE: &str = "jobs.txt";
pub const LOGS_DIR: &str = "logs";

pub fn stage_jobs_file(stage: &str) -> String {
    format!("jobs-{stage}.txt")
}

pub fn stage_sbatch_file(stage: &str) -> String {
    format!("slurm-{stage}.sbatch")
}

/// Writes every file of `plan` into `plan.dir` (which it creates); returns the paths written.
pub fn write_all(plan: &Plan) -> Result<Vec<PathBuf>> {
    let dir = &plan.dir;
    std::fs::create_dir_all(dir.join(LOGS_DIR)).map_err(|e| Error::io(dir, e))?;
    let mut written = Vec::new();
    let mut put = |name: &str, text: String, executable: bool| -> Result<()> {
        let path = dir.join(name);
        write_atomic(&path, |w| w.write_all(text.as_bytes()).map_err(|e| Error::io(&path, e)))?;
        if executable {
            set_executable(&path)?;
        }
        written.push(path);
        Ok(())
    };
    let json = serde_json::to_string_pretty(plan).map_err(|e| Error::config(format!("sweep plan: {e}")))?;
    put(PLAN_FILE, json + "\n", false)?;
    put(JOBS_FILE, lines(plan.stages.iter()), false)?;
    for stage in &plan.stages {
        put(&stage_jobs_file(&stage.name), lines(std::iter::once(stage)), false)?;
        put(&stage_sbatch_file(&stage.name), sbatch(plan, stage), false)?;
    }
    if let [only] = plan.stages.as_slice() {
        put("slurm.sbatch", sbatch(plan, only), false)?;
    }
    put("submit.sh", submit(plan), true)?;
    put("run-local.sh", run_local(plan), true)?;
    Ok(written)
}

fn lines<'a>(stages: impl Iterator<Item = &'a StagePlan>) -> String {
    let mut out = String::new();
    for stage in stages {
        for job in &stage.jobs {
            out.push_str(&job.line);
            out.push('\n');
        }
    }
    out
}

fn set_executable(path: &Path) -> Result<()> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).map_err(|e| Error::io(path, e))
}

/// Single-quoted for bash (the paths are the user's; a quote in them must not end the string).
fn quoted(path: &Path) -> String {
    super::plan::single_quoted(&path.display().to_string())
}

fn sbatch(plan: &Plan, stage: &StagePlan) -> String {
    let slurm = &plan.spec.slurm;
    let last = stage.jobs.len().saturating_sub(1);
    let throttle = slurm.max_running.map(|m| format!("%{m}")).unwrap_or_default();
    let mut s = String::new();
    let _ = writeln!(s, "#!/bin/bash");
    let _ = writeln!(s, "#SBATCH --job-name=mbrl-{}-{}", plan.spec.sweep.name, stage.name);
    let _ = writeln!(s, "#SBATCH --array=0-{last}{throttle}");
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", slurm.cpus.unwrap_or(plan.spec.sweep.threads));
    let _ = writeln!(s, "#SBATCH --mem={}", slurm.memory);
    let _ = writeln!(s, "#SBATCH --time={}", slurm.time);
    if let Some(partition) = &slurm.partition {
        let _ = writeln!(s, "#SBATCH --partition={partition}");
    }
    let _ = writeln!(s, "#SBATCH --signal=B:USR1@{}", slurm.warning_seconds);
    let _ = writeln!(s, "#SBATCH --requeue");
    let _ = writeln!(s, "#SBATCH --open-mode=append");
    let _ = writeln!(s, "#SBATCH --output={}/{LOGS_DIR}/{}-%a.log", plan.dir.display(), stage.name);
    for option in &slurm.options {
        let _ = writeln!(s, "#SBATCH {option}");
    }
    let _ = write!(
        s,
        r#"
# Task i runs line i + 1 of {list}. Slurm's time-limit warning (USR1, {warn} s before the limit) stops
# mbrl, which keeps its last checkpoint; the task then requeues itself, and the rerun of the same line
# resumes the training (a finished job's line is skipped, see --job-dir in `mbrl --help`).
set -u
n=$((SLURM_ARRAY_TASK_ID + 1))
line=$(sed -n "${{n}}p" {list_path})
if [ -z "$line" ]; then
  echo "mbrl sweep: {list} has no line $n" >&2
  exit 1
fi
stop_and_requeue() {{
  kill -TERM "$child" 2>/dev/null
  wait "$child"
  scontrol requeue "${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}"
  exit 0
}}
trap stop_and_requeue USR1
bash -c "exec $line" &
child=$!
wait "$child"
"#,
        list = stage_jobs_file(&stage.name),
        list_path = quoted(&plan.dir.join(stage_jobs_file(&stage.name))),
        warn = slurm.warning_seconds,
    );
    s
}

fn submit(plan: &Plan) -> String {
    let mut s = String::from(
        r#"#!/bin/bash
# Submits this sweep to Slurm: one job array per stage; a stage that follows another waits for it (task i
# for task i when it runs once per upstream run, else for the whole array). With --wait it returns when the
# last stage has ended, prints `mbrl sweep status` and exits non-zero unless every job is done. Other
# arguments go to every sbatch (--partition=…, --account=…).
set -euo pipefail
wait_flag=()
args=()
for arg in "$@"; do
  if [ "$arg" = --wait ]; then wait_flag=(--wait); else args+=("$arg"); fi
done
"#,
    );
    let count = plan.stages.len();
    for (i, stage) in plan.stages.iter().enumerate() {
        let var = format!("job_{i}");
        let dependency = match &stage.after {
            Some(after) => {
                let up = plan.stages.iter().position(|s| &s.name == after).unwrap_or(0);
                let kind = if stage.one_to_one { "aftercorr" } else { "afterok" };
                format!("--kill-on-invalid-dep=yes --dependency={kind}:${{job_{up}%%;*}} ")
            }
            None => String::new(),
        };
        let wait = if i + 1 == count { "\"${wait_flag[@]}\" " } else { "" };
        let last = i + 1 == count;
        let _ = writeln!(
            s,
            "{var}=$(sbatch --parsable {wait}{dependency}\"${{args[@]}}\" {}){}",
            quoted(&plan.dir.join(stage_sbatch_file(&stage.name))),
            if last { " || true" } else { "" }
        );
        let _ = writeln!(s, "echo \"stage {}: job ${{{var}%%;*}} ({} tasks)\"", stage.name, stage.jobs.len());
    }
    let _ = write!(
        s,
        "if [ ${{#wait_flag[@]}} -gt 0 ]; then\n  exec {} sweep status {}\nfi\n",
        quoted(&plan.mbrl),
        quoted(&plan.dir)
    );
    s
}

fn run_local(plan: &Plan) -> String {
    let mut s = String::from(
        r#"#!/bin/bash
# Runs this sweep on this machine without Slurm, stage after stage, N jobs at a time (./run-local.sh N,
# default 1): with GNU parallel when it is installed, else with xargs. Every line is safe to rerun: a
# finished job is skipped, a stopped training resumes. Ends with `mbrl sweep status`.
set -uo pipefail
jobs=${1:-1}
run_list() {
  if command -v parallel >/dev/null; then
    parallel --will-cite -j "$jobs" < "$1"
  else
    tr '\n' '\0' < "$1" | xargs -0 -P "$jobs" -I{} bash -c '{}'
  fi
}
"#,
    );
    for stage in &plan.stages {
        let _ = writeln!(s, "run_list {}", quoted(&plan.dir.join(stage_jobs_file(&stage.name))));
    }
    let _ = writeln!(s, "exec {} sweep status {}", quoted(&plan.mbrl), quoted(&plan.dir));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::{expand, Spec};

    #[test]
    fn scripts_chain_stages_and_quote_paths() {
        let spec = Spec::parse(
            "[[stage]]\nname = \"train\"\ncommand = \"train context --data d.mcap\"\n[stage.grid]\nseed = [0, 1]\n\
             [[stage]]\nname = \"eval\"\nafter = \"train\"\ncommand = \"eval context --model {train} --env toy:inner\"\n\
             [slurm]\nmax_running = 2\n",
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let sweep_dir = dir.path().join("it's");
        let plan = expand(&spec, &sweep_dir, Path::new("/bin/mbrl"), &|_| Ok(()), false).unwrap();
        write_all(&plan).unwrap();
        let read = |name: &str| std::fs::read_to_string(sweep_dir.join(name)).unwrap();
        assert_eq!(read("jobs.txt").lines().count(), 4);
        assert_eq!(read("jobs-eval.txt").lines().count(), 2);
        let sbatch = read("slurm-train.sbatch");
        assert!(sbatch.contains("#SBATCH --array=0-1%2"), "{sbatch}");
        assert!(sbatch.contains(r"it'\''s/jobs-train.txt"), "{sbatch}");
        let submit = read("submit.sh");
        assert!(submit.contains("--dependency=aftercorr:${job_0%%;*}"), "{submit}");
        assert!(!sweep_dir.join("slurm.sbatch").exists(), "two stages need submit.sh, not one sbatch");
        assert!(sweep_dir.join(LOGS_DIR).is_dir(), "Slurm does not create the log directory itself");
        let status = std::process::Command::new("bash").arg("-n").arg(sweep_dir.join("submit.sh")).status().unwrap();
        assert!(status.success(), "submit.sh parses");
        let status =
            std::process::Command::new("bash").arg("-n").arg(sweep_dir.join("slurm-eval.sbatch")).status().unwrap();
        assert!(status.success(), "the batch script parses");
    }
}
