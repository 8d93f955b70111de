"""Contact stiffness that the world's timestep can resolve (Gazebo's "stiffest stable contact").

The converter writes kp/kd as direct solrefs (`-S -B`) capped for Gazebo's 1 ms step. MuJoCo's
refsafe bound (time constant ≥ 2 steps) guards only positive solrefs, so a world with a longer
step (an SDF world's `max_step_size`, `twin physics --step`) would integrate those contacts
unstably: a box dropped at a 2 ms step on a kp = 1e12 ground bounced back to 95 % of its
height. Each compiled model is therefore capped at S ≤ 1/(2h)², keeping the damping ratio.
"""

from __future__ import annotations

import mujoco
import numpy as np


def cap_contact_stiffness(model: mujoco.MjModel, original: np.ndarray | None = None) -> int:
    """Caps every direct geom solref at the model's timestep; returns how many were capped.

    Args:
        model: a compiled model; `geom_solref` is changed in place.
        original: the uncapped solrefs (ngeom, 2) to start from (default: the model's own).
    """
    solref = model.geom_solref if original is None else original.copy()
    h = float(model.opt.timestep)
    limit = 1.0 / (2.0 * h) ** 2
    stiffness = -solref[:, 0]
    over = (solref[:, 0] < 0) & (stiffness > limit)
    ratio = np.ones(len(solref))
    ratio[over] = limit / stiffness[over]
    capped = solref.copy()
    capped[over, 0] = -limit
    capped[over, 1] = solref[over, 1] * np.sqrt(ratio[over])  # same damping ratio B/(2√S)
    model.geom_solref[:] = capped
    return int(over.sum())


def spec_solrefs(spec: mujoco.MjSpec, model: mujoco.MjModel) -> np.ndarray:
    """The uncapped solref of every geom of `model`, read from the spec it was compiled from.

    Needed when the timestep changes: the model holds values capped for the old step.
    """
    out = np.array(model.geom_solref)
    for i in range(model.ngeom):
        geom = spec.geom(model.geom(i).name) if model.geom(i).name else None
        if geom is not None:
            out[i] = geom.solref
    return out
