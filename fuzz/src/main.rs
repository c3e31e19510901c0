#![doc = include_str!("../README.md")]

use std::collections::BTreeMap;
use std::ffi::{OsStr, OsString};
use std::fs;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use base64::Engine;
use clap::{Parser, Subcommand};
use rand::seq::{IndexedMutRandom, IndexedRandom};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `ulimit -v` in KiB: 4 GiB of address space. An unbounded allocation fails instead of swapping the machine.
const MEMORY_LIMIT_KIB: u64 = 4 << 20;
/// A run still going after this long counts as a hang.
const TIME_LIMIT: Duration = Duration::from_secs(20);
/// Mutants per target in the CI slice.
const DEFAULT_MUTANTS: u64 = 100;

// ---------------------------------------------------------------------------------------------------------------
// Targets
// ---------------------------------------------------------------------------------------------------------------

/// What a target mutates.
#[derive(Clone, Copy)]
enum Input {
    /// A seed file (relative to the seed directory), mutated as `kind`; `{in}` in the command is the mutant.
    File { seed: &'static str, kind: Kind },
    /// One of `files` in the checkpoint directory `dir` (chosen per mutant); every other file is copied, and the
    /// manifest is updated to vouch for the mutant (size, CRC-32, metrics length) unless the manifest itself is
    /// the file mutated. `{in}` is the mutated directory.
    Checkpoint { dir: &'static str, files: &'static [&'static str] },
    /// A command-line argument, mutated as text or field by field; `{in}` is the mutant.
    Arg { seed: &'static str },
}

/// How a file is mutated.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// MCAP: raw bytes of the file as written, raw bytes of an uncompressed copy without CRCs (so damaged
    /// lengths reach the record parser), or a re-encoded file whose messages, metadata or schemas were changed.
    Mcap,
    /// Text (JSON, JSONL, CSV, TOML): token- and line-aware mutations, sometimes raw bytes; JSON and TOML also
    /// as documents (a value changed, written back valid).
    Text,
    /// PNG: raw bytes, mostly with the chunk CRCs recomputed so damaged sizes and lengths reach the decoder.
    Png,
}

/// Which program a target runs.
#[derive(Clone, Copy, PartialEq)]
enum Program {
    /// `mbrl --threads 1 -q <args>`.
    Mbrl,
    /// This binary as `read-board-set <args>`, reading the board set through the library.
    BoardSetReader,
}

struct Target {
    name: &'static str,
    input: Input,
    program: Program,
    /// The command after `mbrl --threads 1 -q` (or after this binary), split at spaces; `{in}` is the mutant
    /// (one argument whatever it holds), `{out}` a fresh output path.
    args: &'static str,
    /// The unmutated seed is refused with a clean error by design (a board set is not a dataset).
    seed_is_refused: bool,
}

const fn target(name: &'static str, input: Input, args: &'static str) -> Target {
    Target { name, input, program: Program::Mbrl, args, seed_is_refused: false }
}

const fn mcap(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Mcap }
}

const fn text(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Text }
}

const fn png(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Png }
}

/// CEM settings that make a planning run take milliseconds.
macro_rules! cheap_plan {
    () => {
        " --steps 2 --candidates 16 --elites 4 --iters 1"
    };
}

