#!/usr/bin/env python
"""Replay an action sequence through the authors' SEADS environments (EmbodiedVision/seads-environments).

The environment is built exactly as seads-agent configures it (seads/train_seads.py named configs):
    seads_envs.load_env(env_name, reset_split, env_kwargs)   # time_limit=True, ext_timelimit_obs="full"
with env_kwargs = {"max_steps": 10 (cursor) / 50 (reacher), "max_solution_depth": 5,
                   "random_solution_depth": True, + "action_repeat": 2 for reacher}
i.e. the env is wrapped in seads_envs.wrapper.TimeLimitWrapper.

Deviations from the original set-up (documented in REPORT.md):
  * the board data sets (*.h5py) are Git-LFS objects missing from the snapshot; BoardLoader is replaced by a
    stub that returns the solved board (only used by reset(); the replay sets the board explicitly).
  * mujoco-py 2.0.2.13 / MuJoCo 2.0 cannot be installed; the reacher uses the unchanged reacher.xml in the
    official `mujoco` 3.17 bindings via a tiny mujoco_py shim (shim/mujoco_py).

The start state is put in as the env's own reset() would leave it:
  cursor : env.cursor = np.array([x, y], dtype=float64)           (reset: self.rng.rand(2), float64)
  reacher: sim.reset(); sim.set_state(MjSimState(0, qpos, qvel)); sim.forward()   (as ReacherEnv.reset)
and the wrapper's step counter is zeroed (TimeLimitWrapper.reset_step_counter, as seads/solve_board.py does
before every skill).

Usage:
  replay.py --env lightsout-cursor --state 0,0.5 --board 0000000000000000000000000 \
            --actions '[[0.5,0,-1],[0.5,0,1]]' [--f32-actions] [--efc] [--continue-after-done]
  board: LightsOut 25 chars of 0/1 (row-major, row 0 = top = small y); TileSwap 9 comma-separated ints.
  actions: JSON list of [a0, a1, push]; numbers are parsed as float64 (repr-exact). With --f32-actions each
  action is cast to np.float32 first, which is what the SEADS agent passes (SAC outputs float32 arrays).
Prints one JSON object per step.
"""
import argparse
import json
import sys

import numpy as np

import seads_envs
import seads_envs.board_games.discrete_environments as _de
from seads_envs.board_games.board_repr import LightsOutBoardRepr, TileSwapBoardRepr


class _StubBoardLoader:
    """Stands in for BoardLoader (the *.h5py board sets are LFS objects, absent): returns the solved board."""

    def __init__(self, filename, boardsize):
        if filename.startswith("lightsout"):
            self._packed = LightsOutBoardRepr(boardsize).binary_to_packed(
                LightsOutBoardRepr(boardsize).initial_binary_state
            )
        else:
            self._packed = TileSwapBoardRepr(boardsize).binary_to_packed(
                TileSwapBoardRepr(boardsize).initial_binary_state
            )

    def load_packed_board(self, solution_depth, split, rng):
        return self._packed.copy()


_de.BoardLoader = _StubBoardLoader

ENV_NAMES = {
    "lightsout-cursor": "LightsOutCursorEnvBs5",
    "tileswap-cursor": "TileSwapCursorEnvBs3",
    "lightsout-reacher": "LightsOutReacherEnvBs5",
    "tileswap-reacher": "TileSwapReacherEnvBs3",
}


def env_kwargs_for(env_key):
    # seads-agent/seads/train_seads.py: lightsout_cursor_env / tileswap_cursor_env / *_reacher_env
    kw = {"max_steps": 10, "max_solution_depth": 5, "random_solution_depth": True}
    if env_key.endswith("reacher"):
        kw["max_steps"] = 50
        kw["action_repeat"] = 2
    return kw


def make_env(env_key, seed=0, max_steps=None):
    kw = env_kwargs_for(env_key)
    if max_steps is not None:
        kw["max_steps"] = max_steps
    env = seads_envs.load_env(ENV_NAMES[env_key], "train", kw)
    env.seed(seed)
    return env


def set_start(env, env_key, state, board):
    base = env.env  # TimeLimitWrapper -> hybrid env
    if env_key.startswith("lightsout"):
        b = np.array([bool(int(c)) for c in board], dtype=bool).reshape(5, 5)
    else:
        b = np.array(board, dtype=int).reshape(3, 3)
        assert sorted(b.ravel().tolist()) == list(range(9))
    base._discrete_env.board_state = b.copy()
    if env_key.endswith("cursor"):
        base.cursor = np.array(state[:2], dtype=np.float64)
    else:
        from mujoco_py import MjSimState

        qpos = np.array(state[:2], dtype=np.float64)
        qvel = np.array(state[2:4], dtype=np.float64) if len(state) >= 4 else np.zeros(2)
        base._sim.reset()
        base._sim.set_state(MjSimState(time=0, qpos=qpos, qvel=qvel, act=None, udd_state={}))
        base._sim.forward()
    env.reset_step_counter()


