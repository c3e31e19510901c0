"""Minimal stand-in for mujoco-py 2.0.2.13 on top of the official `mujoco` (3.17) Python bindings.

mujoco-py 2.0.2.13 needs the MuJoCo 2.0 binary + licence key, which cannot be installed here.
Only what seads_envs/hybrid/reacher/common.py uses is provided, with mujoco-py's semantics:
  MjSim(model).step()   -> mj_step  (nsubsteps=1)
  MjSim.forward()       -> mj_forward
  MjSim.reset()         -> mj_resetData
  MjSim.set_state(s)    -> copies time/qpos/qvel (no forward), as mujoco-py does
  MjSim.get_state()     -> MjSimState with copies of qpos/qvel
  data.get_geom_xpos(n) -> data.geom(n).xpos
"""
from collections import namedtuple

import mujoco
import numpy as np

__all__ = ["MjSim", "MjSimState", "load_model_from_path"]

MjSimState = namedtuple("MjSimState", "time qpos qvel act udd_state")


def load_model_from_path(path):
    return mujoco.MjModel.from_xml_path(path)


class _Data:
    def __init__(self, model, data):
        self._m = model
        self._d = data

    def __getattr__(self, name):
        return getattr(self._d, name)

    def get_geom_xpos(self, name):
        return self._d.geom(name).xpos

    def get_body_xpos(self, name):
        return self._d.body(name).xpos


def _dense_M(m, d):
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    return M.tolist()


class MjSim:
    def __init__(self, model, nsubsteps=1):
        self.model = model
        self._data = mujoco.MjData(model)
        self.data = _Data(model, self._data)
        self.nsubsteps = nsubsteps
        # replay.py hook: when a list, each mj_step appends the pre-step state and the constraint data
        # MuJoCo computed for that step (efc_* of the forward pass inside mj_step).
        self.step_log = None

    def step(self):
        for _ in range(self.nsubsteps):
            d = self._data
            if self.step_log is not None:
                pre = dict(time=float(d.time), qpos=d.qpos.tolist(), qvel=d.qvel.tolist(), ctrl=d.ctrl.tolist())
            mujoco.mj_step(self.model, d)
            if self.step_log is not None:
                pre.update(
                    nefc=int(d.nefc),
                    efc_type=d.efc_type.tolist(),
                    efc_id=d.efc_id.tolist(),
                    efc_J=d.efc_J.reshape(d.nefc, self.model.nv).tolist() if d.nefc else [],
                    efc_pos=d.efc_pos.tolist(),
                    efc_margin=d.efc_margin.tolist(),
                    efc_vel=d.efc_vel.tolist(),
                    efc_aref=d.efc_aref.tolist(),
                    efc_R=d.efc_R.tolist(),
                    efc_D=d.efc_D.tolist(),
                    efc_KBIP=d.efc_KBIP.reshape(-1, 4).tolist() if d.nefc else [],
                    efc_diagA=d.efc_diagA.tolist(),
                    efc_b=d.efc_b.tolist(),
                    efc_force=d.efc_force.tolist(),
                    efc_state=d.efc_state.tolist(),
                    qfrc_constraint=d.qfrc_constraint.tolist(),
                    qfrc_smooth=d.qfrc_smooth.tolist(),
                    qacc_smooth=d.qacc_smooth.tolist(),
                    qacc=d.qacc.tolist(),
                    qM_dense=_dense_M(self.model, d),
                    qpos_after=d.qpos.tolist(),
                    qvel_after=d.qvel.tolist(),
                )
                self.step_log.append(pre)

    def forward(self):
        mujoco.mj_forward(self.model, self._data)

    def reset(self):
        mujoco.mj_resetData(self.model, self._data)

    def get_state(self):
        d = self._data
        act = d.act.copy() if self.model.na > 0 else None
        return MjSimState(d.time, d.qpos.copy(), d.qvel.copy(), act, {})

    def set_state(self, state):
        d = self._data
        d.time = state.time
        d.qpos[:] = np.asarray(state.qpos, dtype=np.float64)
        d.qvel[:] = np.asarray(state.qvel, dtype=np.float64)
        if self.model.na > 0 and state.act is not None:
            d.act[:] = state.act

    def render(self, *args, **kwargs):
        raise NotImplementedError("rendering is not provided by this shim")
