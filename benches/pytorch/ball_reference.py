#!/usr/bin/env python3
"""PyTorch reference for the ball EKF's training step (src/models/ball/learn/ is the Rust side, and
benches/pytorch/training_steps.py times this file's step against it as the `ball_b64x50` row).

A batched, differentiable float64 EKF over B chunks with the equations of mbrl's batched filter, step by step:

  * state z = (p, v, ω, a_d, a_m); free flight is one Euler step with drag and Magnus effect,
    v̇ = −k_d ‖v‖ v + k_m ω × v + g with k = a² + ε, and its analytic Jacobian J_z assembled row block by row
    block (filter/flight.rs);
  * the one table impact per chunk: which samples bounce in a step, and which clamps of the gravity-only time of
    impact are active, are decided from the current means (outside the graph, as the Rust side decides them on
    the host) and enter as masks; the impacting samples fly to the time of impact, go through
    C' = blockdiag(I₃, C, 1, 1) and fly the rest of the step, with the Jacobian of C.2 including ∂Δ_imp/∂z
    (impact.rs);
  * prediction J Σ Jᵀ + Q, symmetrized; correction with H = [I₃, 0], (I − K H) Σ, symmetrized, and the
    innovation log-likelihood log N(m | Hμ, S); a missing measurement is the prediction alone (update.rs,
    filter.rs). S is factored by Cholesky where mbrl inverts it by its adjugate (linalg.rs): the two agree to
    rounding, and in PyTorch the factorization was slightly faster than the adjugate's element-wise ops;
  * the initial belief from m_1, m_2 under the broad spin prior (init.rs; the bench trains without the launcher
    network);
  * the loss −Σ w ⊙ log-likelihoods with w = 1 / (measurements in the chunk · B), the batch mean of the
    per-chunk mean innovation NLL; Ψ as raw tensors, variances through softplus(x) + 1e-6 (params.rs);
    torch.optim.Adam with the trainer's settings (lr 5e-3, betas 0.9/0.999, eps 1e-8).

The data, the raw starting values, physics and optimizer settings come from the case file that
`cargo run --release --example ball_loss_case` writes (target/ball_loss_case.json): the batches of the first
11 steps of mbrl's trainer on the bench's 40 simulated shots, with mbrl's loss and gradients on the first
batch and the losses mbrl's training reported over the 11 steps.

--check recomputes all three here and fails beyond the tolerances: the loss and the gradients with respect to
every raw parameter (each relative to that parameter's largest gradient entry), and the loss trajectory of 11
Adam steps, which also holds the optimizer and the later batches to mbrl's.

Usage: python3 benches/pytorch/ball_reference.py --check [FILE]
"""

import argparse
import json
import math
import os
import sys
import warnings
from dataclasses import dataclass

warnings.filterwarnings("ignore", message="Failed to initialize NumPy")

import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_CASE = os.path.join(ROOT, "target", "ball_loss_case.json")
DTYPE = torch.float64
# The floor of the thesis' positivity map [x]⊕ = log(1 + eˣ) + 1e-6.
VARIANCE_FLOOR = 1e-6
# The clamp of the time of impact for a ball starting a step at or below the plane (impact.rs).
MIN_HEIGHT_ABOVE_TABLE = 1e-4
# Raw parameters in the case file, C first as [6, 6].
PARAMETERS = ("c", "q", "r", "init_pos", "init_vel", "init_spin", "init_spin_after_impact", "a_d0", "a_m0",
              "a_d_var", "a_m_var")
# Relative; a gradient's to its parameter's largest entry, since small entries are sums of larger cancelling terms
# and carry their rounding.
LOSS_TOLERANCE = 1e-9
GRADIENT_TOLERANCE = 1e-7
# Adam's first updates are ±lr whatever a gradient's size, so gradient rounding barely moves later losses.
TRAJECTORY_TOLERANCE = 1e-9


