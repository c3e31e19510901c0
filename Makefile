# Reproduction pipelines and maintenance targets. Every target runs the released binary, so the numbers
# in a report come from running the method, never from a stored constant.

MBRL := target/release/mbrl
# Make remakes a target only when it is out of date, and then the output it names is meant to be replaced:
# `--force` lets each command do so (without it mbrl refuses to replace a named output that exists).
RUN := $(MBRL) --force
SEED ?= 0

.PHONY: build test bench bench-vs-pytorch completions mujoco mujoco-assets repro-jaco repro-seads-jaco repro-quick repro-swingup repro-pendulum-data repro-boards repro-ball repro-pets repro-pets-loop repro-context repro-context-toy repro-context-mountaincar repro-tradyn repro-seads repro-dlgpd clean-reports

# The Jaco arm (`--embodiment jaco`, `lightsout:jaco`) runs on MuJoCo behind the `mujoco` cargo feature; the
# default build stays MuJoCo-free. This target fetches MuJoCo 3.17.0 (the version mujoco-rs 7 binds) from its
# PyPI wheel and dm_control's Kinova Jaco model (with Kinova's BSD-3 licence) from the dm_control wheel into
# .mujoco/ (git-ignored), then builds with the feature. The binary finds libmujoco through an rpath and the
# Kinova files through a path compiled in (build.rs), so it runs without LD_LIBRARY_PATH.
MUJOCO_DIR := .mujoco
MUJOCO_WHEEL_VERSION := 3.17.0
DM_CONTROL_VERSION := 1.0.50
mujoco-assets: $(MUJOCO_DIR)/lib/libmujoco.so $(MUJOCO_DIR)/kinova/jaco_arm.xml
$(MUJOCO_DIR)/wheels/.fetched:
	mkdir -p $(MUJOCO_DIR)/wheels
	pip download --no-deps --only-binary=:all: --python-version 3.11 --platform manylinux_2_28_x86_64 \
		-d $(MUJOCO_DIR)/wheels mujoco==$(MUJOCO_WHEEL_VERSION) dm_control==$(DM_CONTROL_VERSION)
	touch $@
$(MUJOCO_DIR)/lib/libmujoco.so: $(MUJOCO_DIR)/wheels/.fetched
	rm -rf $(MUJOCO_DIR)/unpack && mkdir -p $(MUJOCO_DIR)/unpack $(@D)
	unzip -q -o $(MUJOCO_DIR)/wheels/mujoco-$(MUJOCO_WHEEL_VERSION)-*.whl 'mujoco/libmujoco.so.*' -d $(MUJOCO_DIR)/unpack
	cp $(MUJOCO_DIR)/unpack/mujoco/libmujoco.so.$(MUJOCO_WHEEL_VERSION) $(@D)/
	ln -sf libmujoco.so.$(MUJOCO_WHEEL_VERSION) $@
	rm -rf $(MUJOCO_DIR)/unpack
$(MUJOCO_DIR)/kinova/jaco_arm.xml: $(MUJOCO_DIR)/wheels/.fetched
	rm -rf $(MUJOCO_DIR)/unpack $(@D) && mkdir -p $(MUJOCO_DIR)/unpack
	unzip -q -o $(MUJOCO_DIR)/wheels/dm_control-$(DM_CONTROL_VERSION)-*.whl 'dm_control/third_party/kinova/*' \
		-d $(MUJOCO_DIR)/unpack
	mv $(MUJOCO_DIR)/unpack/dm_control/third_party/kinova $(@D)
	cp third_party/kinova/LICENSE $(@D)/LICENSE
	rm -rf $(MUJOCO_DIR)/unpack
mujoco: mujoco-assets
	cargo build --release --features mujoco

# Thesis 7.4.1 with the Jaco: its scripted controller (IK to each push point) on 100 boards of depth ≤ 5 per game.
repro-jaco: mujoco
	for game in lightsout tileswap; do \
		$(RUN) eval embodied --game $$game --embodiment jaco --max-depth 5 --boards 100 --seed $(SEED) \
			--no-tui --out reports/embodied-$$game-jaco || exit 1; \
	done