/// Every reader, with a cheap command that reaches it.
fn targets() -> Vec<Target> {
    const MODEL_FILES: &[&str] = &["checkpoint.json", "config.json", "model.safetensors"];
    vec![
        // Datasets of each kind.
        target("rollouts-eval", mcap("roll.mcap"), "eval dataset --input {in} --out {out}"),
        target(
            "rollouts-train-pets",
            mcap("roll.mcap"),
            "train --method pets --data {in} --config pets.toml --ensemble 1 --steps 1 --out {out}",
        ),
        target(
            "rollouts-evidence",
            mcap("roll.mcap"),
            concat!("plan --env pendulum --model dlgpd --evidence {in} --out {out}", cheap_plan!()),
        ),
        target("images-eval", mcap("img.mcap"), "eval dataset --input {in} --out {out}"),
        target(
            "pairs-train-context",
            mcap("ctx.mcap"),
            "train --method context --data {in} --config context.toml --steps 1 --out {out}",
        ),
        target(
            "pairs-plan-context",
            mcap("quad.mcap"),
            concat!("plan --env pendulum:quadrant --model quad-model --context {in} --out {out}", cheap_plan!()),
        ),
        target(
            "pairs-train-tradyn",
            mcap("uni.mcap"),
            "train --method tradyn --data {in} --config context.toml --steps 1 --out {out}",
        ),
        target(
            "calib-plan-tradyn",
            mcap("calib-uni.mcap"),
            concat!(
                "plan --env unicycle --model tradyn-model --map map.png --start 0.3,0.4,1 --goal 0.5,0.5 --horizon 3 ",
                "--context {in} --out {out}",
                cheap_plan!()
            ),
        ),
        Target {
            seed_is_refused: true,
            ..target("boardset-eval", mcap("boards.mcap"), "eval dataset --input {in} --out {out}")
        },
        Target { program: Program::BoardSetReader, ..target("boardset-read", mcap("boards.mcap"), "read-board-set {in}") },
        target("ball-filter", mcap("ball.mcap"), "filter --model thesis --input {in} --out {out}"),
        target("ball-predict", mcap("ball.mcap"), "predict --model ekf --input {in} --horizon 0.2s"),
        target("ball-train", mcap("ball.mcap"), "train --method ball-ekf --data {in} --steps 1 --batch 4 --out {out}"),
        // Text files.
        target("estimates-export", mcap("filtered.mcap"), "export --input {in} --format npz --out {out}"),
        target("images-export", mcap("img.mcap"), "export --input {in} --format npz --out {out}"),
        target("ball-csv", text("ball.csv"), "filter --model thesis --input {in} --out {out}"),
        // A dataset exported to CSV: its trajectory column splits the recordings.
        target("ball-csv-trajectories", text("ball-traj.csv"), "predict --model thesis --input {in} --out {out}"),
        target("actions-pendulum", text("actions.csv"), "collect --env pendulum --actions {in} --out {out}"),
        // Terrain: a user's map, and a map set (its manifest, or a map the manifest vouches for).
        target("terrain-map", png("map.png"), "collect --env unicycle --map {in} --rollouts 1 --steps 3 --out {out}"),
        target(
            "terrain-set",
            Input::Checkpoint { dir: "terrain", files: &["terrain.json", "map000.png"] },
            "collect --env unicycle --maps {in} --split train --rollouts 1 --steps 3 --out {out}",
        ),
        target(
            "actions-cursor",
            text("cursor.csv"),
            "collect --env lightsout:cursor --actions {in} --init-state 0.1,0.9 --out {out}",
        ),
        target(
            "toml-pets",
            text("pets-full.toml"),
            "train --method pets --data roll.mcap --config {in} --steps 1 --ensemble 1 --out {out}",
        ),
        target(
            "toml-context",
            text("context-full.toml"),
            "train --method context --data ctx.mcap --config {in} --steps 1 --out {out}",
        ),
        target(
            "toml-dlgpd",
            text("dlgpd-full.toml"),
            "train --method dlgpd --data roll.mcap --config {in} --steps 1 --out {out}",
        ),
        target(
            "toml-seads",
            text("seads-full.toml"),
            "train --method seads --env tileswap:cursor --config {in} --env-steps 20 --out {out}",
        ),
        // A sweep spec: every stage's command is parsed, the grid expanded and the scripts written.
        target("toml-sweep", text("sweep.toml"), "sweep plan {in} --out {out}"),
        // A training log (text panels, scalars, progress) and an evaluation log (messages, thousands of lines).
        target("metrics-watch-train", text("seads/metrics.jsonl"), "watch {in}"),
        target("metrics-watch-eval", text("swingup/metrics.jsonl"), "watch {in}"),
        // Board strings and other structured arguments.
        target(
            "board-lightsout",
            Input::Arg { seed: "0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0" },
            "solve-board --game lightsout --model true --board={in}",
        ),
        target(
            "board-tileswap",
            Input::Arg { seed: "8,7,6,5,4,3,2,1,0" },
            "solve-board --game tileswap --model true --board={in}",
        ),
        Target {
            // As `seads-solve`: the seed board is refused cleanly after the skills ran.
            seed_is_refused: true,
            ..target(
                "board-seads",
                Input::Arg { seed: "1,0,2,3,4,5,6,7,8" },
                "solve-board --model seads --board={in} --max-replans 1",
            )
        },
        target(
            "board-collect",
            Input::Arg { seed: "1,0,2,3,4,5,6,7,8" },
            "collect --env tileswap:cursor --actions cursor.csv --board={in} --out {out}",
        ),
        target(
            "init-state",
            Input::Arg { seed: "3.14,0" },
            "collect --env pendulum --actions actions.csv --init-state={in} --out {out}",
        ),
        // The wrist may start past its stops (the soft limit brings it back), up to a turn either way.
        target(
            "init-state-reacher",
            Input::Arg { seed: "0.5,4.5,0,-1" },
            "collect --env lightsout:reacher --actions reacher.csv --init-state={in} --out {out}",
        ),
        // Checkpoints: the files a model is loaded from, and the ones `train --resume` reads besides.
        target(
            "pets-plan",
            Input::Checkpoint { dir: "pets", files: MODEL_FILES },
            concat!("plan --env pendulum --model {in} --particles 2 --out {out}", cheap_plan!()),
        ),
        target("pets-resume", Input::Checkpoint { dir: "pets-resume", files: RESUME_FILES }, "train --resume {in}"),
        target(
            "context-calibrate",
            Input::Checkpoint { dir: "context-model", files: MODEL_FILES },
            "calibrate --model {in} --env toy:inner --instance-seed 1 --strategy random --transitions 2 --out {out}",
        ),
        target(
            "tradyn-plan",
            Input::Checkpoint { dir: "tradyn-model", files: MODEL_FILES },
            concat!(
                "plan --env unicycle --model {in} --map map.png --start 0.3,0.4,1 --goal 0.5,0.5 --horizon 3 --out {out}",
                cheap_plan!()
            ),
        ),
        target(
            "context-resume",
            Input::Checkpoint { dir: "context-model-resume", files: RESUME_FILES },
            "train --resume {in}",
        ),
        target(
            "dlgpd-plan",
            Input::Checkpoint { dir: "dlgpd", files: MODEL_FILES },
            concat!("plan --env pendulum --model {in} --evidence roll.mcap --out {out}", cheap_plan!()),
        ),
        target("dlgpd-resume", Input::Checkpoint { dir: "dlgpd-resume", files: RESUME_FILES }, "train --resume {in}"),
        // A finished run trained on past its total (its 5 steps, one more).
        target("dlgpd-extend", Input::Checkpoint { dir: "dlgpd", files: RESUME_FILES }, "train --resume {in} --steps 6"),
        // A run still in training, looked at with `--allow-incomplete` (the unfinished copies made for resume).
        target(
            "dlgpd-eval-incomplete",
            Input::Checkpoint { dir: "dlgpd-resume", files: MODEL_FILES },
            "eval dlgpd --model {in} --env pendulum --evidence-rollouts 1 --prediction-only --allow-incomplete --out {out}",
        ),
        target(
            "context-eval-incomplete",
            Input::Checkpoint { dir: "context-model-resume", files: MODEL_FILES },
            "eval context --model {in} --env toy:inner --contexts 2 --validation-rollouts 1 --validation-steps 3 \
             --transitions 1 --strategy random --allow-incomplete --out {out}",
        ),
        target(
            "pets-plan-incomplete",
            Input::Checkpoint { dir: "pets-resume", files: MODEL_FILES },
            concat!("plan --env pendulum --model {in} --particles 2 --allow-incomplete --out {out}", cheap_plan!()),
        ),
        target(
            "context-calibrate-incomplete",
            Input::Checkpoint { dir: "context-model-resume", files: MODEL_FILES },
            "calibrate --model {in} --env toy:inner --instance-seed 1 --strategy random --transitions 2 \
             --allow-incomplete --out {out}",
        ),
        target(
            "ekf-predict",
            Input::Checkpoint {
                dir: "ekf",
                files: &["checkpoint.json", "config.json", "params.json", "spin_net.json", "model.safetensors"],
            },
            "predict --model {in} --input ball.mcap --horizon 0.2s",
        ),
        target(
            "ekf-resume",
            Input::Checkpoint {
                dir: "ekf-resume",
                files: &[
                    "checkpoint.json",
                    "config.json",
                    "params.json",
                    "spin_net.json",
                    "state.safetensors",
                    "metrics.jsonl",
                ],
            },
            "train --resume {in}",
        ),
        Target {
            // Planning with the barely trained skills does not reach the goal: a clean error, after every file
            // of the checkpoint was read and the policies ran.
            seed_is_refused: true,
            ..target(
                "seads-solve",
                Input::Checkpoint { dir: "seads", files: MODEL_FILES },
                "solve-board --model {in} --board=1,0,2,3,4,5,6,7,8 --max-replans 1",
            )
        },
        target("seads-resume", Input::Checkpoint { dir: "seads-resume", files: RESUME_FILES }, "train --resume {in}"),
        target(
            "seads-eval-incomplete",
            Input::Checkpoint { dir: "seads-resume", files: MODEL_FILES },
            "eval seads --model {in} --max-depth 1 --boards 1 --coverage-boards 1 --allow-incomplete --out {out}",
        ),
    ]
}

/// The files `train --resume` reads.
const RESUME_FILES: &[&str] =
    &["checkpoint.json", "config.json", "model.safetensors", "state.safetensors", "metrics.jsonl"];

// ---------------------------------------------------------------------------------------------------------------
// Seeds
// ---------------------------------------------------------------------------------------------------------------

/// Tiny PETS network (as tests/cli/pets.rs).
const SWEEP_TOML: &str = "[sweep]\nname = \"fuzz\"\n[[stage]]\nname = \"train\"\n\
    command = \"train context --data ctx.mcap --config context.toml --steps 2 lambda_kl=1\"\n\
    [stage.grid]\nseed = [0, 1]\n\"--preset\" = [\"small\"]\n[[stage]]\nname = \"eval\"\nafter = \"train\"\n\
    command = \"eval context --model {train} --env toy:inner --contexts 2\"\n[stage.grid]\n\"--transitions\" = [1, 2]\n\
    [slurm]\nmemory = \"1G\"\ntime = \"00:05:00\"\nmax_running = 2\n[[compare]]\nstage = \"eval\"\n\
    metric = \"mean_mse[0]\"\na = { transitions = 1 }\nb = { transitions = 2 }\n";
const PETS_TOML: &str = "hidden_layers = 2\nhidden_units = 16\nvalidate_every = 10\ncheckpoint_every = 20\n";
/// Tiny context model (as tests/cli/context.rs).
const CONTEXT_TOML: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\n\
                            context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";
/// Tiny SEADS networks and memory (as tests/cli/seads.rs).
const SEADS_TOML: &str = "episodes_per_epoch = 4\nsampled_episodes = 8\nepisode_memory = 8\nmodel_hidden = 8\n\
                          sac_hidden = [8]\nsac_batch = 8\n";

/// The binary under test, copied into the seed directory (and with it next to saved failures).
const SNAPSHOT: &str = "bin/mbrl";
/// This binary, copied beside it: the child that reads board sets through the library.
const SELF_SNAPSHOT: &str = "bin/mbrl-fuzz";

/// `--dir`: the seeds go to `tmp/fuzz-seeds/` in it, the failures to `fuzz-failures/`.
static WORK: OnceLock<PathBuf> = OnceLock::new();

fn work() -> &'static Path {
    WORK.get().expect("the work directory is set before the campaign")
}

/// The seed directory, generated once at the start of a campaign.
fn seeds() -> &'static Path {
    static SEEDS: OnceLock<PathBuf> = OnceLock::new();
    SEEDS.get_or_init(|| work().join("tmp").join("fuzz-seeds"))
}

