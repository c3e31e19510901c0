//! Running one command under the memory and time bounds, and classifying how it ended.

use std::ffi::{OsStr, OsString};
use std::fs;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use crate::mutant::Mutant;
use crate::seeds::{seeds, SELF_SNAPSHOT, SNAPSHOT};
use crate::targets::{Program, Target};
use crate::{MEMORY_LIMIT_KIB, TIME_LIMIT};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Verdict {
    Ok,
    CleanError,
    Panic,
    Abort(i32),
    Hang,
    Unclean(i32),
    /// Exit 0 on an extreme input, with NaN or infinity in the outputs where the seed's run had none.
    Garbage,
}

impl Verdict {
    pub(crate) fn is_failure(self) -> bool {
        !matches!(self, Verdict::Ok | Verdict::CleanError)
    }

    pub(crate) fn describe(self) -> String {
        match self {
            Verdict::Ok => "ok".into(),
            Verdict::CleanError => "clean error".into(),
            Verdict::Panic => "panic".into(),
            Verdict::Abort(signal) => format!("abort (signal {signal})"),
            Verdict::Hang => format!("hang (over {} s)", TIME_LIMIT.as_secs()),
            Verdict::Unclean(code) => format!("unclean exit {code} without an 'error:' line"),
            Verdict::Garbage => "silent garbage: exit 0 with non-finite numbers in its outputs".into(),
        }
    }
}

/// `outcomes`: exit codes the command documents as results rather than errors (`sweep status` exits 1 when a
/// job failed and 3 when some are unfinished); they count as ok.
pub(crate) fn classify(status: Option<ExitStatus>, stderr: &str, outcomes: &[i32]) -> Verdict {
    let Some(status) = status else { return Verdict::Hang };
    if let Some(signal) = status.signal() {
        return Verdict::Abort(signal);
    }
    let code = status.code().unwrap_or(-1);
    if code == 101 || stderr.contains("panicked") {
        return Verdict::Panic;
    }
    // Warnings (`jobs::warn`) may come before the error that ended the run.
    let first = stderr.lines().find(|l| !l.trim().is_empty() && !l.starts_with("warning:")).unwrap_or("");
    match code {
        0 => Verdict::Ok,
        code if outcomes.contains(&code) && !first.starts_with("error:") => Verdict::Ok,
        1 | 2 if first.starts_with("error:") => Verdict::CleanError,
        _ => Verdict::Unclean(code),
    }
}

/// The program and arguments of a run of `target` on `input`, writing to `out`.
pub(crate) fn command_line(
    target: &Target,
    input: &OsStr,
    flag: Option<&(String, String)>,
    out: &Path,
) -> (PathBuf, Vec<OsString>) {
    let (program, mut args): (_, Vec<OsString>) = match target.program {
        Program::Mbrl => (seeds().join(SNAPSHOT), ["--threads", "1", "-q"].iter().map(OsString::from).collect()),
        Program::BoardSetReader => (seeds().join(SELF_SNAPSHOT), Vec::new()),
    };
    for arg in target.args.split_whitespace() {
        // `{in}` may sit inside an argument (`--board={in}`); the mutant's bytes go in as they are.
        let arg = arg.replace("{out}", &out.to_string_lossy());
        let (before, after) = arg.split_once("{in}").map_or((arg.as_str(), None), |(b, a)| (b, Some(a)));
        let mut bytes = before.as_bytes().to_vec();
        if let Some(after) = after {
            bytes.extend_from_slice(input.as_bytes());
            bytes.extend_from_slice(after.as_bytes());
        }
        args.push(OsString::from_vec(bytes));
    }
    if let Some((name, value)) = flag {
        // `--name=value` whatever the value: a negative number must not read as a flag.
        let set = OsString::from(format!("{name}={value}"));
        let prefix = format!("{name}=");
        match args.iter().position(|a| a == name.as_str() || a.as_bytes().starts_with(prefix.as_bytes())) {
            Some(i) if args[i] == name.as_str() && i + 1 < args.len() => {
                args[i] = set;
                args.remove(i + 1);
            }
            Some(i) => args[i] = set,
            None => args.push(set),
        }
    }
    (program, args)
}

pub(crate) struct Run {
    pub(crate) verdict: Verdict,
    pub(crate) stderr: String,
    pub(crate) seconds: f64,
}

/// Runs one command under the address-space limit and the wall bound. stderr goes to a file (a pipe could fill
/// up and stall the child while we poll), and so does stdout, for the caller to scan.
pub(crate) fn run_bounded(target: &Target, mutant: &Mutant, cwd: &Path, out: &Path, stdio: [&Path; 2]) -> Run {
    let [stdout_path, stderr_path] = stdio;
    let (program, args) = command_line(target, &mutant.input, mutant.flag.as_ref(), out);
    let limit = format!("ulimit -v {MEMORY_LIMIT_KIB}; exec \"$0\" \"$@\"");
    let mut command = Command::new("sh");
    command.arg("-c").arg(limit).arg(&program).args(&args).current_dir(cwd).env("NO_COLOR", "1");
    let stderr_file = fs::File::create(stderr_path).unwrap();
    let stdout_file = fs::File::create(stdout_path).unwrap();
    let start = Instant::now();
    let mut child = command.stdin(Stdio::null()).stdout(stdout_file).stderr(stderr_file).spawn().unwrap();
    let mut pause = Duration::from_millis(1);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(pause);
        pause = (pause * 2).min(Duration::from_millis(20));
    };
    let seconds = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&fs::read(stderr_path).unwrap_or_default()).into_owned();
    let _ = fs::remove_file(stderr_path);
    Run { verdict: classify(status, &stderr, target.outcomes), stderr, seconds }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verdicts of the kinds of endings a run can have (wait statuses as the kernel reports them).
    #[test]
    fn classification_of_endings() {
        let exit = |code: i32| Some(ExitStatus::from_raw(code << 8));
        let signal = |sig: i32| Some(ExitStatus::from_raw(sig));
        assert_eq!(classify(exit(0), "", &[]), Verdict::Ok);
        assert_eq!(classify(exit(1), "error: x.mcap: not a readable MCAP file\n", &[]), Verdict::CleanError);
        assert_eq!(
            classify(exit(2), "error: unexpected argument '--x' (see 'mbrl --help')\n", &[]),
            Verdict::CleanError
        );
        assert_eq!(classify(exit(101), "", &[]), Verdict::Panic);
        assert_eq!(classify(exit(1), "thread 'main' panicked at src/x.rs:1:1:\nerror: x\n", &[]), Verdict::Panic);
        assert_eq!(classify(signal(6), "memory allocation of 68719476736 bytes failed\n", &[]), Verdict::Abort(6));
        assert_eq!(classify(signal(11), "", &[]), Verdict::Abort(11));
        assert_eq!(classify(None, "", &[]), Verdict::Hang);
        assert_eq!(classify(exit(1), "progress 3/5\nerror: late\n", &[]), Verdict::Unclean(1));
        assert_eq!(classify(exit(1), "warning: x: 5 of 5 steps\nerror: y\n", &[]), Verdict::CleanError);
        assert_eq!(classify(exit(3), "error: x\n", &[]), Verdict::Unclean(3));
        assert_eq!(classify(exit(3), "", &[1, 3]), Verdict::Ok, "a documented outcome");
        assert_eq!(classify(exit(3), "", &[]), Verdict::Unclean(3));
    }
}
