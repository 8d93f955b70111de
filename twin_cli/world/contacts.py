"""What every compiled world model gets (`converters.mjcf.world_rules`): capped contact stiffness.

The converter writes kp/kd as direct solrefs (`-S -B`) capped for Gazebo's 1 ms step. MuJoCo's
refsafe bound (time constant ≥ 2 steps) guards only positive solrefs, so a world with a longer
step (an SDF world's `max_step_size`, `twin physics --step`) would integrate those contacts
unstably: a box dropped at a 2 ms step on a kp = 1e12 ground bounced back to 95 % of its
height. Each compiled model is therefore capped at S ≤ 1/(16·h²), keeping the damping ratio, and
given inverse weights that do not depend on where its robots spawned. The rules live in
converters, so the `scene.xml` that `twin convert` writes is finished by the same code.
"""

from __future__ import annotations

import mujoco
import numpy as np

from converters.mjcf.world_rules import finish_world_model


def cap_contact_stiffness(model: mujoco.MjModel, original: np.ndarray | None = None) -> int:
    """Finishes a compiled world model (`finish_world_model`): every direct geom solref capped
    at the model's timestep, pose-free inverse weights; returns how many solrefs were capped.

    Args:
        model: a compiled model; `geom_solref` and the inverse weights are changed in place.
        original: the uncapped solrefs (ngeom, 2) to start from (default: the model's own).
    """
    return finish_world_model(model, original)


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
