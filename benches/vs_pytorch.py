#!/usr/bin/env python3
"""mbrl's training steps beside PyTorch's, back to back on this machine: runs
`cargo bench --bench training_steps` and benches/pytorch/training_steps.py, then prints the ratio table
with each step's FLOP count, both sides' GFLOP/s, the f32 GEMM ceiling measured in the same run, and the
load the machine was under (load average, and how many cores other processes kept busy while each side ran).

The ball EKF's PyTorch side trains on the batches mbrl's trainer draws: when that row is selected, this script
first runs `cargo run --release --example ball_loss_case`, which writes them with mbrl's loss, gradients and
training losses to target/ball_loss_case.json, then `benches/pytorch/ball_reference.py --check` on that file,
and stops if the reference no longer computes mbrl's loss; neither counts towards either side's load figures.

A step meets the target when mbrl is at least 2x PyTorch, or, for the steps whose PyTorch side already runs
near the ceiling (PETS medium and DLGPD's conv VAE, as issue 39 names them), when mbrl reaches at least 85 %
of the GEMM ceiling without being slower than PyTorch. The other steps' GFLOP/s divide PyTorch's FLOP count,
which can exceed the work mbrl does (the context model shares its action embedding between the single-step and
multi-step predictions), so their share of the ceiling is not a target.

With --rounds N (N > 1) the two sides take turns N times, mbrl first in odd rounds and PyTorch first in even
ones, so that a drift in the machine's speed falls on both; each row then shows each side's median time, the
median of the rounds' ratios and their range. On a shared or virtual machine whose speed moves from minute to
minute, a single round's ratio can be off by a fifth either way.

Usage: python3 benches/vs_pytorch.py [--quick] [--rounds N] [--only NAME[,NAME...]] [--python PY]
                                      [--markdown FILE]
(`make bench-vs-pytorch` runs it, ROUNDS=N for rounds; PYTORCH_PYTHON names an interpreter that has torch.)
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BALL_ROW = "ball_b64x50"
# Where ball_reference.py and training_steps.py read the ball case from by default.
BALL_CASE = os.path.join(ROOT, "target", "ball_loss_case.json")

LABELS = {
    "pets_small": "PETS small (5 × 3×64), batch 256",
    "pets_medium": "PETS medium (5 × 4×200), batch 256",
    "context_b64": "context model, paper net, batch 64 × 50",
    "context_b512": "context model, paper net, batch 512 × 50",
    "sac_b128": "SAC update (SEADS 2×256), batch 128",
    "dlgpd_b256": "DLGPD step without Adam, batch 256",
    "dlgpd_b1024": "DLGPD step without Adam, batch 1024",
    "ball_b64x50": "ball EKF, 64 chunks × 50 frames",
}

# The steps whose PyTorch side runs near the GEMM ceiling, where 85 % of it is the alternative to 2x.
NEAR_CEILING = {"pets_medium", "dlgpd_b256", "dlgpd_b1024"}


def machine_busy_seconds():
    with open("/proc/stat") as f:
        fields = [int(v) for v in f.readline().split()[1:]]
    idle = fields[3] + fields[4]
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def children_seconds():
    t = os.times()
    return t.children_user + t.children_system


def load_average():
    with open("/proc/loadavg") as f:
        return f.read().split()[0]


def run_side(name, command):
    """Runs one side; returns its JSON rows and what else the machine did meanwhile."""
    load_before = load_average()
    busy0, own0, wall0 = machine_busy_seconds(), children_seconds(), time.monotonic()
    proc = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE, text=True)
    busy1, own1, wall1 = machine_busy_seconds(), children_seconds(), time.monotonic()
    if proc.returncode != 0:
        sys.exit(f"error: {name} side failed (exit {proc.returncode}): {' '.join(command)}")
    rows = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    others = max(0.0, (busy1 - busy0) - (own1 - own0)) / max(wall1 - wall0, 1e-9)
    return rows, {"load_before": load_before, "load_after": load_average(), "other_cores": others, "wall": wall1 - wall0}


def prepare_ball_case(python):
    commands = [
        ["cargo", "run", "--release", "--quiet", "--example", "ball_loss_case", "--", BALL_CASE],
        [python, os.path.join(HERE, "pytorch", "ball_reference.py"), "--check", BALL_CASE],
    ]
    for command in commands:
        if subprocess.run(command, cwd=ROOT).returncode != 0:
            sys.exit(f"error: the ball EKF's PyTorch case failed: {' '.join(command)}")


def find_python(explicit):
    candidates = [explicit] if explicit else [os.environ.get("PYTORCH_PYTHON"), sys.executable, "python3"]
    for python in filter(None, candidates):
        probe = subprocess.run([python, "-c", "import torch"], capture_output=True)
        if probe.returncode == 0:
            return python
    sys.exit(
        "error: no Python with torch found. Install it with `pip install torch` (CPU-only wheels: "
        "`pip install torch --index-url https://download.pytorch.org/whl/cpu`), or name an interpreter that has "
        "it with --python or PYTORCH_PYTHON."
    )


def fmt_time(seconds):
    if seconds is None:
        return "—"
    return f"{seconds * 1e3:.2f} ms" if seconds < 1 else f"{seconds:.2f} s"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer timed steps on both sides")
    parser.add_argument("--only", help="comma-separated workloads: " + ", ".join(LABELS))
    parser.add_argument("--python", help="the Python interpreter with torch")
    parser.add_argument("--markdown", help="also write the table to this file")
    parser.add_argument("--rounds", type=int, default=1, help="turns each side takes, alternating (default 1)")
    args = parser.parse_args()
    if not 1 <= args.rounds <= 20:
        sys.exit(f"error: --rounds expects 1 to 20 rounds, got {args.rounds}")
    python = find_python(args.python)
    extra = (["--quick"] if args.quick else []) + (["--only", args.only] if args.only else [])
    if args.only is None or BALL_ROW in args.only.split(","):
        prepare_ball_case(python)

    commands = {
        "mbrl": ["cargo", "bench", "--quiet", "--bench", "training_steps", "--"] + extra,
        "PyTorch": [python, os.path.join(HERE, "pytorch", "training_steps.py")] + extra,
    }
    runs = {"mbrl": [], "PyTorch": []}
    loads = {"mbrl": [], "PyTorch": []}
    for round_index in range(args.rounds):
        order = ["mbrl", "PyTorch"] if round_index % 2 == 0 else ["PyTorch", "mbrl"]
        for side in order:
            if args.rounds > 1:
                print(f"round {round_index + 1} of {args.rounds}: {side}", file=sys.stderr, flush=True)
            rows, load = run_side(side, commands[side])
            runs[side].append(rows)
            loads[side].append(load)

    torch_version = next((r["torch"] for rows in runs["PyTorch"] for r in rows if "torch" in r), "?")
    ceiling = {}
    for rows in runs["mbrl"]:
        for r in rows:
            if r.get("workload") == "gemm_ceiling":
                ceiling[r["threads"]] = max(ceiling.get(r["threads"], 0.0), r["gflops"])
    # Per (workload, threads): {round: seconds} on each side, so that a row one side lacks in a round leaves
    # that round unpaired instead of pairing the rounds after it wrongly.
    mbrl, torch_seconds, flop_counts = {}, {}, {}
    for index, rows in enumerate(runs["mbrl"]):
        for r in rows:
            if "seconds" in r:
                mbrl.setdefault((r["workload"], r["threads"]), {})[index] = r["seconds"]
    for index, rows in enumerate(runs["PyTorch"]):
        for r in rows:
            if "workload" in r and "seconds" in r:
                torch_seconds.setdefault((r["workload"], r["threads"]), {})[index] = r["seconds"]
                if r.get("flops"):
                    flop_counts[(r["workload"], r["threads"])] = r["flops"]

    rounds = args.rounds > 1
    lines = [
        f"| training step | threads | PyTorch {torch_version} | mbrl | mbrl / PyTorch speed |"
        + (f" range over {args.rounds} rounds |" if rounds else "")
        + " GFLOP per step | PyTorch GFLOP/s | mbrl GFLOP/s | mbrl, % of GEMM ceiling | 2× PyTorch, % of ceiling |"
        + " target |",
        "|---|---|---|---|---|" + ("---|" if rounds else "") + "---|---|---|---|---|---|",
    ]
    for (name, threads), our_times in mbrl.items():
        their_times = torch_seconds.get((name, threads), {})
        flops = flop_counts.get((name, threads))
        ours_s = statistics.median(our_times.values())
        theirs_s = statistics.median(their_times.values()) if their_times else None
        paired = [their_times[i] / our_times[i] for i in sorted(our_times) if i in their_times]
        ratio = statistics.median(paired) if paired else None
        gflop = flops / 1e9 if flops else None
        our_rate = gflop / ours_s if gflop else None
        their_rate = gflop / theirs_s if gflop and theirs_s else None
        share = our_rate / ceiling[threads] if our_rate and threads in ceiling else None
        # What 2x would take at PyTorch's FLOP count: past 100 %, no step doing that work can get there.
        double_share = 2 * their_rate / ceiling[threads] if their_rate and threads in ceiling else None
        if ratio is None:
            verdict = "no PyTorch reference"
        elif ratio >= 2.0 or (name in NEAR_CEILING and share is not None and share >= 0.85 and ratio >= 1.0):
            verdict = "met"
        else:
            verdict = "not met"
        cells = [
            LABELS.get(name, name),
            str(threads),
            fmt_time(theirs_s),
            fmt_time(ours_s),
            f"{ratio:.2f}×" if ratio else "—",
        ]
        if rounds:
            short = f" ({len(paired)} rounds)" if len(paired) < args.rounds else ""
            cells.append(f"{min(paired):.2f}–{max(paired):.2f}×{short}" if paired else "—")
        cells += [
            f"{gflop:.3g}" if gflop else "—",
            f"{their_rate:.1f}" if their_rate else "—",
            f"{our_rate:.1f}" if our_rate else "—",
            f"{100 * share:.0f} %" if share else "—",
            f"{100 * double_share:.0f} %" if double_share else "—",
            verdict,
        ]
        lines.append("| " + " | ".join(cells) + " |")
    ceilings = ", ".join(f"{ceiling[t]:.1f} GFLOP/s at {t} thread{'s' if t > 1 else ''}" for t in sorted(ceiling))
    lines.append("")
    lines.append(f"f32 GEMM ceiling (faer, 1024³, best of the run): {ceilings}.")
    for side in ("mbrl", "PyTorch"):
        side_loads = loads[side]
        turns = f"{len(side_loads)} turns, " if rounds else ""
        busiest = max(load["other_cores"] for load in side_loads)
        lines.append(
            f"{side} side: {turns}{sum(load['wall'] for load in side_loads):.0f} s, load average "
            f"{side_loads[0]['load_before']} → {side_loads[-1]['load_after']}, other processes kept "
            f"{busiest:.2f} cores busy{' at most' if rounds else ''}."
        )
    if rounds:
        lines.append(
            "Times are each side's median over the rounds; the ratio is the median of the rounds' ratios (each "
            "round's PyTorch time over its mbrl time), and the target is judged on it."
        )
    lines.append(
        "FLOPs: matmul and convolution FLOPs of forward and backward, counted by torch's FlopCounterMode on "
        "PyTorch's step; both sides' GFLOP/s divide that count by their own time. \"2× PyTorch, % of ceiling\" is "
        "twice PyTorch's GFLOP/s over the ceiling: the share of the ceiling a step doing PyTorch's FLOPs would "
        "need to reach 2x."
    )
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table + "\n")


if __name__ == "__main__":
    main()
