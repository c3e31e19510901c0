//! The seed inputs, made by the binary under test itself, and the check that its MCAP files pass the official
//! Python reader.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

/// Tiny PETS network (as tests/cli/pets.rs).
pub(crate) const SWEEP_TOML: &str = "[sweep]\nname = \"fuzz\"\n[[stage]]\nname = \"train\"\n\
    command = \"train context --data ctx.mcap --config context.toml --steps 2 kl_weight=1\"\n\
    [stage.grid]\nseed = [0, 1]\n\"--preset\" = [\"small\"]\n[[stage]]\nname = \"eval\"\nafter = \"train\"\n\
    command = \"eval context --model {train} --env toy:inner --contexts 2\"\n[stage.grid]\n\"--transitions\" = [1, 2]\n\
    [slurm]\nmemory = \"1G\"\ntime = \"00:05:00\"\nmax_running = 2\n[[compare]]\nstage = \"eval\"\n\
    metric = \"mean_mse[0]\"\na = { transitions = 1 }\nb = { transitions = 2 }\n";
pub(crate) const PETS_TOML: &str = "hidden_layers = 2\nhidden_units = 16\nvalidate_every = 10\ncheckpoint_every = 20\n";
/// Tiny context model (as tests/cli/context.rs).
pub(crate) const CONTEXT_TOML: &str = "embedding = 16\nhidden_units = 16\ntransition_features = 8\nchunk_states = 10\n\
                            context_max = 4\nbatch_size = 8\nvalidate_every = 10\ncheckpoint_every = 10\n";
/// Tiny SEADS networks and memory (as tests/cli/seads.rs).
pub(crate) const SEADS_TOML: &str =
    "episodes_per_epoch = 4\nsampled_episodes = 8\nepisode_memory = 8\nmodel_hidden = 8\n\
                          sac_hidden = [8]\nsac_batch = 8\n";

/// The binary under test, copied into the seed directory (and with it next to saved failures).
pub(crate) const SNAPSHOT: &str = "bin/mbrl";
/// This binary, copied beside it: the child that reads board sets through the library.
pub(crate) const SELF_SNAPSHOT: &str = "bin/mbrl-fuzz";

/// `--dir`: the seeds go to `tmp/fuzz-seeds/` in it, the failures to `fuzz-failures/`.
pub(crate) static WORK: OnceLock<PathBuf> = OnceLock::new();

pub(crate) fn work() -> &'static Path {
    WORK.get().expect("the work directory is set before the campaign")
}

/// The seed directory, generated once at the start of a campaign.
pub(crate) fn seeds() -> &'static Path {
    static SEEDS: OnceLock<PathBuf> = OnceLock::new();
    SEEDS.get_or_init(|| work().join("tmp").join("fuzz-seeds"))
}

