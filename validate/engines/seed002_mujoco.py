"""MuJoCo model of seed 002's three-body pendulum: the TMT chain of :mod:`bifilar.seeds.seed002` as an
MjSpec (one hinge per coordinate), with visual geoms and the release keyframe."""

from __future__ import annotations

import mujoco

from bifilar.seeds.seed002 import BODIES, JOINTS, Params, chain, load

from .tmt_mujoco import chain_spec


def mjspec(p: Params) -> mujoco.MjSpec:
    """The MuJoCo model of the same chain, with RK4 at the parameter file's timestep, massless
    visual geoms that never collide, and the release state as keyframe ``release``."""
    L, vis = p.lengths, p.visual
    spec = chain_spec(chain(p), JOINTS, model_name="seed002")
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    spec.option.timestep = p.timestep
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    arm, rod, ball = (spec.body(name) for name in BODIES)
    visual = {"contype": 0, "conaffinity": 0}  # bodies carry explicit inertials, so geoms add no mass

    def bar(body, radius, start, end, kind=mujoco.mjtGeom.mjGEOM_CAPSULE):
        body.add_geom(type=kind, size=[radius, 0, 0], fromto=[*start, *end], **visual)

    # the bearing at the pivot, l1 above the inertial origin, along e1
    bar(spec.worldbody, 2 * vis["rod_radius"], (-0.03, 0, L["l1"]), (0.03, 0, L["l1"]), mujoco.mjtGeom.mjGEOM_CYLINDER)
    # arm: the bar from the pivot through its COM, and a bracket from the bar's end to the elbow
    bar(arm, vis["arm_radius"], (-L["l2"], -L["l3"], 0), (L["l2"], L["l3"], 0))
    bar(arm, vis["rod_radius"], (L["l2"], L["l3"], 0), (0, L["l4"], 0))
    bar(rod, vis["rod_radius"], (-L["l5"], -L["l6"], 0), (L["l5"], L["l6"], 0))
    ball.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[vis["ball_radius"], 0, 0], **visual)
    spec.add_key(name="release", qpos=p.q0, qvel=p.qd0)
    return spec


def model(p: Params | None = None) -> mujoco.MjModel:
    """The compiled MuJoCo model of the parameters (default: the shipped file)."""
    return mjspec(load() if p is None else p).compile()