# Thesis 7.4 with the Jaco: SEADS on LightsOutJaco at SEADS_JACO_PRESET (small: 2M env steps, about 75 min on
# 2 cores; paper: the thesis' 10M, about five hours), then skill coverage and boards of depth 1-5 solved.
SEADS_JACO_PRESET ?= small
repro-seads-jaco: mujoco
	$(RUN) train seads --env lightsout:jaco --preset $(SEADS_JACO_PRESET) --seed $(SEED) --no-tui -q \
		--out models/seads-lightsout-jaco
	$(RUN) eval seads --model models/seads-lightsout-jaco --boards 20 --seed $(SEED) --no-tui -q \
		--out reports/seads-lightsout-jaco

build:
	cargo build --release

test:
	cargo test --release

bench:
	cargo bench

# Every learned method's training step beside PyTorch's, back to back, with GFLOP/s, the GEMM ceiling and the
# machine's load (docs/benchmarks.md). Needs torch: PYTORCH_PYTHON names an interpreter that has it.
PYTORCH_PYTHON ?= python3
bench-vs-pytorch:
	python3 benches/vs_pytorch.py --python $(PYTORCH_PYTHON) $(if $(QUICK),--quick) $(if $(ROUNDS),--rounds $(ROUNDS)) $(if $(ONLY),--only $(ONLY))

$(MBRL): build

# Collected datasets are file targets with an order-only dependency on the binary, so a rerun reuses them (a
# rebuild of mbrl does not re-collect them). Each seeded dataset has its seed in its path; `collect` writes
# through a temporary file, so a file that exists is whole.

# `$(call train_or_resume,DIR,METHOD AND FLAGS)`: a new run in DIR, or the stopped run an interrupted make left
# there resumed (`--resume-if-stopped` refuses one started with other flags), so re-running a long target loses
# none of its training.
train_or_resume = $(RUN) train $(2) --no-tui -q --out $(1) --resume-if-stopped

# The README's main job: a small reproduction of every implemented method (reports/quick/).
repro-quick: build
	$(RUN) eval quick --seed $(SEED) --no-tui --out reports/quick

# Thesis 3.5.2: ground-truth CEM swing-up, 10 episodes with the thesis' CEM settings.
repro-swingup: build
	$(RUN) eval pendulum-swingup --model true --episodes 10 --horizon 20 --candidates 1000 \
		--elites 100 --iters 10 --steps 150 --seed $(SEED) --no-tui --out reports/pendulum-swingup

# Thesis 3.5: 500 random rollouts of 30 transitions of the pendulum and each modified pendulum.
repro-pendulum-data: build
	for env in pendulum pendulum:light pendulum:heavy pendulum:inverted; do \
		$(RUN) collect --env $$env --rollouts 500 --steps 30 --seed $(SEED) --no-tui \
			--out datasets/$$(echo $$env | tr ':' '-')-random.mcap || exit 1; \
	done

# Sweeps (`mbrl sweep`): `$(call sweep,NAME)` plans sweeps/NAME.toml into sweeps/NAME/, runs its jobs here
# SWEEP_JOBS at a time (a rerun skips finished jobs and resumes stopped trainings) and writes the report with
# 95 % t intervals over seeds to sweeps/NAME/report/. The same directory goes to a Slurm cluster instead with
# `sweeps/NAME/submit.sh --wait`, then `mbrl sweep report sweeps/NAME`.
SWEEP_JOBS ?= 2
sweep = $(MBRL) sweep plan sweeps/$(1).toml --out sweeps/$(1) && \
	{ sweeps/$(1)/run-local.sh $(SWEEP_JOBS); status=$$?; $(MBRL) sweep report sweeps/$(1) && exit $$status; }

# The basic model-based loop with PETS, ten seeds (sweeps/pets.toml): per seed 200 random rollouts of 30
# steps, an ensemble of 5 trained on them and one swing-up planned on it at the thesis' CEM settings; the
# ground-truth model plans the same seeds' episodes for comparison.
repro-pets: build
	$(call sweep,pets)

# Explore the Context on the toy problem, three seeds per square (sweeps/context-toy.toml).
repro-context-toy: build
	$(call sweep,context-toy)