@dataclass
class Physics:
    dt: float
    gravity: float
    coeff_offset: float
    table_z: float
    ball_radius: float


@dataclass
class Batch:
    m1: torch.Tensor  # [B, 3]
    m2: torch.Tensor  # [B, 3]
    measurements: torch.Tensor  # [steps, B, 3], zeros where missing
    measured: torch.Tensor  # [steps, B] bool
    # Per slot, whether any and whether every sample was measured: host-side, as the Rust filter's branches are.
    any_measured: list
    all_measured: list
    weights: torch.Tensor  # [B, steps]
    after_impact: torch.Tensor  # [B] bool


def load_case(path):
    try:
        with open(path) as f:
            return json.load(f)
    except FileNotFoundError:
        sys.exit(f"error: no case file {path}; write it with `cargo run --release --example ball_loss_case`")


def physics_of(case):
    return Physics(**case["physics"])


def batch_of(entry):
    """A batch of the case file as tensors, weighted as mbrl's Batch::new: 1 / (measurements in the chunk · B)."""
    slots = entry["slots"]
    b = len(slots)
    measured = torch.tensor([[s is not None for s in chunk] for chunk in slots]).T.contiguous()
    measurements = torch.tensor([[s or [0.0] * 3 for s in chunk] for chunk in slots], dtype=DTYPE)
    counts = measured.sum(0).clamp(min=1)
    weights = measured.T.to(DTYPE) / (counts * b).to(DTYPE).unsqueeze(1)
    return Batch(
        m1=torch.tensor(entry["m1"], dtype=DTYPE),
        m2=torch.tensor(entry["m2"], dtype=DTYPE),
        measurements=measurements.transpose(0, 1).contiguous(),
        measured=measured,
        any_measured=measured.any(1).tolist(),
        all_measured=measured.all(1).tolist(),
        weights=weights,
        after_impact=torch.tensor(entry["after_impact"]),
    )


def raw_parameters(case):
    """Fresh leaf tensors at the case's raw values."""
    raw = case["raw_params"]
    params = {name: torch.tensor(raw[name], dtype=DTYPE) for name in PARAMETERS}
    params["c"] = params["c"].reshape(6, 6)
    for p in params.values():
        p.requires_grad_()
    return params


def adam(params, case):
    o = case["optimizer"]
    return torch.optim.Adam(params.values(), lr=o["lr"], betas=(o["beta1"], o["beta2"]), eps=o["eps"])


def positive(raw):
    return F.softplus(raw) + VARIANCE_FLOOR


def symmetrize(p):
    # Rounding in J Σ Jᵀ and Σ − K H Σ leaves covariances slightly asymmetric.
    return (p + p.mT) * 0.5


def cross_matrix(u):
    """[u]ₓ [B, 3, 3] with [u]ₓ x = u × x."""
    zero = torch.zeros_like(u[:, 0])
    x, y, z = u.unbind(1)
    return torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], 1).reshape(-1, 3, 3)