def board_repr(env):
    b = env.env.board_state
    if b.dtype == bool:
        return "".join("1" if v else "0" for v in b.ravel())
    return [int(v) for v in b.ravel()]


def manip_record(env, env_key):
    base = env.env
    if env_key.endswith("cursor"):
        return {"cursor": [repr(float(v)) for v in base.cursor], "cursor_dtype": str(base.cursor.dtype)}
    st = base._sim.get_state()
    return {
        "qpos": [repr(float(v)) for v in st.qpos],
        "qvel": [repr(float(v)) for v in st.qvel],
        "finger": [repr(float(v)) for v in base._get_finger_pos()],
    }


def replay(env_key, state, board, actions, f32_actions=False, efc=False, continue_after_done=False,
           seed=0, max_steps=None, new_skill_after_done=False):
    """new_skill_after_done: after a done step, call reset_step_counter() (as seads-agent's solve_board.py
    does before each skill) and mark the next step "new_skill"."""
    env = make_env(env_key, seed=seed, max_steps=max_steps)
    set_start(env, env_key, state, board)
    obs0 = env.get_current_observation()
    out = [{"step": 0, **manip_record(env, env_key), "board": board_repr(env),
            "remaining_time": repr(float(obs0[-1]))}]
    sim = getattr(env.env, "_sim", None)
    new_skill = False
    for i, a in enumerate(actions, start=1):
        act = np.array(a, dtype=np.float32 if f32_actions else np.float64)
        board_before = board_repr(env)
        if efc and sim is not None:
            sim.step_log = []
        obs, reward, done, info = env.step(act)
        rec = {
            "step": i,
            "action": [repr(float(v)) for v in act],
            **manip_record(env, env_key),
            "push_flag": bool(act[-1] > env.env.PUSH_THRESHOLD),
            "groundtruth_skill": None if info.get("groundtruth_skill") is None else int(info["groundtruth_skill"]),
            "board_changed": board_repr(env) != board_before,
            "board": board_repr(env),
            "remaining_time": repr(float(obs[-1])),
            "done": bool(done),
            "timeout": bool(info.get("timeout", False)),
        }
        if new_skill:
            rec["new_skill"] = True
        new_skill = False
        if env_key.endswith("cursor") and rec["push_flag"]:
            pos = env.env.cursor
            if env_key.startswith("lightsout"):
                rec["pushed_field_rowcol"] = [int(v) for v in env.env.board.get_field_from_pos(pos)]
            else:
                sp = env.env.board.get_swap_pair_from_pos(pos)
                rec["pushed_swap_pair"] = None if sp is None else [list(map(int, p)) for p in sp]
        if env_key.endswith("reacher") and rec["push_flag"]:
            f = np.array([float(v) for v in rec["finger"]])
            rec["finger_on_board"] = bool((f <= 1).all() and (f >= 0).all())
            if rec["finger_on_board"]:
                if env_key.startswith("lightsout"):
                    rec["pushed_field_rowcol"] = [int(v) for v in env.env.board.get_field_from_pos(f)]
                else:
                    sp = env.env.board.get_swap_pair_from_pos(f)
                    rec["pushed_swap_pair"] = None if sp is None else [list(map(int, p)) for p in sp]
        if efc and sim is not None:
            rec["physics_steps"] = sim.step_log
            sim.step_log = None
        out.append(rec)
        if done and new_skill_after_done:
            env.reset_step_counter()
            new_skill = True
        elif done and not continue_after_done:
            break
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--env", required=True, choices=sorted(ENV_NAMES))
    p.add_argument("--state", required=True, help="cursor: x,y ; reacher: q_shoulder,q_wrist[,v_shoulder,v_wrist]")
    p.add_argument("--board", required=True)
    p.add_argument("--actions", required=True, help="JSON list of actions, or @file.json")
    p.add_argument("--f32-actions", action="store_true")
    p.add_argument("--efc", action="store_true", help="reacher: dump MuJoCo constraint data per physics step")
    p.add_argument("--continue-after-done", action="store_true",
                   help="keep stepping after done (the wrapper raises once max_steps is exceeded)")
    p.add_argument("--max-steps", type=int, default=None)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    state = [float(v) for v in args.state.split(",")]
    board = args.board if args.env.startswith("lightsout") else [int(v) for v in args.board.split(",")]
    acts = args.actions
    acts = json.load(open(acts[1:])) if acts.startswith("@") else json.loads(acts)
    for rec in replay(args.env, state, board, acts, args.f32_actions, args.efc, args.continue_after_done,
                      args.seed, args.max_steps):
        print(json.dumps(rec))


if __name__ == "__main__":
    main()
