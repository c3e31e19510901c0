#!/usr/bin/env python3
"""PyTorch CPU reference timings for the PETS probabilistic ensemble (benches/pets.rs is the Rust side).

The network mirrors facebookresearch/mbrl-lib's GaussianMLP so the figures say what the reference
implementation costs on this machine, not what an idealised PyTorch model would cost:

  * ensemble linear layers, weight [E, in, out] and bias [E, 1, out], all members in one batched
    matmul (baddbmm), SiLU between hidden layers;
  * the output layer gives mean and log-variance, the latter softly bounded by the learned
    max_logvar / min_logvar parameters ([1, d]) with the same two softplus steps;
  * weights start from mbrl-lib's truncated normal (std 1/(2*sqrt(in))), biases at zero; values do not
    change the speed of dense float32 arithmetic, but they keep the sampled states finite.

Figures, each the median of several repeats after warm-up, float32, for T = 1 and T = 2 threads:

  (a) one ensemble forward on 20,000 rows, 4,000 per member: one CEM propagation step with
      1000 candidates x 20 particles (TS-inf: each particle stays on one member);
  (b) one MPC step: 10 CEM iterations x horizon 20 propagations, each followed by a Gaussian sample of
      the predicted delta and the cos/sin feature rebuild; the pendulum reward and the CEM refit are
      included because benches/pets.rs times the whole `Cem::plan`, and they are cheap next to (a);
  (c) one training step: batch 256 per member, Gaussian NLL plus mbrl-lib's logvar-bound penalty,
      backward and Adam (lr 1e-3, PyTorch's default betas and eps).

Each row also reports how many cores other processes kept busy while it was measured (from
/proc/stat), since a shared 2-core machine makes these timings meaningless without it.

Usage: python3 benches/pytorch/pets_reference.py [--quick]
"""

import argparse
import math
import os
import platform
import statistics
import time
import warnings

# torch warns at import when NumPy is absent; this script never touches NumPy, so the warning is noise.
warnings.filterwarnings("ignore", message="Failed to initialize NumPy")

import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402

ENSEMBLE = 5
IN_DIM = 4  # cos θ, sin θ, θ̇, torque
OUT_DIM = 2  # Δθ, Δθ̇
PRESETS = {"small": (3, 64), "medium": (4, 200)}  # hidden layers, units (medium = mbrl-lib pendulum PETS)

CANDIDATES = 1000
PARTICLES = 20
HORIZON = 20
CEM_ITERS = 10
ELITES = 100
MAX_TORQUE = 2.0
BATCH = 256
DATA_POOL = 5000  # same pool size as the Rust training bench, so per-step batch gathering is comparable


class EnsembleLinear(torch.nn.Module):
    def __init__(self, members, n_in, n_out):
        super().__init__()
        self.weight = torch.nn.Parameter(torch.empty(members, n_in, n_out))
        self.bias = torch.nn.Parameter(torch.zeros(members, 1, n_out))
        std = 1.0 / (2.0 * math.sqrt(n_in))
        for w in self.weight.data:
            torch.nn.init.trunc_normal_(w, std=std, a=-2 * std, b=2 * std)

    def forward(self, x):
        # One fused bias-add + batched matmul over members, as the ensemble layer is meant to be used.
        return torch.baddbmm(self.bias, x, self.weight)


class GaussianEnsemble(torch.nn.Module):
    def __init__(self, hidden_layers, units, members=ENSEMBLE, n_in=IN_DIM, d=OUT_DIM):
        super().__init__()
        sizes = [n_in] + [units] * hidden_layers
        self.hidden = torch.nn.ModuleList(EnsembleLinear(members, a, b) for a, b in zip(sizes, sizes[1:]))
        self.out = EnsembleLinear(members, units, 2 * d)
        self.d = d
        # mbrl-lib's initial bounds; learned (learn_logvar_bounds=True) so they take part in training.
        self.min_logvar = torch.nn.Parameter(torch.full((1, d), -10.0))
        self.max_logvar = torch.nn.Parameter(torch.full((1, d), 0.5))

    def forward(self, x):
        for layer in self.hidden:
            x = F.silu(layer(x))
        out = self.out(x)
        mean, logvar = out[..., : self.d], out[..., self.d :]
        # Soft bounds keep the variance differentiable everywhere, unlike a clamp.
        logvar = self.max_logvar - F.softplus(self.max_logvar - logvar)
        logvar = self.min_logvar + F.softplus(logvar - self.min_logvar)
        return mean, logvar


def features(state, action):
    """[θ, θ̇] + torque -> [cos θ, sin θ, θ̇, torque]; the angle enters through cos/sin so it wraps."""
    theta, theta_dot = state[..., 0], state[..., 1]
    return torch.stack((torch.cos(theta), torch.sin(theta), theta_dot, action), dim=-1)


# A fixed input normaliser, as a trained mbrl-lib model applies one before every forward.
NORM_MEAN = torch.zeros(IN_DIM)
NORM_STD = torch.tensor([0.7, 0.7, 4.0, 1.2])