class Flight:
    """The quantities of states x [B, 11] that one free-flight step and its Jacobians share."""

    def __init__(self, x, physics):
        self.v, w = x[:, 3:6], x[:, 6:9]
        self.ad, self.am = x[:, 9:10], x[:, 10:11]
        self.speed = self.v.square().sum(1, keepdim=True).sqrt()
        self.kd = self.ad.square() + physics.coeff_offset
        self.km = self.am.square() + physics.coeff_offset
        self.w_cross, self.v_cross = cross_matrix(w), cross_matrix(self.v)
        self.w_x_v = torch.linalg.cross(w, self.v, dim=1)
        gravity = x.new_tensor([0.0, 0.0, -physics.gravity])
        accel = -(self.kd * self.speed) * self.v + self.km * self.w_x_v + gravity
        # ż = (v, a, 0, 0, 0), which is also J_Δt (eq. C.6).
        self.rate = torch.cat([self.v, accel, torch.zeros_like(x[:, 6:])], 1)

    def step(self, x, dt):
        """g_free(x, Δt); dt a number or per sample [B, 1]."""
        return x + dt * self.rate

    def jacobian(self, dt):
        """J_z(x, Δt) [B, 11, 11]: the position rows, the velocity rows, and identity rows for ω, a_d, a_m."""
        b = self.v.shape[0]
        dt = dt.unsqueeze(2) if torch.is_tensor(dt) else dt
        eye = torch.eye(11, dtype=DTYPE).expand(b, 11, 11)
        v_col = self.v.unsqueeze(2)
        speed = self.speed.unsqueeze(2)
        # ∂(‖v‖v)/∂v = ‖v‖ I + v vᵀ/‖v‖; the clamp keeps 0/0 out at v = 0, where the outer product is 0.
        d_norm_v = speed * torch.eye(3, dtype=DTYPE) + v_col @ v_col.mT / speed.clamp(min=sys.float_info.min)
        km = self.km.unsqueeze(2)
        d_v = -self.kd.unsqueeze(2) * d_norm_v + self.w_cross * km
        d_w = -km * self.v_cross
        d_ad = (-2.0 * (self.v * self.speed * self.ad)).unsqueeze(2)
        d_am = (2.0 * (self.w_x_v * self.am)).unsqueeze(2)
        v_rows = torch.cat([d_v, d_w, d_ad, d_am], 2)
        v_rows = torch.cat([torch.zeros(b, 3, 3, dtype=DTYPE), eye[:, 3:6, 3:] + dt * v_rows], 2)
        p_rows = torch.cat([eye[:, :3, :3], dt * eye[:, :3, :3], eye[:, :3, 6:]], 2)
        return torch.cat([p_rows, v_rows, eye[:, 6:]], 1)


@torch.no_grad()
def impact_plan(x, before, physics):
    """Which samples hit the table in this step, and which clamps of Δ_imp are active: the reference model's own
    tests on the means, outside the graph."""
    pz, vz = x[:, 2], x[:, 5]
    impacting = before & (pz + physics.dt * vz - physics.ball_radius < physics.table_z)
    h_raw = -((pz - physics.ball_radius) - physics.table_z)
    clamped_height = impacting & (h_raw > -MIN_HEIGHT_ABOVE_TABLE)
    h = h_raw.masked_fill(clamped_height, -MIN_HEIGHT_ABOVE_TABLE)
    g_z = -physics.gravity
    capped = impacting & (-(vz + (vz * vz + 2.0 * g_z * h).sqrt()) / g_z > physics.dt)
    return impacting, clamped_height, capped


def impact_step(x, flight, c_full, plan, physics):
    """g(x) and ∂g/∂x of the impact branch for every sample, `flight` holding the flight quantities at x; rows of
    samples outside it are computed with harmless stand-ins (so no NaN reaches a masked-out gradient) and
    discarded by the caller."""
    impacting, clamped_height, capped = (m.unsqueeze(1) for m in plan)
    no_time = capped | ~impacting
    no_height = clamped_height | no_time
    pz, vz = x[:, 2:3], x[:, 5:6]
    g_z = -physics.gravity
    h = (-((pz - physics.ball_radius) - physics.table_z)).masked_fill(clamped_height, -MIN_HEIGHT_ABOVE_TABLE)
    root = (vz.square() + 2.0 * g_z * h).masked_fill(~impacting, 1.0).sqrt()
    # Δ_imp = −(v_z + √(v_z² + 2 g_z h)) / g_z; ∂Δ/∂p_z = 1/√(·), ∂Δ/∂v_z = −(1 + v_z/√(·))/g_z (C.2).
    t_imp = ((vz + root) / -g_z).masked_fill(no_time, physics.dt)
    d_pz = root.reciprocal().masked_fill(no_height, 0.0)
    d_vz = ((vz / root + 1.0) / -g_z).masked_fill(no_time, 0.0)
    zero = torch.zeros_like(d_pz)
    d_toi = torch.cat([zero, zero, d_pz, zero, zero, d_vz, zero.expand(-1, 5)], 1).unsqueeze(1)

    # J2 = C' (J_z(z, Δimp) + J_Δt(z) ∂Δimp/∂z).
    j_before = c_full @ (flight.jacobian(t_imp) + flight.rate.unsqueeze(2) @ d_toi)
    x_plus = flight.step(x, t_imp) @ c_full.T
    after = Flight(x_plus, physics)
    rest = physics.dt - t_imp
    # J = J_z(z⁺, Δrem) J2 − J_Δt(z⁺) ∂Δimp/∂z, since ∂Δrem/∂z = −∂Δimp/∂z.
    jac = after.jacobian(rest) @ j_before - after.rate.unsqueeze(2) @ d_toi
    return after.step(x_plus, rest), jac


