#!/usr/bin/env python3
"""PyTorch CPU reference timing for DLGPD's training step (benches/dlgpd.rs is the Rust side).

The network and loss follow thesis Tables A.1/A.2 and eq. 3.16 as METHODS.md describes the authors' code:

  * encoder: two stacked 64x64 RGB frames (6 channels) -> conv 32/64/128/256, kernel 4, stride 2, no
    padding, ReLU -> flatten 1024 -> mean and std heads (std = softplus(x + 0.55) + 0.01), latent 3;
  * decoder: 3 -> 1024 ReLU -> transposed convs 128 (k5), 64 (k5), 32 (k6), 6 (k6), stride 2 -> logits;
  * loss: Bernoulli reconstruction of the next frames from a reparameterized sample (summed over pixels,
    mean over the batch), the std's entropy term, and the GP terms: three transition GPs on the batch-
    standardized [s, a] scored on the next latents and a reward GP on [s.detach(), a], each an exact GP in
    float64 (SE-ARD kernel, Cholesky) whose negative log marginal likelihood is divided by the batch size.

What is timed matches `dlgpd_step_parts_batch_1024/whole_step_gradients_without_optimizer`: both encodings,
the decoding, the four GPs' marginal likelihoods and the backward pass into the VAE and the GP
hyperparameters, without the optimizer update (the Adam update is timed separately). The GP prior and the
SNR penalty are left out: they cost microseconds next to the convolutions.

Usage: python3 benches/pytorch/dlgpd_reference.py [--quick]
"""

import argparse
import math
import statistics
import time
import warnings

warnings.filterwarnings("ignore", message="Failed to initialize NumPy")

import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402

LATENT, ACTION, SIDE, CHANNELS = 3, 1, 64, 6


class Encoder(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.convs = torch.nn.ModuleList(
            [torch.nn.Conv2d(i, o, 4, 2) for i, o in [(CHANNELS, 32), (32, 64), (64, 128), (128, 256)]]
        )
        self.mean = torch.nn.Linear(1024, LATENT)
        self.std = torch.nn.Linear(1024, LATENT)

    def forward(self, x):
        for conv in self.convs:
            x = F.relu(conv(x))
        x = x.flatten(1)
        return self.mean(x), F.softplus(self.std(x) + 0.55) + 0.01


class Decoder(torch.nn.Module):
    def __init__(self):
        super().__init__()
        self.fc = torch.nn.Linear(LATENT, 1024)
        self.deconvs = torch.nn.ModuleList(
            [
                torch.nn.ConvTranspose2d(i, o, k, 2)
                for i, o, k in [(1024, 128, 5), (128, 64, 5), (64, 32, 6), (32, CHANNELS, 6)]
            ]
        )

    def forward(self, z):
        x = F.relu(self.fc(z)).view(-1, 1024, 1, 1)
        for k, deconv in enumerate(self.deconvs):
            x = deconv(x)
            if k < len(self.deconvs) - 1:
                x = F.relu(x)
        return x


class Gp(torch.nn.Module):
    """Exact GP negative log marginal likelihood with an SE-ARD kernel, in float64."""

    def __init__(self, inputs):
        super().__init__()
        self.raw_lengthscale = torch.nn.Parameter(torch.zeros(inputs, dtype=torch.float64))
        self.raw_outputscale = torch.nn.Parameter(torch.zeros((), dtype=torch.float64))
        self.raw_noise = torch.nn.Parameter(torch.full((), -3.0, dtype=torch.float64))

    def nll(self, x, y, prior_mean):
        ls = F.softplus(self.raw_lengthscale)
        xs = x / ls
        sq = torch.cdist(xs, xs).pow(2)
        k = F.softplus(self.raw_outputscale) * torch.exp(-0.5 * sq)
        k = k + (F.softplus(self.raw_noise) + 1e-4) * torch.eye(x.shape[0], dtype=x.dtype)
        chol = torch.linalg.cholesky(k)
        r = (y - prior_mean).unsqueeze(1)
        alpha = torch.cholesky_solve(r, chol)
        n = x.shape[0]
        value = 0.5 * (r * alpha).sum() + torch.log(torch.diagonal(chol)).sum() + 0.5 * n * math.log(2 * math.pi)
        return value / n


def gp_terms(transition, reward, s, a, s_next, rewards):
    s, s_next = s.double(), s_next.double()
    mean, std = s.mean(0), s.std(0) + 1e-2
    scaled = (s - mean) / std
    x = torch.cat([scaled, a], 1)
    total = 0.0
    for d, gp in enumerate(transition):
        prior = scaled[:, d] * std[d].detach() + mean[d].detach()
        total = total + gp.nll(x, s_next[:, d], prior)
    xr = torch.cat([s.detach(), a], 1)
    return total + reward.nll(xr, rewards, rewards.min())


def step_loss(enc, dec, transition, reward, frames, next_frames, a, rewards):
    mean, std = enc(frames)
    next_mean, next_std = enc(next_frames)
    s = mean + std * torch.randn_like(std)
    s_next = next_mean + next_std * torch.randn_like(next_std)
    logits = dec(s_next)
    recon = F.binary_cross_entropy_with_logits(logits, next_frames, reduction="sum") / frames.shape[0]
    entropy = -torch.log(next_std).sum(1).mean()
    return recon + entropy + gp_terms(transition, reward, s, a, s_next, rewards)


def median_seconds(fn, repeats, warmup=1):
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    args = parser.parse_args()
    repeats = 2 if args.quick else 5
    torch.manual_seed(0)
    enc, dec = Encoder(), Decoder()
    transition = [Gp(LATENT + ACTION) for _ in range(LATENT)]
    reward = Gp(LATENT + ACTION)
    params = list(enc.parameters()) + list(dec.parameters())
    gp_params = [p for gp in transition + [reward] for p in gp.parameters()]
    adam = torch.optim.Adam(params, lr=1e-3)
    gp_adam = torch.optim.Adam(gp_params, lr=1e-3)
    print(f"torch {torch.__version__}, float32 VAE, float64 GPs")
    for threads in (1, 2):
        torch.set_num_threads(threads)
        for batch in (256, 1024):
            # Frames in [0, 1] like rendered pendulum images; the content does not change the cost.
            frames = torch.rand(batch, CHANNELS, SIDE, SIDE)
            next_frames = torch.rand(batch, CHANNELS, SIDE, SIDE)
            a = torch.rand(batch, ACTION, dtype=torch.float64) * 4 - 2
            rewards = -torch.rand(batch, dtype=torch.float64) * 10

            def gradients():
                for p in params + gp_params:
                    p.grad = None
                step_loss(enc, dec, transition, reward, frames, next_frames, a, rewards).backward()

            def whole_step():
                gradients()
                adam.step()
                gp_adam.step()

            without = median_seconds(gradients, repeats)
            with_adam = median_seconds(whole_step, repeats)
            print(
                f"threads {threads}, batch {batch:4}: step without optimizer {without:6.2f} s, "
                f"with Adam {with_adam:6.2f} s (median of {repeats})"
            )


if __name__ == "__main__":
    main()
