#!/usr/bin/env python3
"""PyTorch's side of benches/training_steps.rs: one training step of every learned method, at one thread and
at two, each the median of its timed steps after warm-up. Prints one JSON object per line.

The networks and losses are the reference scripts' (pets_reference.py, context_reference.py,
dlgpd_reference.py), which mirror the authors' code; SAC is written here as the SEADS agent runs it
(pytorch-soft-actor-critic's update: twin critics on r + γ(1 − done)(min Q_target − α log π), then the
actor against the updated critics, then the Polyak step). The ball EKF is ball_reference.py's, which
mirrors mbrl's own batched filter (there is no authors' code to mirror): it trains on the batches mbrl's
trainer draws, read from the case file `cargo run --release --example ball_loss_case` writes
(benches/vs_pytorch.py runs it first), and, as benches/training_steps.rs times that row, each of its figures
is the mean of steps 2-11 of a fresh training run; the batches are tensors before the clock starts.

FLOPs per step are counted once per workload by torch.utils.flop_counter.FlopCounterMode: the matmul and
convolution FLOPs of the forward and backward pass (element-wise work, the optimizer and float64 GP
factorizations are not counted). benches/vs_pytorch.py divides both sides' times into that same count.

Usage: python3 benches/pytorch/training_steps.py [--quick] [--only NAME[,NAME...]]
"""

import argparse
import json
import math
import os
import statistics
import sys
import time
import warnings
from typing import Callable, NamedTuple

warnings.filterwarnings("ignore", message="Failed to initialize NumPy")

import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402
from torch.utils.flop_counter import FlopCounterMode  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ball_reference  # noqa: E402
import context_reference  # noqa: E402
import dlgpd_reference  # noqa: E402
import pets_reference  # noqa: E402


def pets(preset):
    model = pets_reference.GaussianEnsemble(*pets_reference.PRESETS[preset])
    pool_x = torch.randn(pets_reference.DATA_POOL, pets_reference.IN_DIM)
    pool_y = torch.randn(pets_reference.DATA_POOL, pets_reference.OUT_DIM) * 0.3
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    gen = torch.Generator().manual_seed(1)

    def step():
        idx = torch.randint(pets_reference.DATA_POOL, (pets_reference.ENSEMBLE, pets_reference.BATCH), generator=gen)
        loss = pets_reference.nll_loss(model, pool_x[idx], pool_y[idx])
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()

    return step


def context(batch_size):
    model = context_reference.ContextModel()
    opt = torch.optim.Adam(model.parameters(), lr=1e-3, eps=1e-4)
    batch = context_reference.random_batch(batch_size)

    def step():
        opt.zero_grad()
        loss = context_reference.loss_fn(model, batch)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1000.0)
        opt.step()

    return step


SAC_OBS, SAC_ACT, SAC_HIDDEN = 53, 3, 256


def sac_mlp(n_in, n_out):
    return torch.nn.Sequential(
        torch.nn.Linear(n_in, SAC_HIDDEN),
        torch.nn.ReLU(),
        torch.nn.Linear(SAC_HIDDEN, SAC_HIDDEN),
        torch.nn.ReLU(),
        torch.nn.Linear(SAC_HIDDEN, n_out),
    )