/// Makes the seed directory: private copies of the binaries, then every seed input.
fn generate(binary: &Path) -> Result<(), String> {
    let dir = seeds();
    let _ = fs::remove_dir_all(dir);
    let io = |e: std::io::Error| format!("{}: {e}", dir.display());
    fs::create_dir_all(dir.join("bin")).map_err(io)?;
    // Private copies: a rebuild during a long campaign must not change what is tested.
    fs::copy(binary, dir.join(SNAPSHOT)).map_err(|e| format!("copying {}: {e}", binary.display()))?;
    let this = std::env::current_exe().map_err(io)?;
    fs::copy(&this, dir.join(SELF_SNAPSHOT)).map_err(|e| format!("copying {}: {e}", this.display()))?;
    let start = Instant::now();
    generate_seeds(dir)?;
    eprintln!("fuzz: seeds generated in {:.1} s in {}", start.elapsed().as_secs_f64(), dir.display());
    Ok(())
}

/// Runs the binary to make a seed (`args` split at spaces); seeds must come out, so a failure stops the campaign.
fn make(dir: &Path, args: &str) -> Result<(), String> {
    let out = Command::new(dir.join(SNAPSHOT))
        .args(["--threads", "1", "-q", "--no-tui"])
        .args(args.split_whitespace())
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .map_err(|e| format!("seeding: mbrl {args}: {e}"))?;
    if !out.status.success() {
        return Err(format!("seeding failed: mbrl {args}\n{}", String::from_utf8_lossy(&out.stderr)));
    }
    Ok(())
}

/// A falling ball sampled at 180 Hz for 40 frames, frame 5 lost (the recording of tests/cli/common.rs).
fn falling_ball_csv() -> String {
    let mut text = String::from("frame,x,y,z\n");
    for f in 0..40u32 {
        let t = f as f64 / 180.0;
        if f == 5 {
            text += &format!("{f},,,\n");
        } else {
            text += &format!("{f},{:.5},{:.5},{:.5}\n", 0.1, 2.5 - 4.0 * t, 0.3 + 1.0 * t - 4.9 * t * t);
        }
    }
    text
}

fn generate_seeds(dir: &Path) -> Result<(), String> {
    let write = |name: &str, text: &str| fs::write(dir.join(name), text).unwrap();
    write("pets.toml", PETS_TOML);
    write("context.toml", CONTEXT_TOML);
    write("seads.toml", SEADS_TOML);
    write("sweep.toml", SWEEP_TOML);
    write("ball.csv", &falling_ball_csv());
    write("actions.csv", "u\n0.5\n-2\n1.5\n1e-3\n");
    write("cursor.csv", "dx,dy,push\n0.2,-0.2,-1\n0.1,-0.1,0.9\n0,0,-1\n");
    write("reacher.csv", "u1,u2,push\n1,-1,-1\n0.5,0.5,1\n0,0,1\n");

    make(dir, "collect --env pendulum --rollouts 3 --steps 10 --out roll.mcap")?;
    make(dir, "collect --env pendulum --images --rollouts 2 --steps 4 --out img.mcap")?;
    make(dir, "collect --env toy:inner --instances 4 --steps 12 --out ctx.mcap")?;
    make(dir, "collect --env pendulum:quadrant --instances 4 --steps 12 --out quad.mcap")?;
    make(dir, "collect --env ball --trajectories 2 --out ball.mcap")?;
    make(dir, "export --input ball.mcap --out ball-traj.csv")?;
    make(dir, "collect --env lightsout --boards --max-depth 2 --out boards.mcap")?;
    make(dir, "collect --env terrain --maps 2 --out terrain")?;
    fs::copy(dir.join("terrain/map000.png"), dir.join("map.png")).unwrap();

    make(dir, "train --method pets --data roll.mcap --config pets.toml --ensemble 2 --steps 5 --out pets")?;
    make(dir, "train --method context --data ctx.mcap --config context.toml --steps 5 --out context-model")?;
    make(dir, "train --method context --data quad.mcap --config context.toml --steps 3 --out quad-model")?;
    make(dir, "collect --env unicycle --map map.png --instances 4 --steps 12 --out uni.mcap")?;
    make(dir, "train --method tradyn --data uni.mcap --config context.toml --steps 3 --out tradyn-model")?;
    make(
        dir,
        "calibrate --model tradyn-model --env unicycle --map map.png --instance-seed 1 --strategy random --transitions 3 \
         --out calib-uni.mcap",
    )?;
    make(dir, "train --method dlgpd --data roll.mcap --steps 5 --batch 16 --out dlgpd")?;
    make(dir, "train --method ball-ekf --data ball.mcap --launcher-prior --steps 3 --batch 8 --out ekf")?;
    make(dir, "train --method seads --env tileswap:cursor --config seads.toml --env-steps 100 --out seads")?;
    make(dir, "eval pendulum-swingup --model true --episodes 1 --steps 25 --candidates 16 --elites 4 --out swingup")?;

    // More MCAP writers, for the check with the official reader.
    make(dir, "plan --env pendulum --model true --steps 3 --candidates 16 --elites 4 --out plan.mcap")?;
    make(dir, "calibrate --model context-model --env toy:inner --instance-seed 1 --strategy random --out calib.mcap")?;
    make(dir, "filter --model thesis --input ball.mcap --out filtered.csv --mcap filtered.mcap")?;

    // `train --resume` needs an unfinished run: the finished one, marked unfinished at its last step, resumes
    // without training but reads everything a resume reads.
    for name in ["pets", "context-model", "dlgpd", "ekf", "seads"] {
        let copy = dir.join(format!("{name}-resume"));
        copy_dir(&dir.join(name), &copy);
        let manifest = copy.join("checkpoint.json");
        let mut value: serde_json::Value = serde_json::from_slice(&fs::read(&manifest).unwrap()).unwrap();
        value["complete"] = false.into();
        fs::write(&manifest, serde_json::to_vec_pretty(&value).unwrap()).unwrap();
    }
    // Every key of each method's config table, as `--config` TOML.
    for (name, checkpoint) in [("pets", "pets"), ("context", "context-model"), ("dlgpd", "dlgpd"), ("seads", "seads")] {
        let config: serde_json::Value =
            serde_json::from_slice(&fs::read(dir.join(checkpoint).join("config.json")).unwrap()).unwrap();
        let table = without_nulls(config["config"].clone());
        fs::write(dir.join(format!("{name}-full.toml")), toml::to_string(&table).unwrap()).unwrap();
    }
    Ok(())
}

/// TOML has no null; an absent key means the same to the config reader.
fn without_nulls(value: serde_json::Value) -> serde_json::Value {
    match value {
        serde_json::Value::Object(map) => {
            map.into_iter().filter(|(_, v)| !v.is_null()).map(|(k, v)| (k, without_nulls(v))).collect()
        }
        other => other,
    }
}

