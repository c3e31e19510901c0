//! What a campaign reports: counts per target, and each failure saved with a script that reruns it.

use std::ffi::{OsStr, OsString};
use std::fs;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};

use crate::mutant::Mutant;
use crate::runner::{command_line, Run, Verdict};
use crate::seeds::{copy_dir, work, SELF_SNAPSHOT, SNAPSHOT};
use crate::targets::{Input, Program, Target};
use crate::MEMORY_LIMIT_KIB;

/// One failing mutant, as reported and saved.
pub(crate) struct Failure {
    pub(crate) target: usize,
    pub(crate) index: u64,
    pub(crate) verdict: Verdict,
    pub(crate) description: String,
    pub(crate) command: String,
    pub(crate) stderr: String,
    pub(crate) saved: PathBuf,
}

#[derive(Default, Clone, Copy)]
pub(crate) struct Counts {
    pub(crate) runs: u64,
    pub(crate) ok: u64,
    pub(crate) errors: u64,
    pub(crate) panics: u64,
    pub(crate) aborts: u64,
    pub(crate) hangs: u64,
    pub(crate) unclean: u64,
    pub(crate) garbage: u64,
    pub(crate) seconds: f64,
}

impl Counts {
    pub(crate) fn add(&mut self, run: &Run) {
        self.runs += 1;
        self.seconds += run.seconds;
        match run.verdict {
            Verdict::Ok => self.ok += 1,
            Verdict::CleanError => self.errors += 1,
            Verdict::Panic => self.panics += 1,
            Verdict::Abort(_) => self.aborts += 1,
            Verdict::Hang => self.hangs += 1,
            Verdict::Unclean(_) => self.unclean += 1,
            Verdict::Garbage => self.garbage += 1,
        }
    }
}

pub(crate) fn failures_dir() -> PathBuf {
    work().join("fuzz-failures")
}

/// Shell-quotes one argument where needed (bytes kept as they are).
pub(crate) fn quote(arg: &OsStr) -> Vec<u8> {
    let plain = |b: &u8| b.is_ascii_alphanumeric() || b"-_.,/:=+%@".contains(b);
    if !arg.is_empty() && arg.as_bytes().iter().all(plain) {
        return arg.as_bytes().to_vec();
    }
    let mut out = b"'".to_vec();
    for &b in arg.as_bytes() {
        if b == b'\'' {
            out.extend_from_slice(b"'\\''");
        } else {
            out.push(b);
        }
    }
    out.push(b'\'');
    out
}

/// The command as a reader would type it, for the report.
pub(crate) fn shown(target: &Target, input: &OsStr, flag: Option<&(String, String)>) -> String {
    let (program, args) = command_line(target, input, flag, Path::new("OUT"));
    let name = if target.program == Program::Mbrl { "mbrl".into() } else { program.display().to_string() };
    let args: Vec<String> = args.iter().map(|a| String::from_utf8_lossy(&quote(a)).into_owned()).collect();
    format!("{name} {}", args.join(" "))
}

/// Saves a failing mutant next to a script that reruns it in `fuzz-failures/seeds` with the same limits.
pub(crate) fn save_failure(target: &Target, mutant: &Mutant, index: u64, verdict: Verdict, campaign: u64) -> PathBuf {
    let dir = failures_dir().join(target.name);
    fs::create_dir_all(&dir).unwrap();
    let saved = dir.join(mutant.path.file_name().unwrap());
    let _ = fs::remove_dir_all(&saved);
    if mutant.path.is_dir() {
        copy_dir(&mutant.path, &saved);
    } else {
        fs::copy(&mutant.path, &saved).unwrap();
    }
    let relative = Path::new("..").join(target.name).join(saved.file_name().unwrap());
    let (input, setup): (OsString, &str) = match target.input {
        // `train --resume` writes into the checkpoint: run on a copy so the reproducer stays intact.
        Input::Checkpoint { .. } => {
            (OsString::from("$ckpt"), "ckpt=$(mktemp -d)/ckpt\ncp -r \"$here/$name\" \"$ckpt\"\n")
        }
        Input::Arg { .. } => (OsString::from_vec(fs::read(&mutant.path).unwrap()), ""),
        Input::File { .. } => (relative.clone().into_os_string(), ""),
    };
    let (_, args) = command_line(target, &input, mutant.flag.as_ref(), Path::new("fuzz-out"));
    let mut script = format!(
        "#!/bin/sh\n# mbrl fuzz reproducer: target {}, mutant {index} (mbrl-fuzz --seed {campaign})\n# mutation: {}\n\
         # verdict: {}\n# Runs in fuzz-failures/seeds with the harness's limits and the binary that failed\n\
         # (seeds/{SNAPSHOT}); MBRL=/abs/path/to/mbrl tests another build, e.g. MBRL=$PWD/target/release/mbrl.\n\
         here=$(cd \"$(dirname \"$0\")\" && pwd)\nname={}\ncd \"$here/../seeds\" || exit 1\nrm -rf fuzz-out\n{setup}\
         ulimit -v {MEMORY_LIMIT_KIB}\n",
        target.name,
        mutant.description.replace('\n', "\\n"),
        verdict.describe(),
        saved.file_name().unwrap().to_string_lossy(),
    )
    .into_bytes();
    if target.program == Program::BoardSetReader {
        script.extend_from_slice(format!("exec \"$here/../seeds/{SELF_SNAPSHOT}\"").as_bytes());
    } else {
        // By default the very binary that failed (the copy next to the seeds).
        script.extend_from_slice(format!("exec \"${{MBRL:-$here/../seeds/{SNAPSHOT}}}\"").as_bytes());
    }
    for arg in &args {
        script.push(b' ');
        // `$ckpt` must expand; everything else is quoted.
        if arg == "$ckpt" {
            script.extend_from_slice(b"\"$ckpt\"")
        } else {
            script.extend_from_slice(&quote(arg))
        }
    }
    script.push(b'\n');
    let script_path = dir.join(format!("{index}.cmd"));
    fs::write(&script_path, script).unwrap();
    use std::os::unix::fs::PermissionsExt;
    fs::set_permissions(&script_path, fs::Permissions::from_mode(0o755)).unwrap();
    saved
}

pub(crate) fn print_table(targets: &[&Target], counts: &[Counts]) {
    eprintln!(
        "\n{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>7} {:>8}",
        "target", "runs", "ok", "errors", "panics", "aborts", "hangs", "unclean", "garbage", "s/run"
    );
    let mut total = Counts::default();
    for (target, c) in targets.iter().zip(counts) {
        eprintln!(
            "{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>7} {:>8.3}",
            target.name,
            c.runs,
            c.ok,
            c.errors,
            c.panics,
            c.aborts,
            c.hangs,
            c.unclean,
            c.garbage,
            c.seconds / c.runs.max(1) as f64
        );
        for (sum, part) in [
            (&mut total.runs, c.runs),
            (&mut total.ok, c.ok),
            (&mut total.errors, c.errors),
            (&mut total.panics, c.panics),
            (&mut total.aborts, c.aborts),
            (&mut total.hangs, c.hangs),
            (&mut total.unclean, c.unclean),
            (&mut total.garbage, c.garbage),
        ] {
            *sum += part;
        }
        total.seconds += c.seconds;
    }
    eprintln!(
        "{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>7} {:>8.3}\n",
        "total",
        total.runs,
        total.ok,
        total.errors,
        total.panics,
        total.aborts,
        total.hangs,
        total.unclean,
        total.garbage,
        total.seconds / total.runs.max(1) as f64
    );
}
