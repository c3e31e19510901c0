"""Writes src/envs/embodiments/reference_cases.rs from cases.json (python3 to_rust.py > ../../../src/envs/embodiments/reference_cases.rs)."""
import json, sys
c = json.load(open('cases.json'))

def f(x):
    s = repr(float(x))
    if s in ('inf', '-inf', 'nan'): raise SystemExit('non-finite')
    return s

def pushed(case, st, prev_board):
    if not st.get('board_changed'):
        return 'Pushed::Nothing'
    if 'lightsout' in case['env']:
        return f"Pushed::Field({st['groundtruth_skill']})"
    a, b = st['board'], prev_board
    diff = [i for i in range(9) if a[i] != b[i]]
    assert len(diff) == 2, diff
    return f"Pushed::Swap({diff[0]}, {diff[1]})"

out = []
def emit(case, steps_groups):
    env = case['env'].replace('-', ':')
    board0 = case['start_board']
    assert board0 in ('0' * 25, list(range(9))), board0
    reacher = 'reacher' in env
    start = [f(x) for x in case['start_state']]
    if reacher and len(start) == 2: start += ['0.0', '0.0']
    rows = []
    prev_board = board0
    for new_skill, st in steps_groups:
        if reacher:
            state = [f(x) for x in st['qpos'] + st['qvel']]
        else:
            state = [f(x) for x in st['cursor']]
        p = pushed(case, st, prev_board) if 'board' in st else ('Pushed::Nothing' if st.get('groundtruth_skill') is None else f"Pushed::Field({st['groundtruth_skill']})")
        if 'board' in st: prev_board = st['board']
        act = ', '.join(f(x) for x in st['action'])
        rows.append(f"        ReferenceStep {{ new_skill: {str(new_skill).lower()}, action: [{act}], state: &[{', '.join(state)}], pushed: {p}, remaining: {f(st['remaining_time'])}, done: {str(bool(st['done'])).lower()} }},")
    out.append(f"    ReferenceCase {{\n        name: \"{case['name']}\",\n        env: \"{env}\",\n        start: &[{', '.join(start)}],\n        steps: &[\n" + '\n'.join('    ' + r for r in rows) + "\n        ],\n    },")

for case in c['cursor'] + c['remaining_time'] + c['reacher'] + c['random']:
    if case.get('actions_cast_to_float32'):
        # the action values recorded are the float32-cast values, already exact in f64
        pass
    steps = case['steps']
    groups = []
    if 'skill' in steps[0]:
        last_skill = 1
        for st in steps:
            if st['step'] == 0: continue
            groups.append((st['skill'] != last_skill, st)); last_skill = st['skill']
    else:
        groups = [(bool(st.get('new_skill')), st) for st in steps if st['step'] > 0]
    emit(case, groups)

hdr = '''//! Expected steps of the authors' embodied board games, recorded once from the reference and kept as data.
//!
//! How they were made: seads-environments @ 4d4b821c (EmbodiedVision) installed with gym 0.19 and numpy 1.26,
//! each env built as seads-agent's named configs build it (`seads_envs.load_env(..., "train")`, time-limit
//! wrapper included; limits 10 for Cursor, 50 for Reacher, action repeat 2), started from the given
//! manipulator state and the solved board, and stepped with float64 actions; `reset_step_counter()` before
//! a step marked `new_skill`, as seads-agent's `solve_board.py` calls it before each skill. The Reacher's
//! `reacher.xml` ran in MuJoCo 3.17 (the `mujoco` wheel) behind a small mujoco-py stand-in, since
//! mujoco-py 2.0 and MuJoCo 2.0 cannot be installed here. Numbers are Python `repr`s, so each literal is the
//! reference's float64 exactly. The script is `tests/reference/seads/make_cases.py`.

/// What the step did to the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Pushed {
    Nothing,
    /// LightsOut: the field toggled (row · 5 + column).
    Field(usize),
    /// TileSwap: the two fields swapped (row-major indices, smaller first).
    Swap(usize, usize),
}

pub(super) struct ReferenceStep {
    /// The reference reset its step counter before this step.
    pub new_skill: bool,
    pub action: [f64; 3],
    /// Manipulator state after the step: cursor x, y; or Reacher shoulder, wrist, their velocities.
    pub state: &'static [f64],
    pub pushed: Pushed,
    pub remaining: f64,
    pub done: bool,
}

pub(super) struct ReferenceCase {
    pub name: &'static str,
    pub env: &'static str,
    /// Manipulator state before the first step; the board starts solved.
    pub start: &'static [f64],
    pub steps: &'static [ReferenceStep],
}

#[rustfmt::skip]
pub(super) const REFERENCE_CASES: &[ReferenceCase] = &[
'''
sys.stdout.write(hdr + '\n'.join(out) + '\n];\n')
