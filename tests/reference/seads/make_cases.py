#!/usr/bin/env python
"""Generate cases.json: reference outputs of the authors' SEADS envs for mbrl's tests.

Run with venv/bin/python make_cases.py (see README.md). Deterministic: no randomness reaches the replays
(start states/boards are given; the only RNG, for the free reacher sequence, is np.random.RandomState(0)).
"""
import json
import math

import mujoco
import numpy as np

import replay as R

LO_EMPTY = "0" * 25
TS_SOLVED = list(range(9))


def strip(recs, keep_efc=True):
    out = []
    for r in recs:
        r = dict(r)
        if "physics_steps" in r:
            ps = r.pop("physics_steps")
            if keep_efc:
                lim = [p for p in ps if p["nefc"] > 0]
                if lim:
                    r["limit_physics_steps"] = lim
        out.append(r)
    return out


def case(name, env, state, board, actions, note, f32=False, efc=False, cont=False, max_steps=None,
         skills=False):
    recs = R.replay(env, state, board, actions, f32_actions=f32, efc=efc, continue_after_done=cont,
                    max_steps=max_steps, new_skill_after_done=skills)
    return {
        "name": name,
        "env": env,
        "env_name": R.ENV_NAMES[env],
        "start_state": [repr(float(v)) for v in state],
        "start_board": board,
        "actions": [[repr(float(np.float32(v) if f32 else v)) for v in a] for a in actions],
        "actions_cast_to_float32": f32,
        "continue_after_done": cont,
        "note": note,
        "command": "venv/bin/python replay.py --env %s --state %s --board %s --actions '%s'%s%s" % (
            env, ",".join(repr(float(v)) for v in state),
            board if isinstance(board, str) else ",".join(map(str, board)), json.dumps(actions),
            " --f32-actions" if f32 else "", " --continue-after-done" if cont else ""),
        "steps": strip(recs, keep_efc=efc),
    }


def cursor_cases():
    cs = []
    cs.append(case("cursor_wall_x0_clip_push_same_step", "lightsout-cursor", [0.0, 0.5], LO_EMPTY,
                   [[0.5, 0.0, 1.0]],
                   "x: 0 + clip(0.5 -> 0.2f32) = 0.20000000298023224 > 0.2 -> col 1 (field 11); "
                   "an exact-0.2 clip gives x = 0.2 -> col 0 (field 10)"))
    cs.append(case("cursor_wall_x0_clip_then_push", "lightsout-cursor", [0.0, 0.5], LO_EMPTY,
                   [[0.5, 0.0, -1.0], [0.0, 0.0, 1.0]],
                   "clipped move, then a push without moving: field 11 (exact-0.2 clip: field 10)"))
    cs.append(case("cursor_corner_00_diag_clip_push", "lightsout-cursor", [0.0, 0.0], LO_EMPTY,
                   [[0.5, 0.5, 1.0]],
                   "(0.2f32, 0.2f32) -> row 1, col 1 (field 6); exact 0.2 -> field 0"))
    cs.append(case("cursor_x0_three_clips_push", "lightsout-cursor", [0.0, 0.3], LO_EMPTY,
                   [[0.9, 0.0, -1.0], [0.9, 0.0, -1.0], [0.9, 0.0, 1.0]],
                   "x = 3*0.2f32 = 0.6000000089406967 > 0.6000000000000001 -> col 3 (field 8); "
                   "exact: 0.2+0.2+0.2 = 0.6000000000000001 -> col 2 (field 7)"))
    cs.append(case("cursor_x1_three_clips_push", "lightsout-cursor", [1.0, 0.7], LO_EMPTY,
                   [[-0.9, 0.0, -1.0], [-0.9, 0.0, -1.0], [-0.9, 0.0, 1.0]],
                   "x = 1 - 3*0.2f32 = 0.3999999910593033 -> col 1 (field 16); "
                   "exact: 1-0.2-0.2-0.2 = 0.4000000000000001 -> col 2 (field 17)"))
    cs.append(case("cursor_x1_one_clip_push_agree", "lightsout-cursor", [1.0, 0.7], LO_EMPTY,
                   [[-0.9, 0.0, 1.0]],
                   "x = 0.7999999970197678 -> col 3; exact 0.8 -> col 3 too (agreement case)"))
    cs.append(case("cursor_f32_actions_x0_clip_push", "lightsout-cursor", [0.0, 0.5], LO_EMPTY,
                   [[0.5, 0.0, 1.0]],
                   "same as cursor_wall_x0_clip_push_same_step with the action cast to float32 as the SEADS "
                   "agent does (SAC returns float32 arrays): same result", f32=True))
    cs.append(case("cursor_threshold_exact_no_push", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.0, 0.0, 0.6000000000000001]],
                   "push iff action[2] > -1 + 0.8*2 = 0.6000000000000001: exactly that value does not push"))
    cs.append(case("cursor_threshold_next_up_pushes", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.0, 0.0, 0.6000000000000002]],
                   "the next float64 above the threshold pushes (centre field 12)"))
    cs.append(case("cursor_threshold_0p6_no_push", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.0, 0.0, 0.6]], "0.6 does not push"))
    cs.append(case("cursor_threshold_exact_as_f32_pushes", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.0, 0.0, 0.6000000000000001]],
                   "cast to float32 0.6000000000000001 becomes 0.6000000238418579 and pushes", f32=True))
    cs.append(case("tileswap_cursor_corner_diag_clip_push", "tileswap-cursor", [0.0, 0.0], TS_SOLVED,
                   [[0.5, 0.5, 1.0]],
                   "(0.2f32,0.2f32): L1 distance to pivots (1/3,1/6) and (1/6,1/3) is ~1/6 (<= fieldsize/2 test); "
                   "reference outcome recorded"))
    cs.append(case("tileswap_cursor_offpivot_push_then_swap", "tileswap-cursor", [0.0, 0.0], TS_SOLVED,
                   [[0.0, 0.0, 1.0], [0.1, 0.1, 1.0], [0.2, 0.0, 1.0]],
                   "push at (0,0) and at (0.1,0.1): no pivot within 1/6 -> no swap, not done, counter runs on; then at (0.30000000000000004, 0.1) -> swap (0,0)-(0,1), skill 6"))
    return cs