# The iterative loop users of mbrl-lib know: start from a few random rollouts, then alternate planning an
# episode on the current model (executed in the simulator and saved) with retraining on all data so far.
LOOP_ITERATIONS ?= 5
repro-pets-loop: build
	$(RUN) collect --env pendulum --rollouts 10 --steps 30 --seed $(SEED) --no-tui -q --out datasets/pets-loop/iter-0.mcap
	for i in $$(seq 1 $(LOOP_ITERATIONS)); do \
		data=$$(ls datasets/pets-loop/iter-*.mcap | sed 's/^/--data /' | tr '\n' ' '); \
		$(RUN) train pets --env pendulum $$data --steps 1000 --seed $(SEED) --no-tui -q --out models/pets-loop || exit 1; \
		$(RUN) plan --env pendulum --model models/pets-loop --steps 150 --seed $$i --no-tui --out datasets/pets-loop/iter-$$i.mcap || exit 1; \
	done

# Thesis 4.5 (Explore the Context): per env, instance pairs, a context model and the calibration protocol in
# unseen contexts (random / open-loop / MPC from one start; MSE vs horizon, Wilcoxon tests; pendulum: quadrants
# and swing-up return beside ground truth; toy: entropy vs action). CONTEXT_PRESET=medium (200 units, a tenth of
# Table B.1's steps) takes hours per env on 2 cores; CONTEXT_PRESET=small (64 units; toy 32) and smaller CEM
# (CONTEXT_CEM="--candidates 200 --elites 20 --iters 5 --beta-samples 10") make a run of about an hour.
CONTEXT_PRESET ?= medium
CONTEXT_CONTEXTS ?= 50
CONTEXT_CEM ?=
CONTEXT_SWINGUP ?= --swingup
CONTEXT_DATA = datasets/context/seed-$(SEED)
$(CONTEXT_DATA)/toy-%.mcap: | $(MBRL)
	$(RUN) collect --env toy:$* --instances 5000 --steps 100 --seed $(SEED) --no-tui -q --out $@
$(CONTEXT_DATA)/pendulum-quadrant.mcap: | $(MBRL)
	$(RUN) collect --env pendulum:quadrant --instances 10000 --steps 100 --seed $(SEED) --no-tui -q --out $@
$(CONTEXT_DATA)/mountaincar.mcap: | $(MBRL)
	$(RUN) collect --env mountaincar --instances 5000 --steps 100 --seed $(SEED) --no-tui -q --out $@
$(CONTEXT_DATA)/mountaincar-10k.mcap: | $(MBRL)
	$(RUN) collect --env mountaincar --instances 10000 --steps 100 --seed $(SEED) --no-tui -q --out $@
repro-context: build $(CONTEXT_DATA)/toy-inner.mcap $(CONTEXT_DATA)/toy-outer.mcap \
		$(CONTEXT_DATA)/pendulum-quadrant.mcap $(CONTEXT_DATA)/mountaincar.mcap
	for sq in inner outer; do \
		$(RUN) train context --data $(CONTEXT_DATA)/toy-$$sq.mcap --preset $(CONTEXT_PRESET) --seed $(SEED) --no-tui -q --out models/context/toy-$$sq || exit 1; \
		for n in 1 2 3; do \
			$(RUN) eval context --model models/context/toy-$$sq --env toy:$$sq --transitions $$n --contexts $(CONTEXT_CONTEXTS) \
				$(CONTEXT_CEM) --seed $(SEED) --no-tui -q --out reports/context/toy-$$sq-n$$n || exit 1; \
		done; \
	done
	$(call train_or_resume,models/context/pendulum-quadrant,context --data $(CONTEXT_DATA)/pendulum-quadrant.mcap --preset $(CONTEXT_PRESET) --seed $(SEED))
	$(RUN) eval context --model models/context/pendulum-quadrant --env pendulum:quadrant --transitions 30 --horizon 20 \
		--contexts $(CONTEXT_CONTEXTS) $(CONTEXT_CEM) $(CONTEXT_SWINGUP) --seed $(SEED) --no-tui -q --out reports/context/pendulum-quadrant
	$(call train_or_resume,models/context/mountaincar,context --data $(CONTEXT_DATA)/mountaincar.mcap --preset $(CONTEXT_PRESET) --seed $(SEED))
	$(RUN) eval context --model models/context/mountaincar --env mountaincar --transitions 50 --horizon 30 \
		--contexts $(CONTEXT_CONTEXTS) $(CONTEXT_CEM) --seed $(SEED) --no-tui -q --out reports/context/mountaincar