/// Copies a directory tree (copies, not links: the copy is changed in place).
fn copy_dir(from: &Path, to: &Path) {
    fs::create_dir_all(to).unwrap();
    for entry in fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            fs::copy(entry.path(), &target).unwrap();
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------
// Mutators
// ---------------------------------------------------------------------------------------------------------------

const INTERESTING_BYTES: [u8; 4] = [0x00, 0xff, 0x7f, 0x80];
const INTERESTING_INTS: [u64; 12] = [
    0,
    1,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_fff0,
    0xffff_ffff,
    1 << 32,
    0xffff,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    0xffff_ffff_ffff_fff0,
    u64::MAX,
];
const INTERESTING_NUMBERS: [&str; 10] =
    ["1e308", "-1", "0", "NaN", "1e11", "1e-308", "inf", "18446744073709551615", "4294967296", "-0"];
const CONTROL_CHARS: [&[u8]; 10] = [
    b"\0",
    b"\x1b[2J",
    b"\r",
    b"\x7f",
    b"\x08",
    b"\x0c",
    "\u{feff}".as_bytes(),
    "\u{2028}".as_bytes(),
    b"\xff\xfe",
    b"\xc3",
];

/// One to four stacked mutations (mostly one, so that most mutants are near-valid).
fn stacked(rng: &mut ChaCha8Rng, data: &mut Vec<u8>, mutate: fn(&mut ChaCha8Rng, &mut Vec<u8>) -> String) -> String {
    let n = if rng.random_bool(0.7) { 1 } else { rng.random_range(2..=4) };
    (0..n).map(|_| mutate(rng, data)).collect::<Vec<_>>().join("; ")
}

/// A structure-blind mutation: bit flips, interesting bytes or integers, truncation, slice insertion or removal.
fn mutate_bytes(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    if data.is_empty() {
        data.push(rng.random());
        return "insert a byte into the empty input".into();
    }
    let len = data.len();
    match rng.random_range(0..7) {
        0 => {
            let bits: Vec<usize> = (0..rng.random_range(1..=8)).map(|_| rng.random_range(0..len * 8)).collect();
            bits.iter().for_each(|b| data[b / 8] ^= 1 << (b % 8));
            format!("flip bits {bits:?}")
        }
        1 => {
            let at: Vec<usize> = (0..rng.random_range(1..=4)).map(|_| rng.random_range(0..len)).collect();
            let value = *INTERESTING_BYTES.choose(rng).unwrap();
            at.iter().for_each(|&i| data[i] = value);
            format!("bytes {at:?} = {value:#04x}")
        }
        2 | 3 => {
            // An aligned window is where binary formats keep their lengths, counts and offsets.
            let width = if rng.random_bool(0.5) && len >= 8 { 8 } else { 4.min(len) };
            let at = rng.random_range(0..len / width) * width;
            let value = *INTERESTING_INTS.choose(rng).unwrap();
            let big_endian = rng.random_bool(0.25);
            let bytes = match (width, big_endian) {
                (8, false) => value.to_le_bytes().to_vec(),
                (8, true) => value.to_be_bytes().to_vec(),
                (_, false) => (value as u32).to_le_bytes()[..width].to_vec(),
                (_, true) => (value as u32).to_be_bytes()[..width].to_vec(),
            };
            data[at..at + width].copy_from_slice(&bytes);
            format!("{width} bytes at {at} = {value:#x} ({})", if big_endian { "BE" } else { "LE" })
        }
        4 => {
            let at = rng.random_range(0..len);
            data.truncate(at);
            format!("truncate to {at} bytes")
        }
        5 => {
            let start = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - start).min(512));
            let at = rng.random_range(0..=len);
            let slice = if rng.random_bool(0.5) {
                data[start..start + n].to_vec()
            } else {
                (0..n).map(|_| rng.random()).collect()
            };
            data.splice(at..at, slice);
            format!("insert {n} bytes at {at}")
        }
        _ => {
            let start = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - start).min(512));
            data.drain(start..start + n);
            format!("delete {n} bytes at {start}")
        }
    }
}

/// Byte ranges of numbers: a digit (or a sign or point before one) not inside a word, and what follows of
/// `[0-9.eE+-]`.
fn number_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let is_word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let starts = data[i].is_ascii_digit()
            || (matches!(data[i], b'-' | b'+' | b'.') && data.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !is_word(data[i - 1])) {
            let mut end = i + 1;
            while end < data.len() && (data[end].is_ascii_digit() || b".eE+-".contains(&data[end])) {
                end += 1;
            }
            spans.push((i, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of tokens: runs of word characters (with `.+-`), or single punctuation bytes.
fn token_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let is_word = |b: u8| b.is_ascii_alphanumeric() || b"_.+-".contains(&b);
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if data[i].is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let mut end = i + 1;
        if is_word(data[i]) {
            while end < data.len() && is_word(data[end]) {
                end += 1;
            }
        }
        spans.push((i, end));
        i = end;
    }
    spans
}

/// Byte ranges of lines, each with its newline.
fn line_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in data.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < data.len() {
        spans.push((start, data.len()));
    }
    spans
}

/// A token-aware mutation of text: a number replaced by an extreme one, a token or line deleted or duplicated,
/// control characters inserted, or (rarely) a byte-level mutation.
fn mutate_text(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let show = |bytes: &[u8]| String::from_utf8_lossy(&bytes[..bytes.len().min(40)]).escape_debug().to_string();
    match rng.random_range(0..9) {
        0..=2 => {
            let spans = number_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let new = *INTERESTING_NUMBERS.choose(rng).unwrap();
            let old = show(&data[start..end]);
            data.splice(start..end, new.bytes());
            format!("number '{old}' at {start} -> {new}")
        }
        3 | 4 => {
            let spans = token_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let token = data[start..end].to_vec();
            if rng.random_bool(0.5) {
                data.drain(start..end);
                format!("delete token '{}' at {start}", show(&token))
            } else {
                data.splice(end..end, token.iter().copied());
                format!("duplicate token '{}' at {start}", show(&token))
            }
        }
        5 | 6 => {
            let spans = line_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let line = data[start..end].to_vec();
            if rng.random_bool(0.5) {
                data.drain(start..end);
                format!("delete line '{}'", show(&line))
            } else {
                data.splice(end..end, line.iter().copied());
                format!("duplicate line '{}'", show(&line))
            }
        }
        7 => {
            let at = rng.random_range(0..=data.len());
            let chars = *CONTROL_CHARS.choose(rng).unwrap();
            data.splice(at..at, chars.iter().copied());
            format!("insert {} at {at}", show(chars))
        }
        _ => mutate_bytes(rng, data),
    }
}

/// Text that parses (JSON, JSON lines, TOML) is half the time changed as a document and written back valid, so
/// that odd values reach the checks behind the parser (shapes, lengths, ranges); otherwise `mutate_text`.
fn mutate_document(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    if rng.random_bool(0.5) {
        if let Some(what) = mutate_parsed(rng, data) {
            return what;
        }
    }
    stacked(rng, data, mutate_text)
}

fn mutate_parsed(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> Option<String> {
    use serde_json::Value;
    let text = std::str::from_utf8(data).ok()?;
    if let Ok(mut value) = serde_json::from_str::<Value>(text) {
        let what = mutate_value(rng, &mut value);
        let mut out =
            if text.contains("\n ") { serde_json::to_vec_pretty(&value) } else { serde_json::to_vec(&value) }.ok()?;
        if text.ends_with('\n') {
            out.push(b'\n');
        }
        *data = out;
        return Some(format!("JSON {what}"));
    }
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() > 1 && lines.iter().all(|l| serde_json::from_str::<Value>(l).is_ok()) {
        let i = rng.random_range(0..lines.len());
        let mut value: Value = serde_json::from_str(lines[i]).unwrap();
        let what = mutate_value(rng, &mut value);
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        out[i] = serde_json::to_string(&value).ok()?;
        *data = (out.join("\n") + "\n").into_bytes();
        return Some(format!("JSON line {}: {what}", i + 1));
    }
    // TOML goes through the same value tree; what TOML cannot hold (null, integers beyond i64) fails to write and
    // falls back to a text mutation.
    let table: toml::Table = toml::from_str(text).ok()?;
    let mut value = serde_json::to_value(&table).ok()?;
    let what = mutate_value(rng, &mut value);
    *data = toml::to_string(&value).ok()?.into_bytes();
    Some(format!("TOML {what}"))
}

/// The `n`-th node of a value tree in pre-order, with its path.
fn nth_node<'a>(
    value: &'a mut serde_json::Value,
    n: &mut usize,
    path: String,
) -> Option<(String, &'a mut serde_json::Value)> {
    if *n == 0 {
        return Some((path, value));
    }
    *n -= 1;
    match value {
        serde_json::Value::Array(items) => {
            for (i, item) in items.iter_mut().enumerate() {
                if let Some(found) = nth_node(item, n, format!("{path}[{i}]")) {
                    return Some(found);
                }
            }
        }
        serde_json::Value::Object(map) => {
            for (key, item) in map.iter_mut() {
                if let Some(found) = nth_node(item, n, format!("{path}.{key}")) {
                    return Some(found);
                }
            }
        }
        _ => {}
    }
    None
}