def remaining_time_cases():
    cs = []
    # cursor: skill 1 changes the board at step k=4, then (as seads/solve_board.py) reset_step_counter and a
    # second skill that changes the board at step 2. Done by replaying twice from the carried-over state.
    env = R.make_env("lightsout-cursor")
    R.set_start(env, "lightsout-cursor", [0.1, 0.1], LO_EMPTY)
    seq = []
    acts1 = [[0.1, 0.1, -1.0]] * 3 + [[0.1, 0.1, 1.0]]
    acts2 = [[0.2, 0.0, -1.0], [0.0, 0.2, 1.0]]
    o = env.get_current_observation()
    seq.append({"skill": 1, "step": 0, "remaining_time": repr(float(o[-1]))})
    for i, a in enumerate(acts1, 1):
        o, _, d, info = env.step(np.array(a))
        seq.append({"skill": 1, "step": i, "action": a, "remaining_time": repr(float(o[-1])), "done": bool(d),
                    "groundtruth_skill": info.get("groundtruth_skill"),
                    "cursor": [repr(float(v)) for v in env.env.cursor]})
    env.reset_step_counter()
    o = env.get_current_observation()
    seq.append({"skill": 2, "step": 0, "remaining_time": repr(float(o[-1])), "note": "after reset_step_counter"})
    for i, a in enumerate(acts2, 1):
        o, _, d, info = env.step(np.array(a))
        seq.append({"skill": 2, "step": i, "action": a, "remaining_time": repr(float(o[-1])), "done": bool(d),
                    "groundtruth_skill": info.get("groundtruth_skill"),
                    "cursor": [repr(float(v)) for v in env.env.cursor]})
    cs.append({"name": "remaining_time_cursor_two_skills", "env": "lightsout-cursor", "max_steps": 10,
               "start_state": ["0.1", "0.1"], "start_board": LO_EMPTY,
               "note": "board change at step 4 -> remaining (10-4)/10 = 0.6 on that step; counter only resets "
                       "via reset()/reset_step_counter() (solve_board.py calls it before each skill)",
               "steps": seq})
    # Without reset_step_counter the counter keeps running after a board change:
    cs.append(case("remaining_time_cursor_no_reset_after_change", "lightsout-cursor", [0.1, 0.1], LO_EMPTY,
                   [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]],
                   "push changes the board at step 1 (remaining 0.9, done); continuing without "
                   "reset_step_counter: 0.8, 0.7", cont=True))
    cs.append(case("remaining_time_cursor_timeout", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.01, 0.0, -1.0]] * 10,
                   "no push for 10 steps: step 10 has remaining 0.0, done=True, info['timeout']=True"))
    cs.append(case("remaining_time_cursor_change_at_last_step", "lightsout-cursor", [0.5, 0.5], LO_EMPTY,
                   [[0.0, 0.0, -1.0]] * 9 + [[0.0, 0.0, 1.0]],
                   "board change on step 10: remaining 0.0, done, timeout flag also set"))
    # reacher, limit 50: push at step 7 (finger near the centre of the board)
    acts = [[0.0, 0.0, -1.0]] * 6 + [[0.0, 0.0, 1.0]]
    cs.append(case("remaining_time_reacher_change_at_step7", "lightsout-reacher", [0.0, 2.5, 0.0, 0.0], LO_EMPTY,
                   acts, "board change at step 7 -> remaining (50-7)/50 = 0.86"))
    cs.append(case("remaining_time_reacher_timeout", "lightsout-reacher", [0.0, 0.0, 0.0, 0.0], LO_EMPTY,
                   [[0.0, 0.0, -1.0]] * 50,
                   "arm stretched (finger off the board), no push: step 50 remaining 0.0, done, timeout"))
    return cs


