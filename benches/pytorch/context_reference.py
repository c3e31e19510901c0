#!/usr/bin/env python3
"""PyTorch CPU reference timings for the Explore-the-Context model (benches/context.rs is the Rust side).

The network and loss follow the authors' code as METHODS.md describes it, at the paper sizes for the
pendulum (Table B.1: 200 units, D_F 128, D_beta 16, C_max 50; state 3, action 1):

  * state MLP s->200->200 tanh (initial GRU state), action MLP a->200->200 ReLU, context MLP
    beta->200->200 ReLU, torch.nn.GRUCell on [ctx_emb, act_emb], mean and variance decoders
    200->200->s (variance softplus + 1e-4);
  * context encoder [s, a, s']->200->128 ReLU, max-pooled into zeros (masked padding), mean head
    128->200->16, std head with ReLU'd weights, std = softplus(-0.3 enc + 0.5) + 0.01;
  * loss: mean reconstruction over the 50 chunk states, mean single-step likelihood with a fresh beta per
    step, summed multi-step likelihood of one open-loop rollout with one beta, KL(q(beta|{})||N(0,I)) and
    5 * sum_i max(0.1, KL_i(q(beta|C u D)||q(beta|C))); Adam (1e-3, eps 1e-4), gradient norm clip 1000.

Figures (median of repeats after warm-up, float32, T = 1 and 2 threads):
  (a) training steps/s at batch 64 and 512, 50-state chunks;
  (b) mean rollouts of 1000 candidates x 20 steps, no grad (batches/s), beta given per candidate;
  (c) one EIG CEM iteration: 1000 candidates x 20 beta samples x horizon 20 mean rollouts, then the
      transitions' pooled features and the posterior entropy (what benches/context.rs times).

Usage: python3 benches/pytorch/context_reference.py [--quick]
"""

import argparse
import statistics
import time
import warnings

warnings.filterwarnings("ignore", message="Failed to initialize NumPy")

import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402

S, A, E, H, DF, DB, CMAX, CHUNK = 3, 1, 200, 200, 128, 16, 50, 50


def mlp(n_in, n_out):
    return torch.nn.Sequential(torch.nn.Linear(n_in, H), torch.nn.ReLU(), torch.nn.Linear(H, n_out))


class ContextModel(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.state_enc = mlp(S, E)
        self.action_enc = mlp(A, E)
        self.ctx_emb = mlp(DB, E)
        self.gru = torch.nn.GRUCell(2 * E, E)
        self.mean_dec = mlp(E, S)
        self.var_dec = mlp(E, S)
        self.trans_enc = mlp(2 * S + A, DF)
        self.ctx_mean = mlp(DF, DB)
        self.std_w1 = torch.nn.Parameter(torch.rand(H, DF) * 0.1)
        self.std_b1 = torch.nn.Parameter(torch.zeros(H))
        self.std_w2 = torch.nn.Parameter(torch.rand(DB, H) * 0.1)
        self.std_b2 = torch.nn.Parameter(torch.zeros(DB))

    def pool(self, transitions, present):
        feats = F.relu(self.trans_enc(transitions)) * present.unsqueeze(-1)
        return feats.max(dim=1).values.clamp_min(0.0)

    def belief(self, pooled):
        mean = self.ctx_mean(pooled)
        hidden = F.relu(F.linear(pooled, F.relu(self.std_w1), self.std_b1))
        enc = F.linear(hidden, F.relu(self.std_w2), self.std_b2)
        return mean, F.softplus(-0.3 * enc + 0.5) + 0.01

    def decode(self, h):
        return self.mean_dec(h), F.softplus(self.var_dec(h)) + 1e-4

    def step(self, h, beta, action):
        return self.gru(torch.cat([F.relu(self.ctx_emb(beta)), F.relu(self.action_enc(action))], -1), h)


def log_lik(mean, var, x):
    return (-0.5 * ((x - mean) ** 2 / var + var.log() + torch.log(torch.tensor(2 * torch.pi)))).sum(-1)


def kl(pm, ps, qm, qs):
    return ((ps / qs) ** 2 + ((pm - qm) / qs) ** 2 - 1) * 0.5 + (qs / ps).log()


def loss_fn(model, batch):
    states, actions, chunk_trans, context, present = batch
    b, n, _ = states.shape
    t = n - 1
    chunk_pool = model.pool(chunk_trans, torch.ones(b, t))
    ctx_pool = model.pool(context, present)
    post_m, post_s = model.belief(torch.maximum(chunk_pool, ctx_pool))
    prior_m, prior_s = model.belief(ctx_pool)
    empty_m, empty_s = model.belief(torch.zeros(1, DF))
    kl_empty = kl(empty_m, empty_s, torch.zeros_like(empty_m), torch.ones_like(empty_s)).sum()
    kl_ctx = kl(post_m, post_s, prior_m, prior_s).clamp_min(0.1).sum(-1).mean()

    h_all = torch.tanh(model.state_enc(states))
    recon = log_lik(*model.decode(h_all), states).mean(1)
    beta_single = post_m.unsqueeze(1) + post_s.unsqueeze(1) * torch.randn(b, t, DB)
    h_single = model.step(h_all[:, :t].reshape(b * t, E), beta_single.reshape(b * t, DB), actions.reshape(b * t, A))
    single = log_lik(*model.decode(h_single), states[:, 1:].reshape(b * t, S)).reshape(b, t).mean(1)

    beta = post_m + post_s * torch.randn(b, DB)
    ctx = F.relu(model.ctx_emb(beta))
    act = F.relu(model.action_enc(actions))
    h = h_all[:, 0]
    outs = []
    for k in range(t):
        h = model.gru(torch.cat([ctx, act[:, k]], -1), h)
        if k >= 1:
            outs.append(h)
    hs = torch.stack(outs, 1)
    multi = log_lik(*model.decode(hs), states[:, 2:]).sum(1)
    return -(recon.mean() + single.mean() + multi.mean()) + kl_empty + 5.0 * kl_ctx


def random_batch(b):
    g = torch.Generator().manual_seed(b)
    states = torch.randn(b, CHUNK, S, generator=g)
    actions = torch.rand(b, CHUNK - 1, A, generator=g) * 4 - 2
    chunk_trans = torch.cat([states[:, :-1], actions, states[:, 1:]], -1)
    context = torch.randn(b, CMAX, 2 * S + A, generator=g)
    sizes = torch.randint(0, CMAX + 1, (b, 1), generator=g)
    present = (torch.arange(CMAX).unsqueeze(0) < sizes).float()
    return states, actions, chunk_trans, context, present


def timed(fn, repeats, warmup=2):
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def train_rate(batch_size, repeats):
    torch.manual_seed(0)
    model = ContextModel()
    opt = torch.optim.Adam(model.parameters(), lr=1e-3, eps=1e-4)
    batch = random_batch(batch_size)

    def step():
        opt.zero_grad()
        loss = loss_fn(model, batch)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1000.0)
        opt.step()

    return 1.0 / timed(step, repeats)