fn count_nodes(value: &serde_json::Value) -> usize {
    1 + match value {
        serde_json::Value::Array(items) => items.iter().map(count_nodes).sum(),
        serde_json::Value::Object(map) => map.values().map(count_nodes).sum(),
        _ => 0,
    }
}

/// Changes one node of a value tree: a number to an extreme, an array shortened, emptied or grown, a key removed
/// or added, a string or flag changed, or any node replaced by a value of another type.
fn mutate_value(rng: &mut ChaCha8Rng, root: &mut serde_json::Value) -> String {
    use serde_json::{json, Value};
    let mut n = rng.random_range(0..count_nodes(root));
    let (path, node) = nth_node(root, &mut n, String::new()).unwrap();
    let old: String = node.to_string().chars().take(40).collect();
    let numbers = [
        json!(1e308),
        json!(-1e308),
        json!(-1),
        json!(0),
        json!(-0.0),
        json!(0.5),
        json!(1e11),
        json!(1e-308),
        json!(u64::MAX),
        json!(1u64 << 32),
        json!(1u64 << 31),
        json!(1_000_000),
    ];
    let what = match node {
        _ if rng.random_bool(0.15) => {
            *node = [json!(null), json!("x"), json!([]), json!({}), json!(true), json!(0)].choose(rng).unwrap().clone();
            "replaced".to_string()
        }
        Value::Number(_) | Value::Null => {
            *node = numbers.choose(rng).unwrap().clone();
            "number".into()
        }
        Value::Bool(b) => {
            *b = !*b;
            "flipped".into()
        }
        Value::String(text) => {
            let mut bytes = std::mem::take(text).into_bytes();
            let what = mutate_text(rng, &mut bytes);
            *text = String::from_utf8_lossy(&bytes).into_owned();
            what
        }
        Value::Array(items) if !items.is_empty() => {
            let i = rng.random_range(0..items.len());
            match rng.random_range(0..4) {
                0 => {
                    items.remove(i);
                    format!("remove element {i}")
                }
                1 => {
                    let copy = items[i].clone();
                    items.insert(i, copy);
                    format!("duplicate element {i}")
                }
                2 => {
                    items.truncate(i);
                    format!("truncate to {i} elements")
                }
                _ => {
                    let copy = items.clone();
                    items.extend(copy);
                    "double".into()
                }
            }
        }
        Value::Object(map) if !map.is_empty() && rng.random_bool(0.7) => {
            let key = map.keys().nth(rng.random_range(0..map.len())).unwrap().clone();
            map.remove(&key);
            format!("remove key '{key}'")
        }
        Value::Object(map) => {
            map.insert("fuzz".into(), json!(1));
            "add key 'fuzz'".into()
        }
        Value::Array(items) => {
            items.push(json!(0));
            "push 0".into()
        }
    };
    let new: String = node.to_string().chars().take(40).collect();
    format!("at '{path}': {old} -> {new} ({what})")
}

/// A comma-separated argument (a board, a state): half the time its fields are swapped or one is copied over
/// another, which keeps it well-formed (a scrambled or unsolvable board, a chip twice); otherwise `mutate_text`.
fn mutate_argument(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let mut fields: Vec<Vec<u8>> = data.split(|&b| b == b',').map(<[u8]>::to_vec).collect();
    if fields.len() < 2 || rng.random_bool(0.5) {
        return mutate_text(rng, data);
    }
    let (i, j) = (rng.random_range(0..fields.len()), rng.random_range(0..fields.len()));
    let what = if rng.random_bool(0.5) {
        fields.swap(i, j);
        format!("swap fields {i} and {j}")
    } else {
        fields[i] = fields[j].clone();
        format!("copy field {j} to {i}")
    };
    *data = fields.join(&b',');
    what
}

/// safetensors is an 8-byte little-endian header length, a JSON header (names, dtypes, shapes, offsets) and
/// the tensor bytes. Half the mutants change the header as text and keep the length prefix consistent, so that
/// the header parser and the shape and offset checks behind it are reached.
fn mutate_safetensors(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let header_len = data.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap()) as usize);
    match header_len {
        Some(n) if n <= data.len() - 8 && rng.random_bool(0.5) => {
            let mut header = data[8..8 + n].to_vec();
            let what = mutate_document(rng, &mut header);
            let mut out = (header.len() as u64).to_le_bytes().to_vec();
            out.extend_from_slice(&header);
            out.extend_from_slice(&data[8 + n..]);
            *data = out;
            format!("safetensors header: {what}")
        }
        _ => stacked(rng, data, mutate_bytes),
    }
}

/// An MCAP file as records, for structural mutation and re-encoding.
#[derive(Clone)]
struct McapDoc {
    metadata: Vec<mcap::records::Metadata>,
    schemas: Vec<(u16, String, String, Vec<u8>)>,
    channels: Vec<mcap::records::Channel>,
    messages: Vec<(mcap::records::MessageHeader, Vec<u8>)>,
}

impl McapDoc {
    /// Reads every record, chunks flattened; the summary repeats schemas and channels, kept once.
    fn decode(bytes: &[u8]) -> McapDoc {
        use mcap::records::Record;
        let mut doc = McapDoc { metadata: vec![], schemas: vec![], channels: vec![], messages: vec![] };
        for record in mcap::read::ChunkFlattener::new(bytes).unwrap() {
            match record.unwrap() {
                Record::Metadata(m) => doc.metadata.push(m),
                Record::Schema { header, data } if !doc.schemas.iter().any(|s| s.0 == header.id) => {
                    doc.schemas.push((header.id, header.name, header.encoding, data.into_owned()))
                }
                Record::Channel(c) if !doc.channels.iter().any(|k| k.id == c.id) => doc.channels.push(c),
                Record::Message { header, data } => doc.messages.push((header, data.into_owned())),
                _ => {}
            }
        }
        doc
    }

    /// Writes a valid MCAP file (CRCs included unless `checksums` is off); `None` when the mutated records are
    /// something the writer refuses (the byte-level mutators cover invalid containers).
    fn encode(&self, compress: bool, chunked: bool, checksums: bool) -> Option<Vec<u8>> {
        let options = mcap::WriteOptions::new()
            .compression(compress.then_some(mcap::Compression::Zstd))
            .use_chunks(chunked)
            .calculate_chunk_crcs(checksums)
            .calculate_data_section_crc(checksums)
            .calculate_summary_section_crc(checksums)
            .profile("mbrl");
        let mut out = std::io::Cursor::new(Vec::new());
        let mut writer = options.create(&mut out).ok()?;
        for m in &self.metadata {
            writer.write_metadata(m).ok()?;
        }
        for (id, name, encoding, data) in &self.schemas {
            writer.add_schema_with_id(*id, name, encoding, data).ok()?;
        }
        for c in &self.channels {
            writer.add_channel_with_id(c.id, c.schema_id, &c.topic, &c.message_encoding, &c.metadata).ok()?;
        }
        for (header, data) in &self.messages {
            writer.write_to_known_channel(header, data).ok()?;
        }
        writer.finish().ok()?;
        drop(writer);
        Some(out.into_inner())
    }
}

/// The seed MCAP files, decoded once per process: structural mutants start from these.
fn decoded(path: &Path) -> McapDoc {
    static CACHE: OnceLock<Mutex<BTreeMap<PathBuf, McapDoc>>> = OnceLock::new();
    let mut cache = CACHE.get_or_init(Default::default).lock().unwrap();
    cache.entry(path.to_path_buf()).or_insert_with(|| McapDoc::decode(&fs::read(path).unwrap())).clone()
}