/// Makes the seed directory: private copies of the binaries, then every seed input.
pub(crate) fn generate(binary: &Path) -> Result<(), String> {
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
pub(crate) fn make(dir: &Path, args: &str) -> Result<(), String> {
    let mut command = Command::new(dir.join(SNAPSHOT));
    command.args(["--threads", "1", "-q", "--no-tui"]).args(args.split_whitespace());
    run_seeding(command, dir, &format!("mbrl {args}"))
}

/// Runs `command` in the seed directory; `what` names it in the error, with what it printed.
fn run_seeding(mut command: Command, dir: &Path, what: &str) -> Result<(), String> {
    let out = command.current_dir(dir).env("NO_COLOR", "1").output().map_err(|e| format!("seeding: {what}: {e}"))?;
    if !out.status.success() {
        let printed = String::from_utf8_lossy(&out.stderr) + String::from_utf8_lossy(&out.stdout);
        return Err(format!("seeding failed: {what}\n{printed}"));
    }
    Ok(())
}

/// A falling ball sampled at 180 Hz for 40 frames, frame 5 lost (the recording of tests/cli/common.rs).
pub(crate) fn falling_ball_csv() -> String {
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

pub(crate) fn generate_seeds(dir: &Path) -> Result<(), String> {
    let write = |name: &str, text: &str| fs::write(dir.join(name), text).unwrap();
    write("pets.toml", PETS_TOML);
    write("context.toml", CONTEXT_TOML);
    write("seads.toml", SEADS_TOML);
    write("sweep.toml", SWEEP_TOML);
    write("ball.csv", &falling_ball_csv());
    write("actions.csv", "u\n0.5\n-2\n1.5\n1e-3\n");
    write("cursor.csv", "dx,dy,push\n0.2,-0.2,-1\n0.1,-0.1,0.9\n0,0,-1\n");
    write("reacher.csv", "u1,u2,push\n1,-1,-1\n0.5,0.5,1\n0,0,1\n");
    write("unicycle.csv", "acceleration,turn\n0.5,0.1\n-0.5,1\n0,0\n");

    make(dir, "collect --env pendulum --rollouts 3 --steps 10 --out roll.mcap")?;
    make(dir, "collect --env pendulum --images --rollouts 2 --steps 4 --out img.mcap")?;
    make(dir, "collect --env mountaincar --rollouts 2 --steps 10 --out mc.mcap")?;
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
        "train --method tradyn --data uni.mcap --config context.toml --steps 3 --no-terrain --out tradyn-model-nt",
    )?;
    make(
        dir,
        "calibrate --model tradyn-model --env unicycle --map map.png --instance-seed 1 --strategy random --transitions 3 \
         --out calib-uni.mcap",
    )?;
    make(dir, "train --method dlgpd --data roll.mcap --steps 5 --batch 16 --out dlgpd")?;
    make(dir, "train --method ball-ekf --data ball.mcap --launcher-prior --steps 3 --batch 8 --out ekf")?;
    make(dir, "train --method seads --env tileswap:cursor --config seads.toml --env-steps 100 --out seads")?;
    make(dir, "eval pendulum-swingup --model true --episodes 1 --steps 25 --candidates 16 --elites 4 --out swingup")?;
    make(
        dir,
        "eval ball --model ekf --train-shots 2 --test-shots 1 --unseen-shots 1 --augment-rotations 0 --out ball-report",
    )?;
    // Reports whose config.json `eval --config` reruns.
    make(dir, "eval context --model context-model --env toy:inner --contexts 2 --transitions 2 --out context-report")?;
    make(dir, "eval dlgpd --model dlgpd --env pendulum --evidence-rollouts 1 --prediction-only --out dlgpd-report")?;
    make(dir, "eval seads --model seads --max-depth 1 --boards 1 --coverage-boards 1 --out seads-report")?;
    make(
        dir,
        "eval tradyn --model-terrain tradyn-model --model-no-terrain tradyn-model-nt --maps terrain --tasks 2 \
         --transitions 2 --steps 2 --horizon 3 --candidates 16 --elites 4 --iters 1 --prediction-steps 2 --out tradyn-report",
    )?;
    make(dir, "eval embodied --game lightsout --embodiment cursor --max-depth 1 --boards 1 --out embodied-report")?;
    // A finished two-stage sweep, for `sweep status` and `sweep report`.
    make(dir, "sweep plan sweep.toml --out sweep-done")?;
    let mut run_local = Command::new("bash");
    run_local.args(["sweep-done/run-local.sh", "1"]);
    run_seeding(run_local, dir, "sweep-done/run-local.sh 1")?;

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
pub(crate) fn without_nulls(value: serde_json::Value) -> serde_json::Value {
    match value {
        serde_json::Value::Object(map) => {
            map.into_iter().filter(|(_, v)| !v.is_null()).map(|(k, v)| (k, without_nulls(v))).collect()
        }
        other => other,
    }
}

/// Copies a directory tree (copies, not links: the copy is changed in place).
pub(crate) fn copy_dir(from: &Path, to: &Path) {
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

/// Every MCAP file the seeding wrote passes the official Python reader with CRC validation: seeking (summary,
/// chunk CRCs) and streaming (data-section CRC), with the message counts of the summary.
pub(crate) fn seeds_pass_the_python_mcap_reader(seeds: &Path) -> Result<(), String> {
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