@torch.no_grad()
def rollout(model, s0, actions, betas):
    ctx = F.relu(model.ctx_emb(betas))
    act = F.relu(model.action_enc(actions))
    h = torch.tanh(model.state_enc(s0)).expand(betas.shape[0], E)
    means = []
    for k in range(actions.shape[1]):
        h = model.gru(torch.cat([ctx, act[:, k]], -1), h)
        means.append(model.mean_dec(h))
    return torch.stack(means, 1)


@torch.no_grad()
def eig_iteration(model, s0, actions, betas, samples):
    """Costs of 1000 candidates: mean rollouts under `samples` betas each, chopped into transitions, pooled
    with the calibration set so far (empty here), and the entropy of the resulting belief."""
    n, horizon = actions.shape[0], actions.shape[1]
    rep_actions = actions.repeat_interleave(samples, 0)
    preds = rollout(model, s0, rep_actions, betas)
    prev = torch.cat([s0.expand(n * samples, 1, S), preds[:, :-1]], 1)
    trans = torch.cat([prev, rep_actions, preds], -1)
    pooled = model.pool(trans, torch.ones(n * samples, horizon))
    _, std = model.belief(pooled)
    return std.log().sum(-1).reshape(n, samples).mean(1)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    print(f"torch {torch.__version__}, float32, CPU")
    for threads in (1, 2):
        torch.set_num_threads(threads)
        for b in (64, 512):
            print(f"T={threads} train step batch {b} x {CHUNK} states: {train_rate(b, repeats if b == 64 else 3):.2f} steps/s")
        model = ContextModel()
        s0 = torch.tensor([[-1.0, 0.0, 0.0]])
        actions = torch.rand(1000, 20, A) * 4 - 2
        betas = torch.randn(1000, DB)
        t = timed(lambda: rollout(model, s0, actions, betas), repeats)
        print(f"T={threads} mean rollout 1000 x 20: {1.0 / t:.2f} batches/s ({t * 1e3:.1f} ms)")
        betas20 = torch.randn(1000 * 20, DB)
        t = timed(lambda: eig_iteration(model, s0, actions, betas20, 20), 3, warmup=1)
        print(f"T={threads} EIG CEM iteration 1000 x 20 beta x 20 steps: {t * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
