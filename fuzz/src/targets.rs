//! The targets: every reader of the binary, each with the input it mutates and a cheap command that reaches it.

/// What a target mutates.
#[derive(Clone, Copy)]
pub(crate) enum Input {
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
pub(crate) enum Kind {
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
pub(crate) enum Program {
    /// `mbrl --threads 1 -q <args>`.
    Mbrl,
    /// This binary as `read-board-set <args>`, reading the board set through the library.
    BoardSetReader,
}

pub(crate) struct Target {
    pub(crate) name: &'static str,
    pub(crate) input: Input,
    pub(crate) program: Program,
    /// The command after `mbrl --threads 1 -q` (or after this binary), split at spaces; `{in}` is the mutant
    /// (one argument whatever it holds), `{out}` a fresh output path.
    pub(crate) args: &'static str,
    /// The unmutated seed is refused with a clean error by design (a board set is not a dataset).
    pub(crate) seed_is_refused: bool,
    /// Exit codes the command documents as results, not errors (see `runner::classify`).
    pub(crate) outcomes: &'static [i32],
}

pub(crate) const fn target(name: &'static str, input: Input, args: &'static str) -> Target {
    Target { name, input, program: Program::Mbrl, args, seed_is_refused: false, outcomes: &[] }
}

pub(crate) const fn mcap(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Mcap }
}

pub(crate) const fn text(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Text }
}

pub(crate) const fn png(seed: &'static str) -> Input {
    Input::File { seed, kind: Kind::Png }
}

/// CEM settings that make a planning run take milliseconds.
macro_rules! cheap_plan {
    () => {
        " --steps 2 --candidates 16 --elites 4 --iters 1"
    };
}