def predict(mean, cov, before, c_full, q, physics):
    """μ ← g(μ), Σ ← J Σ Jᵀ + Q; `before` [B] says which samples may still bounce and is returned advanced."""
    flight = Flight(mean, physics)
    next_mean = flight.step(mean, physics.dt)
    jac = flight.jacobian(physics.dt)
    # After every sample has bounced no decision is left to take.
    if before.any():
        plan = impact_plan(mean, before, physics)
        impacting = plan[0]
        if impacting.any():
            mean_imp, jac_imp = impact_step(mean, flight, c_full, plan, physics)
            next_mean = torch.where(impacting.unsqueeze(1), mean_imp, next_mean)
            jac = torch.where(impacting.view(-1, 1, 1), jac_imp, jac)
            before = before & ~impacting
    return next_mean, symmetrize(jac @ cov @ jac.mT + q), before


def update(mean, cov, m, r):
    """Corrects every sample with m [B, 3]; returns the belief and log N(m | Hμ, S) [B]."""
    b = mean.shape[0]
    # H Σ is the first three rows of Σ; it serves both S and the gain.
    hp = cov[:, :3]
    chol = torch.linalg.cholesky(hp[:, :, :3] + r)
    innovation = (m - mean[:, :3]).unsqueeze(2)
    gain_t = torch.cholesky_solve(hp, chol)  # Kᵀ = S⁻¹ H Σ
    mean = mean + (gain_t.mT @ innovation).reshape(b, 11)
    cov = symmetrize(cov - hp.mT @ gain_t)
    white = torch.linalg.solve_triangular(chol, innovation, upper=False)
    log_det = 2.0 * chol.diagonal(dim1=1, dim2=2).log().sum(1)
    log_likelihood = -0.5 * (white.square().sum((1, 2)) + log_det + 3.0 * math.log(2.0 * math.pi))
    return mean, cov, log_likelihood


def initial_belief(batch, params, physics):
    """Mean [B, 11] and covariance [B, 11, 11] at m_2 under the broad spin prior ω ~ N(0, diag([σ_ω]⊕))."""
    b = batch.m1.shape[0]
    velocity = (batch.m2 - batch.m1) / physics.dt
    coefficients = torch.cat([params["a_d0"], params["a_m0"]]).expand(b, 2)
    mean = torch.cat([batch.m2, velocity, torch.zeros(b, 3, dtype=DTYPE), coefficients], 1)
    variances = torch.cat([positive(params[n]) for n in ("init_pos", "init_vel", "init_spin", "a_d_var", "a_m_var")])
    return mean, torch.diag_embed(variances).expand(b, 11, 11)