fn mutate_mcap(rng: &mut ChaCha8Rng, seed: &Path) -> (Vec<u8>, String) {
    let doc = decoded(seed);
    match rng.random_range(0..4) {
        0 => {
            let mut data = fs::read(seed).unwrap();
            let what = stacked(rng, &mut data, mutate_bytes);
            (data, format!("raw bytes: {what}"))
        }
        1 => {
            // Without compression or CRCs a damaged length or opcode reaches the record parser itself.
            let mut data = doc.encode(false, rng.random_bool(0.5), false).unwrap();
            let what = stacked(rng, &mut data, mutate_bytes);
            (data, format!("raw bytes of the uncompressed copy without CRCs: {what}"))
        }
        _ => {
            let mut doc = doc;
            let what =
                (0..rng.random_range(1..=2)).map(|_| mutate_records(rng, &mut doc)).collect::<Vec<_>>().join("; ");
            let (compress, chunked) = (rng.random_bool(0.5), rng.random_bool(0.8));
            match doc.encode(compress, chunked, true) {
                Some(data) => (data, format!("records: {what}")),
                None => {
                    let mut data = fs::read(seed).unwrap();
                    let what = stacked(rng, &mut data, mutate_bytes);
                    (data, format!("raw bytes (records unwritable): {what}"))
                }
            }
        }
    }
}

/// One structural change: a message's JSON, a camera frame's PNG, a metadata value or key, the messages' order,
/// count or headers, a channel or schema field.
fn mutate_records(rng: &mut ChaCha8Rng, doc: &mut McapDoc) -> String {
    let n = doc.messages.len();
    match rng.random_range(0..10) {
        0..=2 if n > 0 => {
            let i = rng.random_range(0..n);
            format!("message {i} JSON: {}", mutate_document(rng, &mut doc.messages[i].1))
        }
        3 if n > 0 => {
            let i = rng.random_range(0..n);
            match mutate_frame_png(rng, &doc.messages[i].1) {
                Some((data, what)) => {
                    doc.messages[i].1 = data;
                    format!("message {i} PNG: {what}")
                }
                None => format!("message {i} JSON: {}", mutate_document(rng, &mut doc.messages[i].1)),
            }
        }
        4 | 5 if !doc.metadata.is_empty() => {
            let record = doc.metadata.choose_mut(rng).unwrap();
            let key = record.metadata.keys().cloned().collect::<Vec<_>>().choose(rng).cloned();
            let Some(key) = key else { return "metadata: empty".into() };
            if rng.random_bool(0.15) {
                record.metadata.remove(&key);
                return format!("metadata: remove '{key}'");
            }
            let mut value = record.metadata[&key].clone().into_bytes();
            let what = mutate_document(rng, &mut value);
            // Metadata strings are UTF-8 in MCAP; the writer takes Rust strings.
            record.metadata.insert(key.clone(), String::from_utf8_lossy(&value).into_owned());
            format!("metadata '{key}': {what}")
        }
        6 if n > 0 => {
            let i = rng.random_range(0..n);
            match rng.random_range(0..3) {
                0 => {
                    doc.messages.remove(i);
                    format!("remove message {i}")
                }
                1 => {
                    let copy = doc.messages[i].clone();
                    doc.messages.insert(rng.random_range(0..=n), copy);
                    format!("duplicate message {i}")
                }
                _ => {
                    let j = rng.random_range(0..n);
                    doc.messages.swap(i, j);
                    format!("swap messages {i} and {j}")
                }
            }
        }
        7 if n > 0 => {
            let i = rng.random_range(0..n);
            let value = *INTERESTING_INTS.choose(rng).unwrap();
            let header = &mut doc.messages[i].0;
            match rng.random_range(0..3) {
                0 => header.sequence = value as u32,
                1 => header.log_time = value,
                _ => header.channel_id = doc.channels.choose(rng).map_or(0, |c| c.id),
            }
            format!("message {i} header: {header:?}")
        }
        8 if !doc.channels.is_empty() => {
            let channel = doc.channels.choose_mut(rng).unwrap();
            let field = if rng.random_bool(0.5) { &mut channel.topic } else { &mut channel.message_encoding };
            let mut bytes = std::mem::take(field).into_bytes();
            let what = mutate_text(rng, &mut bytes);
            *field = String::from_utf8_lossy(&bytes).into_owned();
            format!("channel {}: {what}", channel.id)
        }
        _ if !doc.schemas.is_empty() => {
            let schema = doc.schemas.choose_mut(rng).unwrap();
            if rng.random_bool(0.5) {
                let mut bytes = std::mem::take(&mut schema.2).into_bytes();
                let what = mutate_text(rng, &mut bytes);
                schema.2 = String::from_utf8_lossy(&bytes).into_owned();
                format!("schema {} encoding: {what}", schema.0)
            } else {
                format!("schema {} text: {}", schema.0, mutate_text(rng, &mut schema.3))
            }
        }
        _ => "no change".into(),
    }
}

/// A camera frame message (JSON with base64 PNG `data`), its PNG mutated as [`mutate_png`] does.
fn mutate_frame_png(rng: &mut ChaCha8Rng, message: &[u8]) -> Option<(Vec<u8>, String)> {
    let mut json: serde_json::Value = serde_json::from_slice(message).ok()?;
    let engine = base64::engine::general_purpose::STANDARD;
    let mut png = engine.decode(json.get("data")?.as_str()?).ok()?;
    let what = mutate_png(rng, &mut png);
    json["data"] = engine.encode(&png).into();
    Some((serde_json::to_vec(&json).ok()?, what))
}

/// A PNG mutated as bytes, and mostly with its chunk CRCs recomputed so that damaged dimensions or chunk lengths
/// get past the CRC check to the decoder.
fn mutate_png(rng: &mut ChaCha8Rng, png: &mut Vec<u8>) -> String {
    let mut what = stacked(rng, png, mutate_bytes);
    if rng.random_bool(0.8) {
        fix_png_crcs(png);
        what += " (chunk CRCs fixed)";
    }
    what
}

fn fix_png_crcs(png: &mut [u8]) {
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        let Some(end) = (at + 8).checked_add(len).filter(|end| end + 4 <= png.len()) else { break };
        let crc = crc32fast::hash(&png[at + 4..end]);
        png[end..end + 4].copy_from_slice(&crc.to_be_bytes());
        at = end + 4;
    }
}

// ---------------------------------------------------------------------------------------------------------------
// Mutants
// ---------------------------------------------------------------------------------------------------------------

/// A prepared mutant: where it lives, what its `{in}` is, and what was done to it.
struct Mutant {
    /// File or directory holding the mutant (removed after a clean run, saved after a failure).
    path: PathBuf,
    /// The `{in}` of the command: the mutant's path, or the mutated argument's bytes.
    input: OsString,
    description: String,
}

/// The generator of mutant `index` of `target`: the same for every run with the same `MBRL_FUZZ_SEED`.
fn mutant_rng(target: &str, index: u64, campaign: u64) -> ChaCha8Rng {
    // FNV-1a: a stable hash of the name, so adding a target changes no other target's mutants.
    let name = target.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
    ChaCha8Rng::seed_from_u64(name ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ campaign.rotate_left(32))
}

/// Writes mutant `index` (or the unmutated seed, for `None`) of `target` into `work`.
fn prepare(target: &Target, seeds: &Path, work: &Path, index: Option<u64>, campaign: u64) -> Mutant {
    let label = index.map_or("seed".to_string(), |i| i.to_string());
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
            Mutant { input: path.clone().into_os_string(), path, description }
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
            Mutant { input: path.clone().into_os_string(), path, description }
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
            Mutant { input: OsString::from_vec(bytes), path, description }
        }
    }
}

/// Copies a checkpoint without the loss plot and table, which no reader opens.
fn copy_checkpoint(from: &Path, to: &Path) {
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
fn mutate_checkpoint(rng: &mut ChaCha8Rng, dir: &Path, file: &str) -> String {
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
    let manifest_path = dir.join("checkpoint.json");
    // A map set's manifest vouches by pixel CRC, which a fuzzer cannot forge without decoding: left as is.
    if file == "checkpoint.json" || !manifest_path.exists() {
        return format!("{file}: {what}");
    }
    let mut manifest: serde_json::Value = serde_json::from_slice(&fs::read(&manifest_path).unwrap()).unwrap();
    if let Some(entry) = manifest["files"].get_mut(file) {
        entry["bytes"] = bytes.len().into();
        entry["crc32"] = crc32fast::hash(&bytes).into();
    }
    // The manifest records how much of the metrics log belongs to the checkpoint; mostly keep it consistent,
    // sometimes leave the old length to exercise the cut-back on resume.
    if file == "metrics.jsonl" && rng.random_bool(0.8) {
        manifest["metrics_bytes"] = bytes.len().into();
    }
    fs::write(&manifest_path, serde_json::to_vec_pretty(&manifest).unwrap()).unwrap();
    format!("{file} (manifest updated): {what}")
}

// ---------------------------------------------------------------------------------------------------------------
// Running and classifying
// ---------------------------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Verdict {
    Ok,
    CleanError,
    Panic,
    Abort(i32),
    Hang,
    Unclean(i32),
}