# Thesis 4.5.4 / Fig. 4.7 (MountainCar) at the scale measured on 2 cores: 10 000 instance pairs, the small
# preset (64 units, batch 64) for 30 000 steps (≈ 25 min), then 50 unseen contexts of 50 calibration
# transitions with EIG CEM 300 × 30 elites × 4 iterations and 10 β samples on one thread (≈ 25 min; the
# figures in RESULTS.md are this run's, seed 0).
repro-context-mountaincar: build $(CONTEXT_DATA)/mountaincar-10k.mcap
	$(call train_or_resume,models/context/mountaincar-small,context --data $(CONTEXT_DATA)/mountaincar-10k.mcap --preset small --steps 30000 --seed $(SEED))
	$(RUN) eval context --model models/context/mountaincar-small --env mountaincar --transitions 50 --horizon 30 --contexts 50 \
		--candidates 300 --elites 30 --iters 4 --beta-samples 10 --threads 1 --seed $(SEED) --no-tui -q --out reports/context/mountaincar-small

# TRADYN (thesis 5.5) at the medium scale these two cores allow: the thesis' map set and data (100 maps,
# 10 000 instance pairs of 100 colored-noise steps on the 50 train maps), the small-preset network (64 units,
# batch 64) trained for $(TRADYN_STEPS) steps with and without terrain lookup (≈ 20 min each, run side by side),
# then the four variants on $(TRADYN_TASKS) tasks on the test maps with CEM $(TRADYN_CEM) (the thesis:
# 5 models × 150 tasks, 200 units, batch 512, 100k steps, CEM 1000 × 50 elites × 20 iterations on a GPU).
TRADYN_STEPS ?= 15000
TRADYN_TASKS ?= 50
TRADYN_CEM ?= --candidates 300 --elites 30 --iters 10
TRADYN_DATA = datasets/tradyn/seed-$(SEED)
# The map set is a directory (staged and renamed into place whole); its manifest stands for it.
$(TRADYN_DATA)/maps/terrain.json: | $(MBRL)
	$(RUN) collect --env terrain --maps 100 --seed $(SEED) --no-tui -q --out $(@D)
$(TRADYN_DATA)/train.mcap: $(TRADYN_DATA)/maps/terrain.json | $(MBRL)
	$(RUN) collect --env unicycle --maps $(<D) --split train --instances 10000 --steps 100 \
		--seed $(SEED) --no-tui -q --out $@
# The two trainings run side by side; a bare `wait` would return 0 when one of them failed.
repro-tradyn: build $(TRADYN_DATA)/train.mcap
	$(RUN) train tradyn --data $(TRADYN_DATA)/train.mcap --preset small --steps $(TRADYN_STEPS) \
		--seed $(SEED) --no-tui -q --out models/tradyn/terrain & terrain=$$!; \
	$(RUN) train tradyn --no-terrain --data $(TRADYN_DATA)/train.mcap --preset small --steps $(TRADYN_STEPS) \
		--seed $(SEED) --no-tui -q --out models/tradyn/no-terrain & no_terrain=$$!; \
	status=0; wait $$terrain || status=1; wait $$no_terrain || status=1; exit $$status
	$(RUN) eval tradyn --model-terrain models/tradyn/terrain --model-no-terrain models/tradyn/no-terrain \
		--maps $(TRADYN_DATA)/maps --tasks $(TRADYN_TASKS) $(TRADYN_CEM) --seed $(SEED) --no-tui --out reports/tradyn

# Thesis chapter 7: SEADS skills and forward model on both Cursor games, then skill coverage and boards solved
# per depth with and without replanning (Table 7.3, Fig. 7.9/7.10 analogues).
SEADS_PRESET ?= paper
repro-seads: build
	for game in lightsout tileswap; do \
		$(RUN) train seads --env $$game:cursor --preset $(SEADS_PRESET) --seed $(SEED) --no-tui -q \
			--out models/seads-$$game-cursor || exit 1; \
		$(RUN) eval seads --model models/seads-$$game-cursor --boards 20 --seed $(SEED) --no-tui -q \
			--out reports/seads-$$game-cursor || exit 1; \
	done

