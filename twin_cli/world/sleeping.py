"""Which kinematic trees may sleep, and waking the ones twin drives (`twin physics --sleep`).

Why resting humanoids never slept: MuJoCo's compiler gives every tree that an actuator acts on
the sleep policy `mjSLEEP_AUTO_NEVER`, because a change of `ctrl` alone does not wake a tree
(only velocities, `xfrc_applied`, `qfrc_applied`, a changed `qpos` and contacts with awake
bodies do). Every twin robot has actuators (its joint servos), so none could ever sleep, whatever
the tolerance: a humanoid standing on its servos was measured at a dof-length-weighted speed of
1-5e-5 m/s, far under MuJoCo's default `sleep_tolerance` of 1e-3 m/s, yet never asleep.

twin writes every actuator command itself (`twin_cli.world.actuation.apply_command`, the
trajectory follower), so it can wake a tree whenever it changes the tree's `ctrl` or gains. It
therefore lets actuated trees sleep (`mjSLEEP_AUTO_ALLOWED`) and wakes them on each command; a
policy a model states itself (`sleep="never"` or `"allowed"` in MJCF) is left as it is.
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco

AUTO_NEVER = int(mujoco.mjtSleepPolicy.mjSLEEP_AUTO_NEVER)
AUTO_ALLOWED = int(mujoco.mjtSleepPolicy.mjSLEEP_AUTO_ALLOWED)


def allow_actuated(model: mujoco.MjModel) -> None:
    """Lets trees that MuJoCo kept awake only for their actuators sleep (see module docstring)."""
    policy = model.tree_sleep_policy
    policy[policy == AUTO_NEVER] = AUTO_ALLOWED


def wake_trees(data: mujoco.MjData, trees: Iterable[int]) -> None:
    """Wakes the islands of `trees` at the next step (a no-op for awake trees).

    Marking a sleeping tree awake is MuJoCo's own signal for "the user changed this tree" (what
    it does when `qpos` of a sleeping tree changes): the next `mj_step` wakes the tree's whole
    island before it integrates, so the command acts from that step on.
    """
    awake, asleep = data.tree_awake, data.tree_asleep
    for tree in trees:
        if 0 <= tree < len(asleep) and asleep[tree] >= 0:
            awake[tree] = 1


def actuator_trees(model: mujoco.MjModel, actuators: Iterable[int]) -> set[int]:
    """Kinematic trees moved by `actuators` (joint, site and body transmissions)."""
    trees = set()
    for a in actuators:
        kind, target = int(model.actuator_trntype[a]), int(model.actuator_trnid[a, 0])
        if target < 0:
            continue
        if kind in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT):
            body = int(model.jnt_bodyid[target])
        elif kind in (mujoco.mjtTrn.mjTRN_SITE, mujoco.mjtTrn.mjTRN_SLIDERCRANK):
            body = int(model.site_bodyid[target])
        elif kind == mujoco.mjtTrn.mjTRN_BODY:
            body = target
        else:  # a tendon may span trees: wake them all
            trees.update(int(t) for t in range(model.ntree))
            continue
        trees.add(int(model.body_treeid[body]))
    return trees


def wake_actuated(model: mujoco.MjModel, data: mujoco.MjData, actuators: Iterable[int]) -> None:
    """Wakes the trees that `actuators` move, when any tree sleeps (cheap otherwise)."""
    if data.ntree_awake < model.ntree:
        wake_trees(data, actuator_trees(model, actuators))


def hold_awake(model: mujoco.MjModel, trees: Iterable[int], awake: bool) -> None:
    """Keeps `trees` from sleeping while a servo moves them (`awake`), or lets them sleep again.

    A servo that ramps its reference from where the joint is (`twin_cli.world.servos`) starts
    with almost no force, so a tree woken by the command fell asleep again within its first
    steps and never moved. Only the automatic policies are switched; a policy the model states
    is kept.
    """
    policy = model.tree_sleep_policy
    for tree in trees:
        if 0 <= tree < len(policy) and int(policy[tree]) in (AUTO_NEVER, AUTO_ALLOWED):
            policy[tree] = AUTO_NEVER if awake else AUTO_ALLOWED