impl Verdict {
    fn is_failure(self) -> bool {
        !matches!(self, Verdict::Ok | Verdict::CleanError)
    }

    fn describe(self) -> String {
        match self {
            Verdict::Ok => "ok".into(),
            Verdict::CleanError => "clean error".into(),
            Verdict::Panic => "panic".into(),
            Verdict::Abort(signal) => format!("abort (signal {signal})"),
            Verdict::Hang => format!("hang (over {} s)", TIME_LIMIT.as_secs()),
            Verdict::Unclean(code) => format!("unclean exit {code} without an 'error:' line"),
        }
    }
}

fn classify(status: Option<ExitStatus>, stderr: &str) -> Verdict {
    let Some(status) = status else { return Verdict::Hang };
    if let Some(signal) = status.signal() {
        return Verdict::Abort(signal);
    }
    let code = status.code().unwrap_or(-1);
    if code == 101 || stderr.contains("panicked") {
        return Verdict::Panic;
    }
    let first = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    match code {
        0 => Verdict::Ok,
        1 | 2 if first.starts_with("error:") => Verdict::CleanError,
        _ => Verdict::Unclean(code),
    }
}

/// The program and arguments of a run of `target` on `input`, writing to `out`.
fn command_line(target: &Target, input: &OsStr, out: &Path) -> (PathBuf, Vec<OsString>) {
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
    (program, args)
}

struct Run {
    verdict: Verdict,
    stderr: String,
    seconds: f64,
}

/// Runs one command under the address-space limit and the wall bound. stderr goes to a file (a pipe could fill
/// up and stall the child while we poll), stdout is dropped.
fn run_bounded(target: &Target, input: &OsStr, cwd: &Path, out: &Path, stderr_path: &Path) -> Run {
    let (program, args) = command_line(target, input, out);
    let limit = format!("ulimit -v {MEMORY_LIMIT_KIB}; exec \"$0\" \"$@\"");
    let mut command = Command::new("sh");
    command.arg("-c").arg(limit).arg(&program).args(&args).current_dir(cwd).env("NO_COLOR", "1");
    let stderr_file = fs::File::create(stderr_path).unwrap();
    let start = Instant::now();
    let mut child = command.stdin(Stdio::null()).stdout(Stdio::null()).stderr(stderr_file).spawn().unwrap();
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
    Run { verdict: classify(status, &stderr), stderr, seconds }
}

// ---------------------------------------------------------------------------------------------------------------
// The campaign
// ---------------------------------------------------------------------------------------------------------------

/// Process-level fuzzing of every file and string reader of the `mbrl` binary (see fuzz/README.md). Each flag
/// falls back to the environment variable named in its help, then to its default.
#[derive(Parser)]
#[command(name = "mbrl-fuzz", version)]
struct Cli {
    #[command(subcommand)]
    child: Option<Child>,
    /// Mutants per target [env: MBRL_FUZZ_MUTANTS] [default: 100]
    #[arg(long, value_name = "N")]
    mutants: Option<u64>,
    /// Another family of mutants [env: MBRL_FUZZ_SEED] [default: 0]
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Comma-separated substrings of target names (see --list) [env: MBRL_FUZZ_TARGETS]
    #[arg(long, value_name = "A,B")]
    targets: Option<String>,
    /// Parallel runs [env: MBRL_FUZZ_JOBS] [default: one per core]
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
    /// The `mbrl` binary to fuzz [env: MBRL_FUZZ_BIN] [default: target/release/mbrl]
    #[arg(long, value_name = "PATH")]
    bin: Option<PathBuf>,
    /// Where the seeds (DIR/tmp/fuzz-seeds) and the saved failures (DIR/fuzz-failures) go
    #[arg(long, value_name = "DIR", default_value = "target")]
    dir: PathBuf,
    /// Print every run's outcome and first stderr line [env: MBRL_FUZZ_VERBOSE, set to anything]
    #[arg(long)]
    verbose: bool,
    /// Print the target names and exit
    #[arg(long)]
    list: bool,
}

#[derive(Subcommand)]
enum Child {
    /// The child process of the `boardset-read` target: reads a board set through the library (no `mbrl`
    /// subcommand reads board sets).
    #[command(hide = true)]
    ReadBoardSet { path: PathBuf },
}

struct Settings {
    mutants: u64,
    campaign: u64,
    jobs: usize,
    only: Vec<String>,
    /// Print every run's outcome and first stderr line.
    verbose: bool,
    binary: PathBuf,
}

/// The flags, else the environment, else the defaults; the message of an `Err` names the bad variable.
fn settings(cli: &Cli) -> Result<Settings, String> {
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
    })
}

/// One failing mutant, as reported and saved.
struct Failure {
    target: usize,
    index: u64,
    verdict: Verdict,
    description: String,
    command: String,
    stderr: String,
    saved: PathBuf,
}

#[derive(Default, Clone, Copy)]
struct Counts {
    runs: u64,
    ok: u64,
    errors: u64,
    panics: u64,
    aborts: u64,
    hangs: u64,
    unclean: u64,
    seconds: f64,
}

impl Counts {
    fn add(&mut self, run: &Run) {
        self.runs += 1;
        self.seconds += run.seconds;
        match run.verdict {
            Verdict::Ok => self.ok += 1,
            Verdict::CleanError => self.errors += 1,
            Verdict::Panic => self.panics += 1,
            Verdict::Abort(_) => self.aborts += 1,
            Verdict::Hang => self.hangs += 1,
            Verdict::Unclean(_) => self.unclean += 1,
        }
    }
}

fn failures_dir() -> PathBuf {
    work().join("fuzz-failures")
}

/// Shell-quotes one argument where needed (bytes kept as they are).
fn quote(arg: &OsStr) -> Vec<u8> {
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
fn shown(target: &Target, input: &OsStr) -> String {
    let (program, args) = command_line(target, input, Path::new("OUT"));
    let name = if target.program == Program::Mbrl { "mbrl".into() } else { program.display().to_string() };
    let args: Vec<String> = args.iter().map(|a| String::from_utf8_lossy(&quote(a)).into_owned()).collect();
    format!("{name} {}", args.join(" "))
}

/// Saves a failing mutant next to a script that reruns it in `fuzz-failures/seeds` with the same limits.
fn save_failure(target: &Target, mutant: &Mutant, index: u64, verdict: Verdict, campaign: u64) -> PathBuf {
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
    let (_, args) = command_line(target, &input, Path::new("fuzz-out"));
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

/// Runs mutant `index` (or the seed) of a target and cleans up after it; a failure is saved first.
fn run_one(target: &Target, seeds: &Path, index: Option<u64>, campaign: u64) -> (Run, Option<Mutant>) {
    let work = seeds.join("work").join(target.name);
    fs::create_dir_all(&work).unwrap();
    let mutant = prepare(target, seeds, &work, index, campaign);
    let label = index.map_or("seed".to_string(), |i| i.to_string());
    let out = work.join(format!("{label}.out"));
    let run = run_bounded(target, &mutant.input, seeds, &out, &work.join(format!("{label}.stderr")));
    remove(&out);
    if run.verdict.is_failure() {
        return (run, Some(mutant));
    }
    remove(&mutant.path);
    (run, None)
}

fn remove(path: &Path) {
    let _ = fs::remove_dir_all(path).or_else(|_| fs::remove_file(path));
}

/// Every unmutated seed must be read as intended under the same limits; otherwise the mutants test nothing
/// (and a 4 GiB limit that breaks normal runs is itself a finding).
fn check_seeds(targets: &[&Target], seeds: &Path) -> Result<(), String> {
    for target in targets {
        let (run, failed) = run_one(target, seeds, None, 0);
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
                shown(target, OsStr::new("<seed>")),
                run.stderr
            ));
        }
    }
    Ok(())
}