/// Every reader, with a cheap command that reaches it.
pub(crate) fn targets() -> Vec<Target> {
    const MODEL_FILES: &[&str] = &["checkpoint.json", "config.json", "model.safetensors"];
    const SWEEP_FILES: &[&str] = &[
        "sweep.json",
        "runs/train/preset-small_seed-0/job.json",
        "runs/eval/preset-small_seed-1_transitions-2/job.json",
        "runs/eval/preset-small_seed-1_transitions-2/report/summary.json",
    ];
    const EKF_FILES: &[&str] = &["checkpoint.json", "config.json", "params.json", "spin_net.json", "model.safetensors"];
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
        // The report of every kind of rollout dataset: time axes, state panels, returns.
        target("pairs-eval", mcap("ctx.mcap"), "eval dataset --input {in} --out {out}"),
        target("quadrant-eval", mcap("quad.mcap"), "eval dataset --input {in} --out {out}"),
        target("unicycle-eval", mcap("uni.mcap"), "eval dataset --input {in} --out {out}"),
        target("calib-eval", mcap("calib.mcap"), "eval dataset --input {in} --out {out}"),
        target("mountaincar-eval", mcap("mc.mcap"), "eval dataset --input {in} --out {out}"),
        target("rollouts-export", mcap("roll.mcap"), "export --input {in} --format npz --out {out}"),
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
        target("ball-predict", mcap("ball.mcap"), "predict --model ekf --input {in} --horizon 0.2s --out {out}"),
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
        // Torques past the Reacher's bound, and unicycle commands that could stall its adaptive integrator.
        target(
            "actions-reacher",
            text("reacher.csv"),
            "collect --env lightsout:reacher --actions {in} --init-state 0.5,1.2,0,0 --out {out}",
        ),
        target(
            "actions-unicycle",
            text("unicycle.csv"),
            "collect --env unicycle --map map.png --actions {in} --init-state 0.3,0.4,0,1 --out {out}",
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
        target(
            "init-state-mountaincar",
            Input::Arg { seed: "0.2,-0.5" },
            "collect --env mountaincar --actions actions.csv --init-state={in} --out {out}",
        ),
        target(
            "init-state-toy",
            Input::Arg { seed: "0.1,-0.2" },
            "collect --env toy:inner --actions actions.csv --init-state={in} --out {out}",
        ),
        // Calibration takes a start of its own, checked by the same rules as a replay's.
        target(
            "init-state-calibrate",
            Input::Arg { seed: "0.1,-0.2" },
            concat!(
                "calibrate --model context-model --env toy:inner --instance-seed 1 --strategy random ",
                "--transitions 2 --init-state={in} --out {out}"
            ),
        ),
        // The number inside an env name.
        target("env-mass", Input::Arg { seed: "1.5" }, "collect --env pendulum:mass={in} --rollouts 1 --steps 3 --out {out}"),
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
            Input::Checkpoint { dir: "ekf", files: EKF_FILES },
            "predict --model {in} --input ball.mcap --horizon 0.2s --out {out}",
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
        // The evals that plan or fit with tiny settings, for their numeric flags and the models they load.
        target(
            "swingup-eval",
            Input::Checkpoint { dir: "pets", files: MODEL_FILES },
            concat!(
                "eval pendulum-swingup --model {in} --episodes 1 --steps 25 --particles 2 --horizon 3 ",
                "--candidates 16 --elites 4 --iters 1 --out {out}"
            ),
        ),
        target(
            "tradyn-eval",
            Input::Checkpoint { dir: "tradyn-model-nt", files: MODEL_FILES },
            concat!(
                "eval tradyn --model-terrain tradyn-model --model-no-terrain {in} --maps terrain --tasks 2 ",
                "--transitions 2 --steps 2 --horizon 3 --candidates 16 --elites 4 --iters 1 --prediction-steps 2 --out {out}"
            ),
        ),
        target(
            "ekf-eval",
            Input::Checkpoint { dir: "ekf", files: EKF_FILES },
            "eval ball --model {in} --train-shots 2 --test-shots 1 --unseen-shots 1 --augment-rotations 0 --out {out}",
        ),
        target(
            "embodied-eval",
            Input::Arg { seed: "lightsout" },
            "eval embodied --game={in} --embodiment cursor --max-depth 1 --boards 1 --out {out}",
        ),
        // A finished sweep: its plan, jobs' outcomes and an eval summary, read by `status` and `report` from
        // the copy (a sweep is read where it lies).
        // `sweep status` exits 1 when a job failed and 3 when some are unfinished: a damaged record is either.
        Target {
            outcomes: &[1, 3],
            ..target("sweep-status", Input::Checkpoint { dir: "sweep-done", files: SWEEP_FILES }, "sweep status {in}")
        },
        target(
            "sweep-report",
            Input::Checkpoint { dir: "sweep-done", files: SWEEP_FILES },
            "sweep report {in} --out {out}",
        ),
        // A report's config.json, rerun with `--config`; and KEY=VALUE settings, whose numbers are arguments.
        target("report-config-swingup", text("swingup/config.json"), "eval pendulum-swingup --config {in} --out {out}"),
        target("report-config-ball", text("ball-report/config.json"), "eval ball --config {in} --out {out}"),
        target("report-config-context", text("context-report/config.json"), "eval context --config {in} --out {out}"),
        target("report-config-dlgpd", text("dlgpd-report/config.json"), "eval dlgpd --config {in} --out {out}"),
        target("report-config-seads", text("seads-report/config.json"), "eval seads --config {in} --out {out}"),
        target("report-config-tradyn", text("tradyn-report/config.json"), "eval tradyn --config {in} --out {out}"),
        target(
            "report-config-embodied",
            text("embodied-report/config.json"),
            "eval embodied --config {in} --out {out}",
        ),
        target(
            "override-eval",
            Input::Arg { seed: "1" },
            "eval ball --config ball-report/config.json --out {out} settings.test_shots_default={in}",
        ),
        target(
            "override-learning-rate",
            Input::Arg { seed: "0.001" },
            "train --method context --data ctx.mcap --config context.toml --steps 1 --out {out} optimizer.learning_rate={in}",
        ),
        target(
            "override-size",
            Input::Arg { seed: "16" },
            "train --method pets --data roll.mcap --config pets.toml --ensemble 1 --steps 1 --out {out} hidden_units={in}",
        ),
    ]
}

/// The files `train --resume` reads.
pub(crate) const RESUME_FILES: &[&str] =
    &["checkpoint.json", "config.json", "model.safetensors", "state.safetensors", "metrics.jsonl"];