def reacher_cases():
    cs = []
    # r1: from rest at wrist 2.0 rad, full + wrist torque into the +160 deg stop, hold, then full - torque back.
    acts = [[0.0, 1.0, -1.0]] * 19 + [[0.0, 1.0, 1.0]] + [[0.0, -1.0, -1.0]] * 19 + [[0.0, -1.0, 1.0]]
    cs.append(case("reacher_r1_plus_stop_and_back", "lightsout-reacher", [0.0, 2.0, 0.0, 0.0], LO_EMPTY, acts,
                   "40 steps; push at steps 20 and 40", efc=True, cont=True))
    # r2: moving towards the -160 stop, shoulder torque too, then reverse
    acts = [[0.5, -1.0, -1.0]] * 24 + [[0.5, -1.0, 1.0]] + [[-0.5, 1.0, -1.0]] * 14 + [[-0.5, 1.0, 1.0]]
    cs.append(case("reacher_r2_minus_stop_and_back", "lightsout-reacher", [1.0, -2.5, 0.0, -3.0], LO_EMPTY, acts,
                   "40 steps; push at 25 and 40", efc=True, cont=True))
    # r3: fast into the + stop with full torque on both joints, then full reverse; pushes every 10 steps
    acts = []
    for i in range(1, 51):
        c = [1.0, 1.0] if i <= 25 else [-1.0, -1.0]
        acts.append(c + [1.0 if i % 10 == 0 else -1.0])
    cs.append(case("reacher_r3_fast_plus_stop_both_full", "tileswap-reacher", [4.0, 2.7, 1.0, 5.0], TS_SOLVED, acts,
                   "50 steps (the 50th hits the time limit); pushes every 10 steps on TileSwap", efc=True, cont=True))
    # r4: gentle press, violation stays below solimp width (0.001 rad): impedance on the sigmoid, force > 0
    cs.append(case("reacher_r4_gentle_press_sigmoid", "lightsout-reacher", [0.0, 2.79, 0.0, 0.05], LO_EMPTY,
                   [[0.0, 0.002, -1.0]] * 29 + [[0.0, 0.002, 1.0]],
                   "wrist torque 0.002*0.05 against the + stop: equilibrium violation ~3e-4 rad < width, so "
                   "d(r) is on the solimp sigmoid; push at step 30", efc=True, cont=True))
    # reset-like start beyond the stop (ReacherEnv.reset draws the wrist in U(0, 2pi))
    cs.append(case("reacher_start_beyond_plus_stop", "lightsout-reacher", [1.0, 4.5, 0.0, 0.0], LO_EMPTY,
                   [[0.0, 0.0, -1.0]] * 10,
                   "wrist starts at 4.5 rad (> 160 deg), no torque: soft limit pushes it back", efc=True, cont=True))
    # free sequence: no limit contact
    rng = np.random.RandomState(0)
    acts = []
    for i in range(1, 31):
        u = rng.uniform(-0.4, 0.4, 2).round(6).tolist()
        acts.append(u + [1.0 if i in (15, 30) else -1.0])
    cs.append(case("reacher_free_no_limit", "lightsout-reacher", [0.5, 1.8, 0.0, 0.0], LO_EMPTY, acts,
                   "random torques in [-0.4, 0.4] (RandomState(0), rounded to 6 decimals); wrist stays inside "
                   "the range, so no constraint is ever active; pushes at 15 and 30", efc=True, cont=True))
    for c in cs:
        c["any_limit_active"] = any("limit_physics_steps" in s for s in c["steps"])
    return cs