fn print_table(targets: &[&Target], counts: &[Counts]) {
    eprintln!(
        "\n{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>8}",
        "target", "runs", "ok", "errors", "panics", "aborts", "hangs", "unclean", "s/run"
    );
    let mut total = Counts::default();
    for (target, c) in targets.iter().zip(counts) {
        eprintln!(
            "{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>8.3}",
            target.name,
            c.runs,
            c.ok,
            c.errors,
            c.panics,
            c.aborts,
            c.hangs,
            c.unclean,
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
        ] {
            *sum += part;
        }
        total.seconds += c.seconds;
    }
    eprintln!(
        "{:<22} {:>6} {:>6} {:>7} {:>6} {:>6} {:>6} {:>7} {:>8.3}\n",
        "total",
        total.runs,
        total.ok,
        total.errors,
        total.panics,
        total.aborts,
        total.hangs,
        total.unclean,
        total.seconds / total.runs.max(1) as f64
    );
}

/// Runs every mutant of the chosen targets on the seeds; `Err` holds the report of the failures.
fn fuzz_every_reader(settings: &Settings, targets: &[&Target]) -> Result<(), String> {
    let seeds = seeds();
    check_seeds(targets, seeds)?;
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
        "fuzz: {} targets × {} mutants, {} parallel runs, --seed {}",
        targets.len(),
        settings.mutants,
        settings.jobs,
        settings.campaign
    );
    std::thread::scope(|scope| {
        for _ in 0..settings.jobs {
            scope.spawn(|| {
                while let Some(&(t, index)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let target = targets[t];
                    let (run, failed) = run_one(target, seeds, Some(index), settings.campaign);
                    if let Some(mutant) = failed {
                        let saved = save_failure(target, &mutant, index, run.verdict, settings.campaign);
                        remove(&mutant.path);
                        // The command as it reads the saved copy (arguments are their own copy).
                        let input = match target.input {
                            Input::Arg { .. } => mutant.input.clone(),
                            _ => saved.clone().into_os_string(),
                        };
                        let command = shown(target, &input);
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

/// Every MCAP file the seeding wrote passes the official Python reader with CRC validation: seeking (summary,
/// chunk CRCs) and streaming (data-section CRC), with the message counts of the summary.
fn seeds_pass_the_python_mcap_reader(seeds: &Path) -> Result<(), String> {
    let probe = Command::new("python3").args(["-c", "import mcap"]).output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!(
            "note: Python reader check skipped: python3 with the `mcap` package is not available (pip install mcap)"
        );
        return Ok(());
    }
    // The seed directory and the report directories in it (`work/` holds mutants).
    let dirs = fs::read_dir(seeds).unwrap().map(|e| e.unwrap().path()).filter(|p| p.is_dir() && !p.ends_with("work"));
    let mut files: Vec<PathBuf> = std::iter::once(seeds.to_path_buf())
        .chain(dirs)
        .flat_map(|dir| fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()))
        .filter(|p| p.extension().is_some_and(|e| e == "mcap"))
        .collect();
    files.sort();
    if files.len() < 10 {
        return Err(format!("expected every seed MCAP file, found {files:?}"));
    }
    const SCRIPT: &str = r#"
import sys
from mcap.reader import make_reader, NonSeekingReader
for path in sys.argv[1:]:
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        assert summary is not None, f"{path}: no summary"
        count = sum(1 for _ in reader.iter_messages())
        metadata = [m.name for m in reader.iter_metadata()]
        expected = summary.statistics.message_count
        assert count == expected, f"{path}: {count} messages, the summary says {expected}"
        assert len(metadata) == 1 and metadata[0].startswith("mbrl."), f"{path}: metadata {metadata}"
    with open(path, "rb") as f:
        streamed = sum(1 for _ in NonSeekingReader(f, validate_crcs=True).iter_messages())
        assert streamed == count, f"{path}: streamed {streamed} messages, seeking {count}"
    print(f"{path}: {count} messages, {metadata[0]}, CRCs valid")
"#;
    let out = Command::new("python3").arg("-c").arg(SCRIPT).args(&files).output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if !out.status.success() || stdout.lines().count() != files.len() {
        return Err(format!("the Python mcap reader refused a seed:\n{stdout}{stderr}"));
    }
    eprintln!("fuzz: the Python mcap reader read all {} seed MCAP files with valid CRCs", files.len());
    Ok(())
}

/// Reads a board set through the library: what the `boardset-read` target runs.
fn read_board_set(path: &Path) -> ExitCode {
    match mbrl::data::boardset::read_board_set(path) {
        Ok(set) => {
            println!("{} boards of {}", set.boards.len(), set.game);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Some(Child::ReadBoardSet { path }) = &cli.child {
        return read_board_set(path);
    }
    let all = targets();
    if cli.list {
        for target in &all {
            println!("{}", target.name);
        }
        return ExitCode::SUCCESS;
    }
    // 2: the campaign could not run; 1: it ran and found something.
    let setup_error = |message: String| {
        eprintln!("mbrl-fuzz: error: {message}");
        ExitCode::from(2)
    };
    let settings = match settings(&cli) {
        Ok(settings) => settings,
        Err(message) => return setup_error(message),
    };
    if !settings.binary.is_file() {
        let hint = if cli.bin.is_none() && std::env::var_os("MBRL_FUZZ_BIN").is_none() {
            ": build it with `cargo build --release` in the repository root, or pass --bin PATH"
        } else {
            ""
        };
        return setup_error(format!("{} not found{hint}", settings.binary.display()));
    }
    let targets: Vec<&Target> =
        all.iter().filter(|t| settings.only.is_empty() || settings.only.iter().any(|o| t.name.contains(o))).collect();
    if targets.is_empty() {
        return setup_error(format!("--targets {}: matches no target (see --list)", settings.only.join(",")));
    }
    // Absolute: the children run inside the seed directory.
    let dir = match std::path::absolute(&cli.dir) {
        Ok(dir) => dir,
        Err(e) => return setup_error(format!("{}: {e}", cli.dir.display())),
    };
    WORK.set(dir).expect("set once");
    eprintln!("fuzz: testing {}", settings.binary.display());
    if let Err(message) = generate(&settings.binary) {
        return setup_error(message);
    }
    let outcome = seeds_pass_the_python_mcap_reader(seeds()).and_then(|()| fuzz_every_reader(&settings, &targets));
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(report) => {
            eprintln!("mbrl-fuzz: {report}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The verdicts of the kinds of endings a run can have (wait statuses as the kernel reports them).
    #[test]
    fn classification_of_endings() {
        let exit = |code: i32| Some(ExitStatus::from_raw(code << 8));
        let signal = |sig: i32| Some(ExitStatus::from_raw(sig));
        assert_eq!(classify(exit(0), ""), Verdict::Ok);
        assert_eq!(classify(exit(1), "error: x.mcap: not a readable MCAP file\n"), Verdict::CleanError);
        assert_eq!(classify(exit(2), "error: unexpected argument '--x' (see 'mbrl --help')\n"), Verdict::CleanError);
        assert_eq!(classify(exit(101), ""), Verdict::Panic);
        assert_eq!(classify(exit(1), "thread 'main' panicked at src/x.rs:1:1:\nerror: x\n"), Verdict::Panic);
        assert_eq!(classify(signal(6), "memory allocation of 68719476736 bytes failed\n"), Verdict::Abort(6));
        assert_eq!(classify(signal(11), ""), Verdict::Abort(11));
        assert_eq!(classify(None, ""), Verdict::Hang);
        assert_eq!(classify(exit(1), "progress 3/5\nerror: late\n"), Verdict::Unclean(1));
        assert_eq!(classify(exit(3), "error: x\n"), Verdict::Unclean(3));
    }
}