def rollout_batch():
    return torch.randn(ENSEMBLE, CANDIDATES * PARTICLES // ENSEMBLE, IN_DIM)


def mpc_step(model, init_state, gen):
    """One CEM plan: every iteration rolls all candidates x particles through the ensemble."""
    per_member = CANDIDATES * PARTICLES // ENSEMBLE
    per_candidate = PARTICLES // ENSEMBLE  # particles of one candidate on one member
    mu = torch.zeros(HORIZON)
    sigma = torch.full((HORIZON,), MAX_TORQUE)
    for _ in range(CEM_ITERS):
        plans = (mu + sigma * torch.randn(CANDIDATES, HORIZON, generator=gen)).clamp(-MAX_TORQUE, MAX_TORQUE)
        # Row layout [member][candidate][particle]: a reshape, not a gather, maps rows to members.
        row_actions = plans.repeat_interleave(per_candidate, dim=0)  # [per_member, H]
        state = init_state.expand(ENSEMBLE, per_member, 2).clone()
        total = torch.zeros(ENSEMBLE, per_member)
        for t in range(HORIZON):
            a = row_actions[:, t].expand(ENSEMBLE, per_member)
            x = (features(state, a) - NORM_MEAN) / NORM_STD
            mean, logvar = model(x)
            nxt = state + mean + torch.exp(0.5 * logvar) * torch.randn(mean.shape, generator=gen)
            ang = torch.remainder(state[..., 0] + math.pi, 2 * math.pi) - math.pi
            total += -(ang**2 + 0.1 * state[..., 1] ** 2 + 0.001 * a**2)
            state = nxt
        returns = total.view(ENSEMBLE, CANDIDATES, per_candidate).mean(dim=(0, 2))
        elite = plans[returns.topk(ELITES).indices]
        mu, sigma = elite.mean(0), elite.std(0)
    return mu[0]


def nll_loss(model, x, y):
    mean, logvar = model(x)
    # Mean over the batch, summed over outputs and members (mbrl-lib also averages over outputs: a
    # constant factor that changes no timing).
    nll = (((mean - y) ** 2) * torch.exp(-logvar) + logvar).mean(dim=1).sum()
    return nll + 0.01 * (model.max_logvar.sum() - model.min_logvar.sum())


def timed(fn, warmup, repeats):
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def measure(preset, threads, quick):
    torch.set_num_threads(threads)
    torch.manual_seed(0)
    model = GaussianEnsemble(*PRESETS[preset])
    gen = torch.Generator().manual_seed(1)
    heavy = preset == "medium"

    x = rollout_batch()
    with torch.no_grad():
        fwd = timed(lambda: model(x), warmup=3 if quick else 10, repeats=5 if quick else (20 if heavy else 50))
        init = torch.tensor([math.pi, 0.0])
        mpc = timed(lambda: mpc_step(model, init, gen), warmup=0 if quick else 1, repeats=1 if quick else (3 if heavy else 5))

    # Training draws a fresh bootstrap batch per member each step from a fixed pool, like the Rust trainer.
    pool_x = torch.randn(DATA_POOL, IN_DIM)
    pool_y = torch.randn(DATA_POOL, OUT_DIM) * 0.3
    opt = torch.optim.Adam(model.parameters(), lr=1e-3, betas=(0.9, 0.999), eps=1e-8)

    def train_step():
        idx = torch.randint(DATA_POOL, (ENSEMBLE, BATCH), generator=gen)
        loss = nll_loss(model, pool_x[idx], pool_y[idx])
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()

    train = timed(train_step, warmup=5 if quick else 20, repeats=10 if quick else (50 if heavy else 100))
    return fwd, mpc, train


def busy_seconds():
    """CPU seconds the whole machine has spent busy (Linux /proc/stat), or None elsewhere."""
    try:
        with open("/proc/stat") as f:
            fields = [int(v) for v in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)  # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def own_seconds():
    t = os.times()
    return t.user + t.system


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, for checking the script runs")
    args = parser.parse_args()

    load_before = os.getloadavg()
    rows = []
    for preset in PRESETS:
        for threads in (1, 2):
            # The load average lags by a minute; the busy time nobody else but us could have used says
            # directly whether another process competed for the cores while this row was measured.
            wall0, busy0, own0 = time.perf_counter(), busy_seconds(), own_seconds()
            fwd, mpc, train = measure(preset, threads, args.quick)
            wall, busy, own = time.perf_counter() - wall0, busy_seconds(), own_seconds() - own0
            others = None if busy0 is None else max(0.0, (busy - busy0) - own) / wall
            rows.append((preset, threads, fwd, mpc, train, others))
    load_after = os.getloadavg()

    hidden = lambda p: "{}x{}".format(*PRESETS[p])  # noqa: E731
    print(f"PyTorch {torch.__version__}, float32, CPU: {cpu_name()} ({os.cpu_count()} logical)")
    print(
        f"E={ENSEMBLE}, in={IN_DIM}, out={OUT_DIM}; forward = {CANDIDATES * PARTICLES} rows "
        f"({CANDIDATES} candidates x {PARTICLES} particles); MPC = {CEM_ITERS} iterations x horizon {HORIZON}; "
        f"train batch {BATCH}/member; {'quick' if args.quick else 'full'} run"
    )
    print(
        "load average (1/5/15 min) before: {:.2f} {:.2f} {:.2f}, after: {:.2f} {:.2f} {:.2f}".format(
            *load_before, *load_after
        )
    )
    print()
    print("| preset | hidden | threads | forward 20k rows (ms) | MPC step (s) | train step (ms) | other procs (cores) |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for preset, threads, fwd, mpc, train, others in rows:
        other = "n/a" if others is None else f"{others:.2f}"
        print(
            f"| {preset} | {hidden(preset)} | {threads} | {fwd * 1e3:.2f} | {mpc:.3f} | {train * 1e3:.2f} | {other} |"
        )


if __name__ == "__main__":
    main()
