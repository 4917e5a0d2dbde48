"""Open-loop batches in MuJoCo's C threads (`mujoco.rollout`) and the full physics state they start from."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...engines.core import callbacks_installed, check_plugin_faults, n_workers
from ...errors import SceneError, SolverError


def rollout_sweep(models: Any, initial_states: np.ndarray, controls: np.ndarray, *, workers: int = 0,
                  nstep: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Open-loop trajectories of a batch in MuJoCo's C threads (`mujoco.rollout`), `workers` threads (0 = all cores).

    `models`: one MjModel or a sequence (one per trajectory, same sizes); `initial_states` (B, nstate) in
    mjSTATE_FULLPHYSICS; `controls` (B, nstep, nu) (or singleton dimensions). Returns (state (B, nstep, nstate),
    sensordata). Refuses to run while a Python callback is installed: rollout's threads would call it without the GIL
    serialising the model's state, and a scene with callbacks must go through `run_sweep` instead."""
    import mujoco
    from mujoco import rollout

    installed = callbacks_installed()
    if installed:
        raise SceneError(f"rollout_sweep needs a scene without Python callbacks; installed: {installed}. "
                         "Use run_sweep (processes) for such scenes.")
    m0 = models if isinstance(models, mujoco.MjModel) else models[0]
    nt = max(1, min(n_workers(workers), np.shape(initial_states)[0]))
    datas = [mujoco.MjData(m0) for _ in range(nt)]
    state, sens = rollout.rollout(models, datas, np.asarray(initial_states, float), np.asarray(controls, float),
                                  nstep=nstep)
    for d in datas:  # a fault of an mbsuite plugin in any trajectory stays recorded in the data that ran it
        check_plugin_faults(m0, d, "mujoco.rollout batch")
    if not np.all(np.isfinite(state)):
        raise SolverError("mujoco.rollout batch: a trajectory became non-finite (NaN/inf); reduce the timestep")
    return state, sens


def state_size(model: Any) -> int:
    """The length of MuJoCo's full physics state of `model` (`mj_stateSize`, `mjSTATE_FULLPHYSICS`)."""
    import mujoco

    return mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)


def get_state(model: Any, data: Any) -> np.ndarray:
    """The full physics state of `data` (the initial-state format of `rollout_sweep`)."""
    import mujoco

    s = np.zeros(state_size(model))
    mujoco.mj_getState(model, data, s, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    return s
