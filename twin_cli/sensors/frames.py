"""Finding a sensor's MuJoCo elements in a world by name (`<entity>/sensor:<name>`)."""

from __future__ import annotations

import mujoco

from twin_cli.errors import PartNotFoundError


def element_id(
    model: mujoco.MjModel, kind: mujoco.mjtObj, label: str, name: str, entity: str
) -> int:
    """The id of element `name` of `kind` (mjtObj) in `model`.

    Raises:
        PartNotFoundError: no such element (the sensor's site was not built).
    """
    found = mujoco.mj_name2id(model, kind, name)
    if found < 0:
        raise PartNotFoundError(entity, label, name, [])
    return int(found)


def site_id(model: mujoco.MjModel, entity: str, site: str) -> int:
    return element_id(model, mujoco.mjtObj.mjOBJ_SITE, "site", f"{entity}/{site}", entity)


def body_id(model: mujoco.MjModel, entity: str, body: str) -> int:
    """Body `body` of the entity (the world body for "world")."""
    if body == "world":
        return 0
    return element_id(model, mujoco.mjtObj.mjOBJ_BODY, "body", f"{entity}/{body}", entity)


def entity_bodies(model: mujoco.MjModel, entity: str) -> frozenset[int]:
    """Ids of every body whose name starts with `<entity>/`."""
    prefix = f"{entity}/"
    return frozenset(b for b in range(model.nbody) if model.body(b).name.startswith(prefix))


def native_ids(
    model: mujoco.MjModel, entity: str, site: str, parts: tuple[tuple[str, str], ...]
) -> list[int]:
    """The ids of the MuJoCo sensors `<entity>/<site>:<part>`, in `parts` order ([]: one lacks)."""
    kind = mujoco.mjtObj.mjOBJ_SENSOR
    ids = [mujoco.mj_name2id(model, kind, f"{entity}/{site}:{part}") for part, _ in parts]
    return ids if ids and min(ids) >= 0 else []


def native_slice(
    model: mujoco.MjModel, entity: str, site: str, parts: tuple[tuple[str, str], ...]
) -> slice | None:
    """Where the MuJoCo sensors `<entity>/<site>:<part>` of one twin sensor sit in sensordata.

    The converter adds them in `parts` order (the `native_parts` of the sensor's record);
    None when the model lacks one (a model built before they existed: computed instead).
    """
    ids = native_ids(model, entity, site, parts)
    if not ids:
        return None
    start = int(model.sensor_adr[ids[0]])
    end = start
    for i in ids:
        if int(model.sensor_adr[i]) != end:
            return None
        end += int(model.sensor_dim[i])
    return slice(start, end)