def log_likelihoods(params, batch, physics):
    """log N(m_n | μ_n|1:n−1, S_n) [B, steps], 0 where a slot has no measurement."""
    b = batch.m1.shape[0]
    c_full = torch.block_diag(torch.eye(3, dtype=DTYPE), params["c"], torch.eye(2, dtype=DTYPE))
    q = torch.diag(positive(params["q"]))
    r = torch.diag(positive(params["r"]))
    mean, cov = initial_belief(batch, params, physics)
    before = ~batch.after_impact
    per_slot = []
    for t, (m, measured) in enumerate(zip(batch.measurements, batch.measured)):
        mean, cov, before = predict(mean, cov, before, c_full, q, physics)
        if not batch.any_measured[t]:
            per_slot.append(torch.zeros(b, dtype=DTYPE))
            continue
        mean_u, cov_u, ll = update(mean, cov, m, r)
        if batch.all_measured[t]:
            mean, cov = mean_u, cov_u
            per_slot.append(ll)
        else:
            # A missing measurement is a prediction alone.
            mean = torch.where(measured.unsqueeze(1), mean_u, mean)
            cov = torch.where(measured.view(-1, 1, 1), cov_u, cov)
            per_slot.append(ll.masked_fill(~measured, 0.0))
    return torch.stack(per_slot, 1)


def chunk_loss(params, batch, physics):
    """The batch mean of each chunk's mean innovation NLL per measurement (eq. 6.24)."""
    return -(log_likelihoods(params, batch, physics) * batch.weights).sum()


def train_step(params, optimizer, batch, physics):
    """One Adam step; returns the loss before it, as mbrl's trainer reports it."""
    optimizer.zero_grad(set_to_none=True)
    loss = chunk_loss(params, batch, physics)
    loss.backward()
    optimizer.step()
    return loss.item()


def relative(difference, scale):
    return difference / scale if scale > 0 else difference


def check(case):
    """Prints the largest differences to mbrl's figures; returns whether all are within tolerance."""
    physics = physics_of(case)
    batches = [batch_of(entry) for entry in case["batches"]]
    params = raw_parameters(case)
    loss = chunk_loss(params, batches[0], physics)
    loss.backward()
    loss_diff = relative(abs(loss.item() - case["loss"]), abs(case["loss"]))
    print(f"loss: PyTorch {loss.item():.15e}, mbrl {case['loss']:.15e}, relative difference {loss_diff:.2e}")

    worst_grad = 0.0
    for name in PARAMETERS:
        theirs = torch.tensor(case["gradients"][name], dtype=DTYPE)
        ours = params[name].grad.reshape(-1) if params[name].grad is not None else torch.zeros_like(theirs)
        diff = relative((ours - theirs).abs().max().item(), theirs.abs().max().item())
        worst_grad = max(worst_grad, diff)
        print(f"  ∂loss/∂{name}: largest difference {diff:.2e} of the largest |gradient| {theirs.abs().max():.3e}")

    params = raw_parameters(case)
    optimizer = adam(params, case)
    worst_step = 0.0
    for batch, theirs in zip(batches, case["train_losses"]):
        ours = train_step(params, optimizer, batch, physics)
        worst_step = max(worst_step, relative(abs(ours - theirs), abs(theirs)))
    print(f"losses of {len(batches)} Adam steps: largest relative difference {worst_step:.2e}")

    ok = loss_diff <= LOSS_TOLERANCE and worst_grad <= GRADIENT_TOLERANCE and worst_step <= TRAJECTORY_TOLERANCE
    print(f"{'ok' if ok else 'FAILED'}: tolerances {LOSS_TOLERANCE:g} (loss), {GRADIENT_TOLERANCE:g} (gradients), "
          f"{TRAJECTORY_TOLERANCE:g} (training losses)")
    return ok


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--check", metavar="FILE", nargs="?", const=DEFAULT_CASE, required=True,
        help=f"compare with mbrl's loss, gradients and training losses in FILE (default {DEFAULT_CASE})",
    )
    args = parser.parse_args()
    # The figures do not depend on the thread count; on a busy 2-core machine one thread is far faster.
    torch.set_num_threads(1)
    sys.exit(0 if check(load_case(args.check)) else 1)


if __name__ == "__main__":
    main()