# Thesis chapter 3: DLGPD on rendered pendulum frames, then swing-ups on matching and mismatching evidence.
# The default evaluation checks the two claims (standard pendulum swung up; inverted pendulum higher with
# matching evidence, Wilcoxon over 6 pairs: ≈ 75 min on one core). The Figs. 3.4/3.5 analogues (5/10/20
# evidence rollouts; standard, inverted, light, heavy) are DLGPD_EVAL="--evidence-rollouts 5,10,20 --runs 2
# --candidates 300 --elites 30 --iters 10" (hours). The medium preset's 3000 steps reconstruct the pole but
# do not swing up; DLGPD_STEPS=30000 (about 4 h of one core) is the length of the run RESULTS.md reports,
# with one thread as there; an interrupted make resumes the stopped run. A finished run is trained further
# with `mbrl train --resume DIR --steps N`.
DLGPD_PRESET ?= medium
DLGPD_STEPS ?=
DLGPD_THREADS ?= 1
DLGPD_EVAL ?= --env pendulum --env pendulum:inverted --evidence-rollouts 20 --runs 6 --candidates 200 --elites 20 --iters 8
DLGPD_DATA = datasets/dlgpd/seed-$(SEED)
$(DLGPD_DATA)/pendulum-frames.mcap: | $(MBRL)
	$(RUN) collect --env pendulum --images --rollouts 500 --steps 29 --seed $(SEED) --no-tui -q --out $@
repro-dlgpd: build $(DLGPD_DATA)/pendulum-frames.mcap
	$(call train_or_resume,models/dlgpd-$(DLGPD_PRESET),dlgpd --data $(DLGPD_DATA)/pendulum-frames.mcap \
		--preset $(DLGPD_PRESET) $(if $(DLGPD_STEPS),--steps $(DLGPD_STEPS)) --threads $(DLGPD_THREADS) --seed $(SEED))
	$(RUN) eval dlgpd --model models/dlgpd-$(DLGPD_PRESET) $(DLGPD_EVAL) --threads $(DLGPD_THREADS) --seed $(SEED) \
		--no-tui -q --out reports/dlgpd

# Thesis chapter 7 environments: depth/split tables, board sets, embodied play with scripted controllers.
datasets/%-boards-d5.mcap: | $(MBRL)
	$(RUN) collect --env $* --boards --max-depth 5 --no-tui --out $@
repro-boards: build datasets/lightsout-boards-d5.mcap datasets/tileswap-boards-d5.mcap
	$(RUN) eval boards --no-tui --out reports/boards
	for game in lightsout tileswap; do for arm in cursor reacher; do \
		$(RUN) eval embodied --game $$game --embodiment $$arm --max-depth 5 --boards 500 --seed $(SEED) \
			--no-tui --out reports/embodied-$$game-$$arm || exit 1; \
	done; done

# Thesis chapter 6: train the ball EKF on simulated default-pose shots, with rotation augmentation (with
# and without the launcher spin network) and without augmentation, and compare with the thesis' parameters
# and the black-box baseline on default and unseen launcher poses.
BALL_DATA = datasets/ball/seed-$(SEED)
$(BALL_DATA)/train.mcap: | $(MBRL)
	$(RUN) collect --env ball --trajectories 108 --augment-rotations 19 --seed $(SEED) --no-tui --out $@
$(BALL_DATA)/train-noaug.mcap: | $(MBRL)
	$(RUN) collect --env ball --trajectories 108 --seed $(SEED) --no-tui --out $@
repro-ball: build $(BALL_DATA)/train.mcap $(BALL_DATA)/train-noaug.mcap
	$(RUN) train ball-ekf --data $(BALL_DATA)/train.mcap --steps 2000 --seed $(SEED) --no-tui --out models/ball-ekf
	$(RUN) train ball-ekf --data $(BALL_DATA)/train.mcap --steps 2000 --launcher-prior --seed $(SEED) --no-tui \
		--out models/ball-ekf-launch
	$(RUN) train ball-ekf --data $(BALL_DATA)/train-noaug.mcap --steps 2000 --seed $(SEED) --no-tui \
		--out models/ball-ekf-noaug
	$(RUN) eval ball --model models/ball-ekf-launch --model models/ball-ekf --model models/ball-ekf-noaug --model thesis \
		--seed $(SEED) --no-tui --out reports/ball

completions: build
	$(RUN) completions bash > completions/mbrl.bash
	$(RUN) completions zsh > completions/_mbrl
	$(RUN) completions fish > completions/mbrl.fish

clean-reports:
	rm -rf reports