class Policy(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.net = sac_mlp(SAC_OBS, 2 * SAC_ACT)

    def sample(self, obs, scale):
        mean, log_std = self.net(obs).chunk(2, -1)
        log_std = log_std.clamp(-20, 2)
        std = log_std.exp()
        u = mean + std * torch.randn_like(mean)
        y = torch.tanh(u)
        gaussian = -0.5 * ((u - mean) / std) ** 2 - log_std - 0.5 * math.log(2 * math.pi)
        log_prob = (gaussian - torch.log(scale * (1 - y**2) + 1e-6)).sum(-1, keepdim=True)
        return y * scale, log_prob


def sac():
    rows = 128
    policy = Policy()
    q1, q2 = sac_mlp(SAC_OBS + SAC_ACT, 1), sac_mlp(SAC_OBS + SAC_ACT, 1)
    t1, t2 = sac_mlp(SAC_OBS + SAC_ACT, 1), sac_mlp(SAC_OBS + SAC_ACT, 1)
    t1.load_state_dict(q1.state_dict())
    t2.load_state_dict(q2.state_dict())
    critic_params = list(q1.parameters()) + list(q2.parameters())
    critic_opt = torch.optim.Adam(critic_params, lr=3e-4)
    policy_opt = torch.optim.Adam(policy.parameters(), lr=3e-4)
    scale = torch.tensor([0.2, 0.2, 1.0])
    obs, next_obs = torch.rand(rows, SAC_OBS), torch.rand(rows, SAC_OBS)
    actions = (torch.rand(rows, SAC_ACT) - 0.5) * 0.4
    rewards = torch.rand(rows, 1) * 3 - 2
    done = (torch.rand(rows, 1) < 0.1).float()
    gamma, alpha, tau = 0.99, 0.1, 0.005

    def step():
        with torch.no_grad():
            next_a, next_logp = policy.sample(next_obs, scale)
            x = torch.cat([next_obs, next_a], 1)
            y = rewards + (1 - done) * gamma * (torch.min(t1(x), t2(x)) - alpha * next_logp)
        x = torch.cat([obs, actions], 1)
        critic_loss = F.mse_loss(q1(x), y) + F.mse_loss(q2(x), y)
        critic_opt.zero_grad()
        critic_loss.backward()
        critic_opt.step()
        a, logp = policy.sample(obs, scale)
        x = torch.cat([obs, a], 1)
        actor_loss = (alpha * logp - torch.min(q1(x), q2(x))).mean()
        policy_opt.zero_grad()
        actor_loss.backward()
        policy_opt.step()
        with torch.no_grad():
            for target, live in ((t1, q1), (t2, q2)):
                for pt, p in zip(target.parameters(), live.parameters()):
                    pt.mul_(1 - tau).add_(p, alpha=tau)

    return step


def dlgpd(batch):
    enc, dec = dlgpd_reference.Encoder(), dlgpd_reference.Decoder()
    latent, action = dlgpd_reference.LATENT, dlgpd_reference.ACTION
    transition = [dlgpd_reference.Gp(latent + action) for _ in range(latent)]
    reward = dlgpd_reference.Gp(latent + action)
    params = list(enc.parameters()) + list(dec.parameters()) + [p for gp in transition + [reward] for p in gp.parameters()]
    side, channels = dlgpd_reference.SIDE, dlgpd_reference.CHANNELS
    frames, next_frames = torch.rand(batch, channels, side, side), torch.rand(batch, channels, side, side)
    a = torch.rand(batch, action, dtype=torch.float64) * 4 - 2
    rewards = -torch.rand(batch, dtype=torch.float64) * 10

    def step():
        for p in params:
            p.grad = None
        dlgpd_reference.step_loss(enc, dec, transition, reward, frames, next_frames, a, rewards).backward()

    return step


class SelfTimed(NamedTuple):
    """A workload that times itself, as its Rust side does: `sample()` returns seconds per optimizer step;
    `step()` takes one step, for the FLOP count."""

    sample: Callable[[], float]
    step: Callable[[], None]


def ball():
    case = ball_reference.load_case(ball_reference.DEFAULT_CASE)
    physics = ball_reference.physics_of(case)
    batches = [ball_reference.batch_of(entry) for entry in case["batches"]]

    def fresh_run():
        params = ball_reference.raw_parameters(case)
        return params, ball_reference.adam(params, case)

    def first_step():
        ball_reference.train_step(*fresh_run(), batches[0], physics)

    def sample():
        # As benches/training_steps.rs times `train` for 11 steps less `train` for 1: a fresh run whose first
        # step (the first batch, Adam's first update) is not counted and whose other ten are averaged.
        params, optimizer = fresh_run()
        ball_reference.train_step(params, optimizer, batches[0], physics)
        start = time.perf_counter()
        for batch in batches[1:]:
            ball_reference.train_step(params, optimizer, batch, physics)
        return (time.perf_counter() - start) / (len(batches) - 1)

    return SelfTimed(sample, first_step)


def timed(step):
    def sample():
        start = time.perf_counter()
        step()
        return time.perf_counter() - start

    return sample


# name: (builder, warm-up steps, timed steps or, for a self-timed workload, samples) — the same counts as
# benches/training_steps.rs.
WORKLOADS = {
    "pets_small": (lambda: pets("small"), 20, 200),
    "pets_medium": (lambda: pets("medium"), 10, 60),
    "context_b64": (lambda: context(64), 2, 10),
    "context_b512": (lambda: context(512), 1, 3),
    "sac_b128": (sac, 10, 100),
    "dlgpd_b256": (lambda: dlgpd(256), 1, 3),
    "dlgpd_b1024": (lambda: dlgpd(1024), 1, 3),
    "ball_b64x50": (ball, 0, 3),
}


def count_flops(step):
    with FlopCounterMode(display=False) as counter:
        step()
    return counter.get_total_flops()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer timed steps")
    parser.add_argument("--only", help="comma-separated workload names")
    args = parser.parse_args()
    names = list(WORKLOADS)
    if args.only:
        names = args.only.split(",")
        unknown = [n for n in names if n not in WORKLOADS]
        if unknown:
            sys.exit(f"error: unknown workload '{unknown[0]}'; known: {', '.join(WORKLOADS)}")
    print(json.dumps({"torch": torch.__version__}), flush=True)
    flops = {}
    for threads in (1, 2):
        torch.set_num_threads(threads)
        for name in names:
            build, warmup, repeats = WORKLOADS[name]
            if args.quick:
                warmup, repeats = min(warmup, 2), max(repeats // 5, 2)
            torch.manual_seed(0)
            workload = build()
            sample, step = workload if isinstance(workload, SelfTimed) else (timed(workload), workload)
            if name not in flops:
                flops[name] = count_flops(step)
            for _ in range(warmup):
                step()
            samples = [sample() for _ in range(repeats)]
            row = {"workload": name, "threads": threads, "seconds": statistics.median(samples)}
            row.update({"samples": repeats, "flops": flops[name]})
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