def random_cases():
    """Random and edge-aimed sequences; the step counter restarts after every skill end, as mbrl's
    `collect --actions` replay and seads-agent's solve_board.py do."""
    cs = []
    edges = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]
    for env, board in (("lightsout-cursor", LO_EMPTY), ("tileswap-cursor", TS_SOLVED)):
        for seed in range(1, 5):
            rng = np.random.RandomState(seed)
            start = rng.uniform(0, 1, 2).tolist()
            acts = [rng.uniform(-0.3, 0.3, 2).tolist() + [1.0 if rng.rand() < 0.35 else -1.0] for _ in range(40)]
            cs.append(case(f"random_{env.replace('-', '_')}_{seed}", env, start, board, acts,
                           f"RandomState({seed}): start U(0,1)^2, moves U(-0.3,0.3) (some clipped), push p=0.35",
                           skills=True))
            start = [edges[rng.randint(6)], edges[rng.randint(6)]]
            steps = [0.2, -0.2, 0.1, -0.1, 0.0, 0.5, -0.5, 0.4, -0.4]
            acts = [[steps[rng.randint(9)], steps[rng.randint(9)], 1.0 if rng.rand() < 0.5 else -1.0]
                    for _ in range(30)]
            cs.append(case(f"edges_{env.replace('-', '_')}_{seed}", env, start, board, acts,
                           f"RandomState({seed}): start on field edges, moves of 0, ±0.1, ±0.2, ±0.4, ±0.5 "
                           "(landing on and clipping at edges), push p=0.5", skills=True))
    for env, board in (("lightsout-reacher", LO_EMPTY), ("tileswap-reacher", TS_SOLVED)):
        for seed in range(1, 4):
            rng = np.random.RandomState(100 + seed)
            start = rng.uniform(0, 2 * math.pi, 2).tolist() + [0.0, 0.0]
            acts = [rng.uniform(-1, 1, 2).tolist() + [1.0 if rng.rand() < 0.2 else -1.0] for _ in range(80)]
            cs.append(case(f"random_{env.replace('-', '_')}_{seed}", env, start, board, acts,
                           f"RandomState({100 + seed}): reset-like start U(0,2pi)^2 (the wrist often past its "
                           "stop), torques U(-1,1)^2, push p=0.2", skills=True))
    return cs


def model_facts():
    m = mujoco.MjModel.from_xml_path(
        str(R.seads_envs.__path__[0]) + "/hybrid/reacher/xmls/reacher.xml")
    return {
        "mujoco_version": mujoco.__version__,
        "opt": {"timestep": m.opt.timestep, "integrator": int(m.opt.integrator), "solver": int(m.opt.solver),
                "cone": int(m.opt.cone), "iterations": int(m.opt.iterations), "tolerance": m.opt.tolerance,
                "disableflags": int(m.opt.disableflags), "enableflags": int(m.opt.enableflags),
                "gravity": m.opt.gravity.tolist()},
        "jnt_range": m.jnt_range.tolist(), "jnt_limited": m.jnt_limited.tolist(),
        "jnt_solref": m.jnt_solref.tolist(), "jnt_solimp": m.jnt_solimp.tolist(),
        "jnt_margin": m.jnt_margin.tolist(),
        "dof_damping": m.dof_damping.tolist(), "dof_armature": m.dof_armature.tolist(),
        "dof_invweight0": [repr(float(v)) for v in m.dof_invweight0],
        "body_names": [m.body(i).name for i in range(m.nbody)],
        "body_mass": [repr(float(v)) for v in m.body_mass],
        "body_inertia": [[repr(float(v)) for v in row] for row in m.body_inertia],
        "body_ipos": m.body_ipos.tolist(),
        "actuator_gear": m.actuator_gear[:, 0].tolist(), "actuator_ctrlrange": m.actuator_ctrlrange.tolist(),
    }


def main():
    out = {
        "generated_by": "tests/reference/seads/make_cases.py with its venv (gym 0.19.0, numpy 1.26.4, "
                        "mujoco 3.17.0 via mujoco_py shim); seads-environments 4d4b821c, seads-agent 3556ad1e",
        "conventions": {
            "lightsout_board": "25 chars, row-major, row 0 = top (small y), field index = row*5 + col, col from x",
            "tileswap_board": "9 ints row-major; pushed_swap_pair = ((row,col),(row,col))",
            "numbers": "repr() strings of float64 (17 significant digits round-trip)",
            "reacher_state": "qpos=[shoulder, wrist], qvel likewise; finger = (geom xpos[:2] + 0.15)/0.3 "
                             "(x -> col, y -> row)",
            "remaining_time": "obs[-1] = (max_steps - steps)/max_steps, steps counted since reset()/"
                              "reset_step_counter()",
            "limit_physics_steps": "per control step, the physics steps (of action_repeat=2) in which MuJoCo "
                                   "had an active constraint: pre-step qpos/qvel/ctrl, efc_* of the forward pass "
                                   "inside mj_step, qM_dense, qacc_smooth, qacc, and qpos/qvel after the step",
        },
        "reacher_model": model_facts(),
        "cursor": cursor_cases(),
        "remaining_time": remaining_time_cases(),
        "reacher": reacher_cases(),
        "random": random_cases(),
    }
    with open("cases.json", "w") as f:
        json.dump(out, f, indent=1, default=lambda o: int(o) if isinstance(o, np.integer) else str(o))


if __name__ == "__main__":
    main()
