# Print an optspec for argparse to handle cmd's options that are independent of any subcommand.
function __fish_mbrl_global_optspecs
    string join \n seed= threads= tui hold no-tui force q/quiet job-dir= max-memory-gib= h/help V/version
end

function __fish_mbrl_needs_command
    # Figure out if the current invocation already has a command.
    set -l cmd (commandline -opc)
    set -e cmd[1]
    argparse -s (__fish_mbrl_global_optspecs) -- $cmd 2>/dev/null
    or return
    if set -q argv[1]
        # Also print the command, so this can be used to figure out what it is.
        echo $argv[1]
        return 1
    end
    return 0
end

function __fish_mbrl_using_subcommand
    set -l cmd (__fish_mbrl_needs_command)
    test -z "$cmd"
    and return 1
    contains -- $cmd[1] $argv
end

complete -c mbrl -n "__fish_mbrl_needs_command" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_needs_command" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_needs_command" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_needs_command" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_needs_command" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_needs_command" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_needs_command" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_needs_command" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_needs_command" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_needs_command" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_needs_command" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "collect" -d 'Collect rollouts from a simulator into an MCAP dataset'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "plan" -d 'Plan with CEM on a model and execute the plan in the simulator (MPC)'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "train" -d 'Train a model and write it to a checkpoint directory (config.json, weights, metrics.jsonl)'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "calibrate" -d 'Calibrate a context model in an instance of its env by expected information gain'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "filter" -d 'Filter table-tennis ball recordings with the gray-box EKF (thesis chapter 6)'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "predict" -d 'Predict table-tennis ball trajectories: filter until a horizon before the end, then predict ahead'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "solve-board" -d 'Find a shortest solution of a LightsOut or TileSwap board and optionally play it with a manipulator'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "eval" -d 'Run an evaluation protocol and write a report directory (report.md, CSV, PNG, summary.json, config.json)'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "watch" -d 'Follow running or finished runs (training or eval) in the live view; several runs are overlaid'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "export" -d 'Convert a dataset, board set, ball recording or filter-estimate file to CSV or NumPy `.npz`, or a run\'s metrics to CSV'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "list" -d 'List envs, methods, presets or embodiments with their parameters'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "sweep" -d 'Plan seeds × settings of any command as Slurm job arrays or local job lists; follow and report them'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "completions" -d 'Print a shell completion script'
complete -c mbrl -n "__fish_mbrl_needs_command" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l env -d 'Environment: pendulum[:light|heavy|mass=<m>|inverted|quadrant], toy:inner|outer, mountaincar, unicycle (with --map or --maps), terrain (map sets), lightsout[:<n>x<n>], tileswap, <game>:cursor|reacher|jaco (a board game played by a manipulator, e.g. lightsout:cursor), ball' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l rollouts -d 'Number of rollouts, each in its own instance of a parametrized env' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l instances -d 'Instead of --rollouts: N instances with two rollouts each (ids 2k, 2k+1), for context models' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l actions -d 'Replay these actions (CSV: one row per step, one column per action dimension) instead of random ones' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l init-state -d 'With --actions: the start state, comma-separated (pendulum: θ,θ̇; toy: s1,s2; mountaincar: x,ẋ; unicycle: x,y,v,φ; <game>:cursor: x,y; <game>:reacher: shoulder,wrist,shoulder velocity,wrist velocity; <game>:jaco: 9 angles, 9 velocities)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l instance-seed -d 'With --actions: which instance of a parametrized env (default: --seed); the same seed names the same instance in every subcommand' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l board -d 'With --actions on <game>:cursor|reacher|jaco: the start board, comma-separated as solve-board takes it (default: the solved board)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l episodes -d 'For <game>:cursor|reacher|jaco: N skill episodes of random actions, each from a scrambled board' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l steps -d 'Steps per rollout' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l policy -d 'Behaviour policy' -r -f -a "random\t'Random actions: uniform within the action bounds (the unicycle: colored noise, as its authors drew)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l out -d 'Output file (default: datasets/<env>-random.mcap, <env>-pairs.mcap, <env>-replay.mcap, or <game>-boards-d<D>.mcap; when that exists, the first free name ending -2, -3, …). An existing --out is replaced only with --force' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l trajectories -d 'For the ball: number of simulated shots (each with exactly one table bounce)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l orientation -d 'For the ball: launcher pose, default or unseen-1..unseen-5 (thesis 6.5.1)' -r -f -a "default\t''
unseen-1\t''
unseen-2\t''
unseen-3\t''
unseen-4\t''
unseen-5\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l augment-rotations -d 'For the ball: rotated copies added per shot, about z through its lowest point (19 in the thesis)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l max-depth -d 'Deepest solution depth in a board set' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l split -d 'Only boards of this split (--boards), or the maps of this split of a map set (--maps DIR)' -r -f -a "train\t''
test\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l maps -d 'For --env terrain: how many maps to make. For --env unicycle: a map set directory (with terrain.json) whose --split maps the instances are drawn on' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l map -d 'For --env unicycle: drive on this terrain map (an 8-bit RGB PNG)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l images -d 'Pendulum: also store a 64 × 64 RGB frame of every state (gym\'s rendering, DLGPD\'s observations), shown by Foxglove\'s Image panel on /frames'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l boards -d 'For board games: write the set of all boards of solution depth 1..=--max-depth with their split'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand collect" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l env -d 'Environment: pendulum[:light|heavy|mass=<m>|inverted|quadrant] or unicycle' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
unicycle\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l model -d 'Dynamics the planner uses: `true` (the simulator\'s equations) or a checkpoint directory written by `mbrl train` (e.g. models/pets-pendulum)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l particles -d 'Particles per candidate for stochastic learned models (PETS: trajectory sampling)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l propagation -d 'How particles use the ensemble members' -r -f -a "ts1\t'TS-1: each particle draws an ensemble member anew at every step'
tsinf\t'TS-∞: each particle keeps one member for the whole horizon'
expectation\t'Each member\'s mean prediction, no sampling'"
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l context -d 'Calibration transitions (`mbrl calibrate --out`) a context model is conditioned on; without it the model plans with its prior mean context' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l steps -d 'Steps to execute (pendulum 150; unicycle 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l map -d 'Unicycle: the terrain map (PNG) to drive on' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l start -d 'Unicycle: start pose x,y,φ (position in [0, 1]², heading in radians; the robot starts at rest)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l goal -d 'Unicycle: goal position x,y in [0, 1]²' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l horizon -d 'Planning horizon in steps (pendulum 20; unicycle 30, shrinking to the steps left)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l candidates -d 'Candidate action sequences per iteration (1000)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l elites -d 'Elite candidates used to refit the sampling distribution (pendulum 100; unicycle 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l iters -d 'CEM iterations per planning call (pendulum 10; unicycle 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l noise -d 'Sampling noise (pendulum white; unicycle colored)' -r -f -a "white\t'Independent Gaussian samples (thesis Algorithm 1)'
colored\t'Power spectral density ∝ 1/f^β along time (iCEM)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l beta -d 'Exponent β of colored noise (0.5; used with --noise colored)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l evidence -d 'DLGPD models: rollouts to condition the GPs on (a dataset written by `collect`)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l instance-seed -d 'Plan in the instance (hidden parameters) this seed names, as `calibrate --instance-seed` does' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l out -d 'Where to save the executed rollout (default: datasets/plan-<env>-<model>.mcap, <model> being `true` or the checkpoint\'s directory name; when that exists, the first free name ending -2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l allow-incomplete -d 'Take a run still in training (its best-validation weights so far); the output says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l no-warm-start -d 'Start every planning call from zero instead of the previous plan shifted by one step'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand plan" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l resume -d 'Continue the stopped run in this checkpoint directory; the method, config and data are the checkpoint\'s' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l steps -d 'With --resume: train a pets or dlgpd run, finished or not, on to this many steps in total' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "pets" -d 'Probabilistic ensemble of MLPs on (state, action) → state change (PETS, Chua et al. 2018), for any env that `collect` rolls out; plan with it via `mbrl plan --model DIR`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "ball-ekf" -d 'Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by maximizing the filter\'s marginal likelihood (thesis 6.4.4, eq. 6.24)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "context" -d 'Context-conditional GRU dynamics with a context encoder (Explore the Context, thesis ch. 4), trained on instance-pair datasets (`collect --instances N`); calibrate with `mbrl calibrate`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "tradyn" -d 'TRADYN (thesis ch. 5): the context model on the unicycle\'s observation with the terrain under the robot as input, read from the map at predicted positions; --no-terrain trains the ablation that predicts it'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "seads" -d 'SEADS (thesis ch. 7): skill policies (SAC) and a symbolic forward model learned without reward in an embodied board game; needs no --data, it collects its own episodes'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "dlgpd" -d 'DLGPD (thesis ch. 3): a VAE on pendulum frames (`collect --images`) with Gaussian-process latent dynamics and reward; plan with `mbrl plan --model DIR --evidence E.mcap`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and not __fish_seen_subcommand_from pets ball-ekf context tradyn seads dlgpd help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l data -d 'Rollout datasets (.mcap) of one env, merged (repeatable)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l env -d 'The env the data must come from (default: the dataset\'s env)' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l config -d 'Hyperparameters over the preset\'s: a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l preset -d 'Network size and training length (default: small)' -r -f -a "small\t'3 hidden layers × 64 SiLU units, 2000 steps (≈ 10 s on 2 cores)'
medium\t'4 × 200 SiLU units, 5000 steps: mbrl-lib\'s PETS pendulum network'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l ensemble -d 'Ensemble members (default 5)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l steps -d 'Optimizer steps (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l batch -d 'Transitions per member in a batch (default 256)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l lr -d 'Adam learning rate (default 1e-3)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l reward -d 'Where the model\'s reward comes from (default: known where the env has a closed form)' -r -f -a "known\t'The env\'s closed-form reward (pendulum variants without hidden actuators)'
learned\t'An extra output of the network, trained on the dataset\'s rewards'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l out -d 'Checkpoint directory (default: models/pets-<env>)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from pets" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l data -d 'A ball dataset (.mcap) or a .csv recording' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l config -d 'Training settings over the thesis\': a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l steps -d 'Optimizer steps (default 1000)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l batch -d 'Chunks in a batch (thesis: 64)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l chunk -d 'Frames per chunk (thesis: 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l lr -d 'Adam learning rate (thesis: 5e-3)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l out -d 'Checkpoint directory (default: models/ball-ekf)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l launcher-prior -d 'Learn the spin prior from launcher settings (thesis C.1.3); recordings need side information'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from ball-ekf" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l data -d 'An instance-pair dataset (.mcap) from `mbrl collect --instances N`' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l env -d 'The env the data must come from (default: the dataset\'s env)' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l preset -d 'Network size and training length (default: small)' -r -f -a "small\t'Toy: 32 units, 20-state chunks, lr 3e-3, 1200 steps (about 25 s; what `eval quick` trains). Pendulum and MountainCar: 64 units, 5000 steps (minutes)'
medium\t'The thesis networks (200 units) for a tenth of its steps: toy 5000, pendulum and MountainCar 10 000'
paper\t'Table B.1: 200 units; toy 50 000 steps at batch 64, pendulum and MountainCar 100 000 at batch 512 (days on 2 cores)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l config -d 'Hyperparameters over the preset\'s: a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l steps -d 'Optimizer steps (default: the preset\'s); the p_ctx schedule keeps its shares of the run' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l batch -d 'Chunks of consecutive states in a batch (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l lr -d 'Adam learning rate (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l out -d 'Checkpoint directory (default: models/context-<env>)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from context" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l data -d 'A unicycle instance-pair dataset (.mcap): `collect --env unicycle --maps DIR --split train --instances N`' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l env -d 'The env: TRADYN models the unicycle, the only value taken' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l preset -d 'Network size and training length (default: small)' -r -f -a "small\t'64 units, 5000 steps at batch 64 (minutes on 2 cores; what `eval quick` trains)'
medium\t'200 units, 10 000 steps at batch 128'
paper\t'200 units, 100 000 steps at batch 512 (days on 2 cores)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l config -d 'Hyperparameters over the preset\'s: a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l steps -d 'Optimizer steps (default: the preset\'s); the p_ctx schedule keeps its shares of the run' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l batch -d 'Chunks of consecutive states in a batch (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l lr -d 'Adam learning rate (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l out -d 'Checkpoint directory (default: models/tradyn-terrain, models/tradyn-no-terrain)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l no-terrain -d 'Ablation (thesis "−T"): no terrain lookup; the terrain features become part of the predicted state'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from tradyn" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l env -d 'The embodied board game: lightsout:cursor, tileswap:cursor, lightsout:reacher or tileswap:reacher' -r -f -a "lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l config -d 'Hyperparameters over the preset\'s: a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l preset -d 'Network sizes and budget of environment steps (default: small)' -r -f -a "small\t'A short budget for tests and `eval quick` (about a minute for a Cursor game on 2 cores): SAC of 64 units and the paper\'s forward model (256 units) with 16 Adam steps per epoch instead of 4'
medium\t'The paper\'s networks (256 units) on a fifth of the Cursor budget'
paper\t'The paper\'s networks and budgets: 500k environment steps on the Cursor, 10M on the Reacher'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l skills -d 'Number of skills K (default: the game\'s move count, 25 LightsOut, 12 TileSwap)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l env-steps -d 'Budget of environment steps (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l out -d 'Checkpoint directory (default: models/seads-<env>)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l no-relabel -d 'Ablation: no relabelling of skill labels'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l no-second-best -d 'Ablation: no second-best normalization of the reward'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l no-novelty -d 'Ablation: no novelty bonus in the reward'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from seads" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l data -d 'Pendulum rollouts (.mcap), merged (repeatable): with frames (`collect --images`) for the medium and paper presets, any for the small one' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l env -d 'The env the data must come from (default: the dataset\'s env)' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l config -d 'Hyperparameters over the preset\'s: a TOML file of config keys, or a run\'s config.json to rerun it' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l preset -d 'Model and training size (default: small, which learns from the pole angle instead of frames)' -r -f -a "small\t'An MLP VAE on the pole direction (cos θ, sin θ) instead of frames, batch 256, 3000 steps: minutes on 2 cores; any pendulum data'
medium\t'The paper\'s conv VAE on 64 × 64 frames at batch 128 for 3000 steps (about an hour on 2 cores)'
paper\t'The paper: batch 1024, 28 000 steps (2000 epochs of 14 000 transitions; days on 2 cores)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l steps -d 'Optimizer steps (default: the preset\'s)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l batch -d 'Transitions in a batch (default: the preset\'s; the paper 1024)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l lr -d 'Adam learning rate (default 1e-3)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l out -d 'Checkpoint directory (default: models/dlgpd-pendulum)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l resume-if-stopped -d 'Resume the stopped run in --out when this command started it (same method, config, data and seed; a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without this flag. A re-run script then loses none of an interrupted run\'s training'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from dlgpd" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "pets" -d 'Probabilistic ensemble of MLPs on (state, action) → state change (PETS, Chua et al. 2018), for any env that `collect` rolls out; plan with it via `mbrl plan --model DIR`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "ball-ekf" -d 'Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by maximizing the filter\'s marginal likelihood (thesis 6.4.4, eq. 6.24)'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "context" -d 'Context-conditional GRU dynamics with a context encoder (Explore the Context, thesis ch. 4), trained on instance-pair datasets (`collect --instances N`); calibrate with `mbrl calibrate`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "tradyn" -d 'TRADYN (thesis ch. 5): the context model on the unicycle\'s observation with the terrain under the robot as input, read from the map at predicted positions; --no-terrain trains the ablation that predicts it'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "seads" -d 'SEADS (thesis ch. 7): skill policies (SAC) and a symbolic forward model learned without reward in an embodied board game; needs no --data, it collects its own episodes'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "dlgpd" -d 'DLGPD (thesis ch. 3): a VAE on pendulum frames (`collect --images`) with Gaussian-process latent dynamics and reward; plan with `mbrl plan --model DIR --evidence E.mcap`'
complete -c mbrl -n "__fish_mbrl_using_subcommand train; and __fish_seen_subcommand_from help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l model -d 'A context-model checkpoint (`mbrl train context`, or `mbrl train tradyn` for the unicycle)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l env -d 'Environment the model was trained on, e.g. toy:inner, pendulum:quadrant, mountaincar, unicycle' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l map -d 'For --env unicycle: the terrain map (PNG) the robot calibrates on' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l instance-seed -d 'Which instance (hidden parameters) to calibrate in' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l strategy -r -f -a "random\t'Uniformly random actions (the baseline)'
open-loop\t'One action sequence maximizing the expected information gain, planned at the start (eq. 4.36)'
mpc\t'Replan the EIG-optimal sequence after every transition, horizon min(H_max, N − n) (eq. 4.37)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l transitions -d 'Calibration transitions N (default 30; TRADYN 10)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l horizon -d 'H_max: the longest planning horizon of MPC calibration' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l candidates -d 'CEM candidates per iteration' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l elites -d 'CEM elites' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l iters -d 'CEM iterations' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l beta-samples -d 'β samples of the Monte Carlo information gain' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l init-state -d 'Start state, comma-separated in the env\'s state order (pendulum: θ,θ̇; unicycle: x,y,v,φ). Default: the thesis\' start (toy x = 0; MountainCar x = ẋ = 0; pendulum:quadrant hanging down, |θ − π|, |θ̇| ≤ 0.05, drawn from --seed), elsewhere a reset drawn from --seed' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l out -d 'Where to write the calibration transitions (default: datasets/calib-<env>-<strategy>-i<S>.mcap; when that exists, the first free name ending -2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l allow-incomplete -d 'Take a run still in training (its best-validation weights so far); the output says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand calibrate" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l model -d 'Ball model: thesis, initial, or a checkpoint directory' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l input -d 'Recordings: a .mcap ball dataset or a .csv recording' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l out -d 'CSV output: per frame the measurement, the state mean and its standard deviations (default: filtered.csv; when that exists, the first free filtered-2.csv, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l mcap -d 'Also write the means with full covariances as MCAP' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand filter" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l model -d 'Ball model: thesis, initial, or a checkpoint directory' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l input -d 'Recordings: a .mcap ball dataset or a .csv recording' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l horizon -d 'How far to predict: seconds with an `s` suffix (1s, 0.5s) or camera frames with `f` (90f)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l from-frame -d 'Filter until this camera frame instead of one horizon before the end' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l plane-y -d 'Report the crossing of the plane y = this value [m]' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l out -d 'CSV of predicted points (default: predicted.csv; when that exists, the first free predicted-2.csv, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand predict" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l game -d 'Game: lightsout (5x5), lightsout:<n>x<n> (n = 2..13), tileswap (default with a SEADS --model: its game)' -r -f -a "lightsout\t''
tileswap\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l board -d 'The board to solve' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l random-depth -d 'Draw a random board whose shortest solution has this many moves (5x5 LightsOut, TileSwap)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l split -d 'Draw the random board from this split only (thesis appendix D.1.4)' -r -f -a "train\t''
test\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l model -d 'Successor model: `true` (the game\'s rules) or a SEADS checkpoint directory (its learned forward model and skill policies)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l max-replans -d 'Replans allowed when a skill\'s outcome differs from the model\'s prediction (SEADS --model)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l embodiment -d 'Play the plan with this manipulator\'s scripted controller' -r -f -a "cursor\t'A point moved by steps of at most 0.2, pushing where it stands (10 steps per move)'
reacher\t'A torque-driven two-link arm over a 0.3 m board (50 steps per move)'
jaco\t'The 9-DoF Kinova Jaco arm on MuJoCo, target joint velocities at 10 Hz (50 steps per move; needs a build with `make mujoco`)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l search -d 'Search algorithm' -r -f -a "bidirectional\t'From both ends (moves undo themselves); far fewer states'
bfs\t'From the start only, as the thesis\' planner'"
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l max-depth -d 'Longest plan searched for' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l max-nodes -d 'Give up after storing this many states' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l max-memory-mib -d 'Give up when the search needs more memory than this (MiB)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l allow-incomplete -d 'Take a SEADS run still in training (the weights of its last checkpoint); a warning says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand solve-board" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "quick" -d 'Small reproduction of every implemented method, each line with its thesis target and verdict (about 10.5 minutes on 2 cores)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "dataset" -d 'Summarise a dataset: rollouts, returns, state ranges, plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "boards" -d 'Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "embodied" -d 'A manipulator\'s scripted controller plays optimal plans of boards of depth 1..D'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "ball" -d 'Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "context" -d 'Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "tradyn" -d 'TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "seads" -d 'SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "dlgpd" -d 'DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "pendulum-swingup" -d 'Pendulum swing-up with MPC: success rate, returns, angle plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "render" -d 'Redraw a report (report.md, CSVs, PNGs) from its summary.json, without rerunning anything'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and not __fish_seen_subcommand_from quick dataset boards embodied ball context tradyn seads dlgpd pendulum-swingup render help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l out -d 'Report directory (default: reports/quick; when that exists, the first free reports/quick-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l config -d 'Rerun with the seed a quick report recorded (its config.json)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from quick" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l input -d 'Dataset file written by `mbrl collect` or `mbrl plan`' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l out -d 'Report directory (default: reports/dataset; when that exists, the first free reports/dataset-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l config -d 'Redo the report of the dataset a dataset report recorded (its config.json)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dataset" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l out -d 'Report directory (default: reports/boards; when that exists, the first free reports/boards-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l config -d 'Rerun with the seed a boards report recorded (its config.json)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from boards" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l game -d 'Game: lightsout (5x5) or tileswap' -r -f -a "lightsout\t''
tileswap\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l embodiment -d 'Manipulator' -r -f -a "cursor\t'A point moved by steps of at most 0.2, pushing where it stands (10 steps per move)'
reacher\t'A torque-driven two-link arm over a 0.3 m board (50 steps per move)'
jaco\t'The 9-DoF Kinova Jaco arm on MuJoCo, target joint velocities at 10 Hz (50 steps per move; needs a build with `make mujoco`)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l max-depth -d 'Boards of depth 1..=max-depth are evaluated' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l boards -d 'Boards drawn per depth (fewer when the split has fewer)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l split -d 'Split the boards come from' -r -f -a "train\t''
test\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l out -d 'Report directory (default: reports/embodied; when that exists, the first free reports/embodied-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l config -d 'Rerun the settings and seed an embodied report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from embodied" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l model -d 'EKF models to compare (repeatable): thesis, initial, or checkpoint directories' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l train-shots -d 'Default-pose shots the black-box baseline is fitted on' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l augment-rotations -d 'Rotated copies per training shot' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l test-shots -d 'Default-pose test shots' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l unseen-shots -d 'Test shots per unseen pose (5 poses)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l out -d 'Report directory (default: reports/ball; when that exists, the first free reports/ball-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l config -d 'Rerun the settings and seed a ball report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from ball" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l model -d 'A context-model checkpoint (`mbrl train context`)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l env -d 'The env the model was trained on' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''
toy:inner\t''
toy:outer\t''
mountaincar\t''
unicycle\t''
terrain\t''
lightsout\t''
tileswap\t''
lightsout:cursor\t''
lightsout:reacher\t''
tileswap:cursor\t''
tileswap:reacher\t''
lightsout:jaco\t''
tileswap:jaco\t''
ball\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l contexts -d 'Unseen contexts (instances) to calibrate in (thesis: 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l validation-rollouts -d 'Random validation rollouts per context (thesis: 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l validation-steps -d 'Steps per validation rollout (thesis: 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l transitions -d 'Calibration transitions N (toy 1–3, pendulum 30, MountainCar 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l horizon -d 'H_max of MPC calibration (pendulum 20, MountainCar 30)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l strategy -d 'Strategies to compare (repeatable; default: all three)' -r -f -a "random\t'Uniformly random actions (the baseline)'
open-loop\t'One action sequence maximizing the expected information gain, planned at the start (eq. 4.36)'
mpc\t'Replan the EIG-optimal sequence after every transition, horizon min(H_max, N − n) (eq. 4.37)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l candidates -d 'CEM candidates per iteration (thesis 1000)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l elites -d 'CEM elites (thesis 100)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l iters -d 'CEM iterations (thesis 10)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l beta-samples -d 'β samples of the information gain (thesis 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l swingup-steps -d 'Agent steps of each swing-up (thesis 50; the quadrant pendulum repeats each action twice)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l swingup-candidates -d 'CEM candidates of the swing-up planner (thesis 1000; elites are a tenth, 10 iterations, horizon 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l out -d 'Report directory (default: reports/context; when that exists, the first free reports/context-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l config -d 'Rerun the settings and seed a context report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l swingup -d 'Pendulum: after each calibration, swing up with MPC on the calibrated model (thesis 4.5.3), and once on the true equations as the reference'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l allow-incomplete -d 'Take a run still in training (its best-validation weights so far); the report says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from context" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l model-terrain -d 'The TRADYN model with terrain lookup (`mbrl train tradyn`): the +T variants' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l model-no-terrain -d 'The ablation trained with `--no-terrain`: the −T variants' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l maps -d 'The map set (`mbrl collect --env terrain`); tasks are drawn on its test maps' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l tasks -d 'Navigation tasks (thesis: 150 per model seed)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l transitions -d 'Random colored calibration transitions from each start (thesis 10)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l steps -d 'Executed steps per task (thesis 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l horizon -d 'Longest planning horizon (thesis 30; it shrinks to the steps left)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l candidates -d 'CEM candidates per iteration (thesis 1000; the default trades it for time on a CPU)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l elites -d 'CEM elites (thesis 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l iters -d 'CEM iterations (thesis 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l prediction-steps -d 'Length of the random rollout per task whose open-loop prediction is scored (thesis 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l out -d 'Report directory (default: reports/tradyn; when that exists, the first free reports/tradyn-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l config -d 'Rerun the settings and seed a tradyn report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l allow-incomplete -d 'Take runs still in training (their best-validation weights so far); the report says how far each got'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from tradyn" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l model -d 'A SEADS checkpoint directory (`mbrl train seads`); repeat it to compare runs (seeds of the full method and of ablations: one-sided Mann-Whitney U tests of each ablation against `full`)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l max-depth -d 'Boards of depth 1..=max-depth are solved' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l boards -d 'Boards per depth (thesis: 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l coverage-boards -d 'Boards every skill is executed from for the coverage table' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l max-replans -d 'Replans allowed per board (thesis: 10)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l split -d 'Split the boards come from' -r -f -a "train\t''
test\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l max-nodes -d 'A search storing more states than this counts as a failure (a model lacking a move can make the goal unreachable)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l out -d 'Report directory (default: reports/seads-<checkpoint name>)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l config -d 'Rerun the settings and seed a seads report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l allow-incomplete -d 'Take runs still in training (the weights of their last checkpoint); the report says how far each got'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from seads" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l model -d 'A DLGPD checkpoint (`mbrl train dlgpd`)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l env -d 'Settings to swing up (repeatable; default: the thesis\' pendulum, pendulum:inverted, pendulum:light, pendulum:heavy)' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l evidence-rollouts -d 'Evidence sizes in rollouts of 30 frames (thesis: 10, 20, 30, 50, 70, 100, 200)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l runs -d 'Runs per point, each with its own evidence pool and start state (thesis: 27)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l steps -d 'Steps per swing-up' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l candidates -d 'CEM candidates per iteration (the authors\': 1000, about 1.5 s a step on 2 cores at 10 evidence rollouts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l elites -d 'CEM elites (the authors\': 100)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l iters -d 'At most this many CEM iterations per step (the authors\': 30, stopping at first-action std ≤ 0.01)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l out -d 'Report directory (default: reports/dlgpd; when that exists, the first free reports/dlgpd-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l config -d 'Rerun the settings and seed a dlgpd report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l prediction-only -d 'Skip the swing-ups: only check the conditioned models\' reward predictions on held-out rollouts (seconds instead of an hour; tells a model that cannot see the pendulum from a planner that fails)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l allow-incomplete -d 'Take a run still in training (its best-validation weights so far); the report says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from dlgpd" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l model -d 'Dynamics the planner uses: `true` (the simulator\'s equations) or a checkpoint directory written by `mbrl train` (e.g. models/pets-pendulum)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l particles -d 'Particles per candidate for stochastic learned models (PETS: trajectory sampling)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l propagation -d 'How particles use the ensemble members' -r -f -a "ts1\t'TS-1: each particle draws an ensemble member anew at every step'
tsinf\t'TS-∞: each particle keeps one member for the whole horizon'
expectation\t'Each member\'s mean prediction, no sampling'"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l context -d 'Calibration transitions (`mbrl calibrate --out`) a context model is conditioned on; without it the model plans with its prior mean context' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l episodes -d 'Number of episodes (each with its own start state)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l env -d 'Environment variant: pendulum[:light|heavy|mass=<m>|inverted|quadrant]' -r -f -a "pendulum\t''
pendulum:light\t''
pendulum:heavy\t''
pendulum:inverted\t''
pendulum:quadrant\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l steps -d 'Steps per episode' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l horizon -d 'Planning horizon in steps (pendulum 20; unicycle 30, shrinking to the steps left)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l candidates -d 'Candidate action sequences per iteration (1000)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l elites -d 'Elite candidates used to refit the sampling distribution (pendulum 100; unicycle 50)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l iters -d 'CEM iterations per planning call (pendulum 10; unicycle 20)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l noise -d 'Sampling noise (pendulum white; unicycle colored)' -r -f -a "white\t'Independent Gaussian samples (thesis Algorithm 1)'
colored\t'Power spectral density ∝ 1/f^β along time (iCEM)'"
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l beta -d 'Exponent β of colored noise (0.5; used with --noise colored)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l out -d 'Report directory (default: reports/pendulum-swingup; when that exists, the first free reports/pendulum-swingup-2, -3, …)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l config -d 'Rerun the settings and seed a swing-up report recorded (its config.json); no other flag but --out, KEY=VALUE may change its settings' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l allow-incomplete -d 'Take a run still in training (its best-validation weights so far); the output says how far it got'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l no-warm-start -d 'Start every planning call from zero instead of the previous plan shifted by one step'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from pendulum-swingup" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from render" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "quick" -d 'Small reproduction of every implemented method, each line with its thesis target and verdict (about 10.5 minutes on 2 cores)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "dataset" -d 'Summarise a dataset: rollouts, returns, state ranges, plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "boards" -d 'Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "embodied" -d 'A manipulator\'s scripted controller plays optimal plans of boards of depth 1..D'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "ball" -d 'Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "context" -d 'Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "tradyn" -d 'TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "seads" -d 'SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "dlgpd" -d 'DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues)'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "pendulum-swingup" -d 'Pendulum swing-up with MPC: success rate, returns, angle plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "render" -d 'Redraw a report (report.md, CSVs, PNGs) from its summary.json, without rerunning anything'
complete -c mbrl -n "__fish_mbrl_using_subcommand eval; and __fish_seen_subcommand_from help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand watch" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l input -d 'An mbrl MCAP file (a dataset from `collect`, board set, ball recording or `filter --out *.mcap` output), or a run directory (or its metrics.jsonl) whose metrics to export' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l out -d 'Output file; its extension (.csv or .npz) chooses the format unless --format is given. Default: beside the input (see below)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l format -d 'csv or npz (metrics: csv only); must agree with --out\'s extension when that names a format' -r -f -a "csv\t''
npz\t''"
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand export" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -s h -l help -d 'Print help (see more with \'--help\')'
complete -c mbrl -n "__fish_mbrl_using_subcommand list" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -f -a "plan" -d 'Expand a spec into job lists and Slurm scripts in --out'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -f -a "status" -d 'Each job\'s standing: done, running, stopped at step k, failed (with its error), not started. Exits 1 when a job failed, 3 when none failed but some are not done'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -f -a "report" -d 'Per stage and cell (the grid values without the seed): n, mean, sd and a 95 % t interval of every scalar of the finished runs (eval summaries; trainings\' final metrics), learning curves as mean ± t interval over seeds, and the spec\'s [[compare]] tests; report.md, cells.csv, compare.csv, PNGs'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and not __fish_seen_subcommand_from plan status report help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l out -d 'The sweep\'s directory (created); rerunning the same spec there rewrites the same files' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l mbrl -d 'The binary the job lines run (default: this one), e.g. its path on the cluster\'s shared disk' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l allow-large -d 'Plan more than 10 000 jobs'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from plan" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from status" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l out -d 'Where the report goes (default: DIR/report; replaced on every report)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from report" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from help" -f -a "plan" -d 'Expand a spec into job lists and Slurm scripts in --out'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from help" -f -a "status" -d 'Each job\'s standing: done, running, stopped at step k, failed (with its error), not started. Exits 1 when a job failed, 3 when none failed but some are not done'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from help" -f -a "report" -d 'Per stage and cell (the grid values without the seed): n, mean, sd and a 95 % t interval of every scalar of the finished runs (eval summaries; trainings\' final metrics), learning curves as mean ± t interval over seeds, and the spec\'s [[compare]] tests; report.md, cells.csv, compare.csv, PNGs'
complete -c mbrl -n "__fish_mbrl_using_subcommand sweep; and __fish_seen_subcommand_from help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l seed -d 'Seed for every random choice; the same seed and thread count give the same output bytes' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l threads -d 'Worker threads (0 = one per core)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l job-dir -d 'Record this command\'s outcome in DIR/job.json (done, failed with its error, stopped) and hold DIR\'s lock while it runs; when DIR records this same command as done, do nothing. What makes a job list\'s lines safe to rerun (`mbrl sweep plan` adds it to every line)' -r -F
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l max-memory-gib -d 'Refuse work whose flags ask for more memory than this (estimated before it starts)' -r
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l tui -d 'Show the live terminal view (default when stdout is a terminal and MBRL_TUI is not `never`). It opens once the work has run a second and closes by itself when the work ends'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l hold -d 'Keep the live view open when the work ends, until q is pressed (also MBRL_TUI=hold)'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l no-tui -d 'Print plain progress lines on stderr instead of the live view'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -l force -d 'Replace an output named with --out (or another output flag) that exists; without it such a command is refused. Default output names never replace anything: a free numbered name is used'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -s q -l quiet -d 'Print only results and errors'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -s h -l help -d 'Print help'
complete -c mbrl -n "__fish_mbrl_using_subcommand completions" -s V -l version -d 'Print version'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "collect" -d 'Collect rollouts from a simulator into an MCAP dataset'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "plan" -d 'Plan with CEM on a model and execute the plan in the simulator (MPC)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "train" -d 'Train a model and write it to a checkpoint directory (config.json, weights, metrics.jsonl)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "calibrate" -d 'Calibrate a context model in an instance of its env by expected information gain'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "filter" -d 'Filter table-tennis ball recordings with the gray-box EKF (thesis chapter 6)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "predict" -d 'Predict table-tennis ball trajectories: filter until a horizon before the end, then predict ahead'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "solve-board" -d 'Find a shortest solution of a LightsOut or TileSwap board and optionally play it with a manipulator'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "eval" -d 'Run an evaluation protocol and write a report directory (report.md, CSV, PNG, summary.json, config.json)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "watch" -d 'Follow running or finished runs (training or eval) in the live view; several runs are overlaid'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "export" -d 'Convert a dataset, board set, ball recording or filter-estimate file to CSV or NumPy `.npz`, or a run\'s metrics to CSV'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "list" -d 'List envs, methods, presets or embodiments with their parameters'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "sweep" -d 'Plan seeds × settings of any command as Slurm job arrays or local job lists; follow and report them'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "completions" -d 'Print a shell completion script'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and not __fish_seen_subcommand_from collect plan train calibrate filter predict solve-board eval watch export list sweep completions help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "pets" -d 'Probabilistic ensemble of MLPs on (state, action) → state change (PETS, Chua et al. 2018), for any env that `collect` rolls out; plan with it via `mbrl plan --model DIR`'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "ball-ekf" -d 'Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by maximizing the filter\'s marginal likelihood (thesis 6.4.4, eq. 6.24)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "context" -d 'Context-conditional GRU dynamics with a context encoder (Explore the Context, thesis ch. 4), trained on instance-pair datasets (`collect --instances N`); calibrate with `mbrl calibrate`'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "tradyn" -d 'TRADYN (thesis ch. 5): the context model on the unicycle\'s observation with the terrain under the robot as input, read from the map at predicted positions; --no-terrain trains the ablation that predicts it'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "seads" -d 'SEADS (thesis ch. 7): skill policies (SAC) and a symbolic forward model learned without reward in an embodied board game; needs no --data, it collects its own episodes'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from train" -f -a "dlgpd" -d 'DLGPD (thesis ch. 3): a VAE on pendulum frames (`collect --images`) with Gaussian-process latent dynamics and reward; plan with `mbrl plan --model DIR --evidence E.mcap`'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "quick" -d 'Small reproduction of every implemented method, each line with its thesis target and verdict (about 10.5 minutes on 2 cores)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "dataset" -d 'Summarise a dataset: rollouts, returns, state ranges, plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "boards" -d 'Depth and train/test split tables of LightsOut 5x5 and TileSwap (thesis Tables 7.1, 7.2)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "embodied" -d 'A manipulator\'s scripted controller plays optimal plans of boards of depth 1..D'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "ball" -d 'Ball prediction error vs horizon on simulated shots, default and unseen launcher poses (thesis 6.5)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "context" -d 'Explore the Context (thesis 4.5): calibration strategies compared by prediction error after calibration'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "tradyn" -d 'TRADYN (thesis 5.5): ±terrain lookup × ±calibration on navigation tasks on test maps: energy, final distance, failures (Table 5.2), Wilcoxon on energies (Fig. 5.7), prediction error (Fig. 5.5), paths (Fig. 5.6)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "seads" -d 'SEADS (thesis 7.4): skill coverage, boards solved per depth with and without replanning, planning time'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "dlgpd" -d 'DLGPD (thesis 3.5.3): swing-up success and return vs evidence rollouts on the standard, inverted, light and heavy pendulum, with matching and mismatching evidence (Figs. 3.4/3.5 analogues)'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "pendulum-swingup" -d 'Pendulum swing-up with MPC: success rate, returns, angle plots'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from eval" -f -a "render" -d 'Redraw a report (report.md, CSVs, PNGs) from its summary.json, without rerunning anything'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from sweep" -f -a "plan" -d 'Expand a spec into job lists and Slurm scripts in --out'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from sweep" -f -a "status" -d 'Each job\'s standing: done, running, stopped at step k, failed (with its error), not started. Exits 1 when a job failed, 3 when none failed but some are not done'
complete -c mbrl -n "__fish_mbrl_using_subcommand help; and __fish_seen_subcommand_from sweep" -f -a "report" -d 'Per stage and cell (the grid values without the seed): n, mean, sd and a 95 % t interval of every scalar of the finished runs (eval summaries; trainings\' final metrics), learning curves as mean ± t interval over seeds, and the spec\'s [[compare]] tests; report.md, cells.csv, compare.csv, PNGs'
