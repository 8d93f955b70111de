"""Joint-level Gazebo tags on an MjSpec (springs, limit softness, feedback) and blob reporting."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description.gazebo import Blob, GazeboExtensions, JointExtension
from converters.gazebo.contact import DEFAULT_LIMIT_ERP, LIMIT_SOLIMP, limit_solref
from converters.provenance import Provenance
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

BLOB_REASONS = {
    "plugin": "Gazebo plugins are not run by twin",
    "sensor": "twin does not simulate this sensor type",
    "canonicalBody": "sdformat itself does nothing with canonicalBody",
    "velocity_decay": "write dampingFactor instead; SDF <velocity_decay> blobs are not read",
    "kinematic": "kinematic links are not supported",
    "light": "lights attached to links are not converted",
    "projector": "projectors are not converted",
    "enable_wind": "twin has no wind",
    "allow_auto_disable": "sleeping is set for the whole world (twin physics --sleep)",
}


def apply_joint_tags(
    spec: mujoco.MjSpec, ext: GazeboExtensions, provenance: Provenance, report: Report
) -> None:
    """Map springStiffness/springReference/stopErp/... of each tagged joint onto the spec.

    Args:
        spec: the robot spec; joints named as in provenance.joints (MuJoCo name → URDF name).
        ext: parsed extensions.
        provenance: name maps of the built spec.
        report: receives one entry per tag.
    """
    mj_name = {urdf: mj for mj, urdf in provenance.joints.items()}
    _apply_default_limit_softness(spec, provenance, report)
    for name, joint_ext in ext.joints.items():
        subject = f"joint '{name}'"
        joint = spec.joint(mj_name.get(name, name))
        if name in ext.preserved_joints:
            report.mapped(subject, "fixed joint kept: child stays a separate body", tag="lumping")
        elif joint_ext.preserve_fixed_joint or joint_ext.disable_fixed_joint_lumping:
            report.ignored(subject, "not a fixed joint: nothing to preserve", tag="lumping")
        if joint is None:
            if _has_dynamics(joint_ext):
                report.warn(subject, "fixed (no MuJoCo joint): its joint tags have no effect")
            continue
        _apply_joint(joint, joint_ext, subject, report)


def _apply_default_limit_softness(
    spec: mujoco.MjSpec, provenance: Provenance, report: Report
) -> None:
    """Gazebo's default joint limit (SDF `limit/erp` 0.2, cfm 0: hard) on every robot joint.

    `converters.gazebo.contact.limit_solref` gives MuJoCo the reference dynamics of ODE's limit row
    (v' = −erp·r/h); `LIMIT_SOLIMP` (d = 0.9999) makes the row nearly as hard as cfm 0. MuJoCo's
    own default (solref 0.02 s, d 0.9–0.95) let a 1000 N m drive push the R2-D2 gripper 0.6 rad
    past its stop.
    """
    timeconst, ratio = limit_solref(None)
    count = 0
    for mj_joint in provenance.joints:
        joint = spec.joint(mj_joint)
        if joint is not None:
            joint.solref_limit = np.array([timeconst, ratio])
            joint.solimp_limit = np.array(LIMIT_SOLIMP)
            count += 1
    if count:
        report.mapped(
            "joint limits",
            f"Gazebo default limit erp {DEFAULT_LIMIT_ERP:g}, cfm 0 at 1 ms: solreflimit "
            f"{timeconst:g} s, damping ratio {ratio:.4g} (v' = −erp·r/h, as ODE), solimplimit "
            f"d = {LIMIT_SOLIMP[0]:g} (gives way by 1e-4 of the load) on {count} joints",
            tag="stopErp",
        )


def _has_dynamics(joint_ext: JointExtension) -> bool:
    names = ("stop_erp", "stop_cfm", "spring_stiffness", "spring_reference", "fudge_factor")
    return any(getattr(joint_ext, n) is not None for n in names)


def _apply_joint(joint: mujoco.MjsJoint, ext: JointExtension, subject: str, report: Report) -> None:
    if ext.spring_stiffness is not None:
        stiffness = list(joint.stiffness)
        stiffness[0] = ext.spring_stiffness
        joint.stiffness = np.array(stiffness)
        report.mapped(subject, f"joint stiffness {ext.spring_stiffness}", tag="springStiffness")
    if ext.spring_reference is not None:
        joint.springref = ext.spring_reference
        report.mapped(subject, f"springref {ext.spring_reference}", tag="springReference")
    if ext.stop_erp is not None or ext.stop_cfm is not None:
        timeconst, ratio = limit_solref(ext.stop_erp)
        joint.solref_limit = np.array([timeconst, ratio])
        entry = report.approximated if ext.stop_cfm else report.mapped
        entry(
            subject,
            f"stopErp={ext.stop_erp}: limit solref {timeconst:.4g} s, damping ratio {ratio:.4g}"
            + (f"; stopCfm={ext.stop_cfm} compliance not mapped" if ext.stop_cfm else ""),
            tag="stopErp",
        )
    _report_joint_flags(ext, subject, report)


def _report_joint_flags(ext: JointExtension, subject: str, report: Report) -> None:
    if ext.provide_feedback is not None:
        report.mapped(
            subject,
            "joint wrenches are always available in MuJoCo (cfrc_int, jointforce sensors)",
            tag="provideFeedback",
        )
    if ext.implicit_spring_damper is not None:
        report.approximated(
            subject,
            "MuJoCo integrates joint damping implicitly with the implicit integrator; "
            "springs stay explicit",
            tag="implicitSpringDamper",
        )
    if ext.fudge_factor is not None:
        report.ignored(subject, "ODE fudge factor has no MuJoCo equivalent", tag="fudgeFactor")


def report_blobs(ext: GazeboExtensions, report: Report) -> None:
    """Report every kept-verbatim element (plugins, unknown tags) as ignored, with why.

    Sensors are reported by `converters.gazebo.sensor_sites`, which maps them; model plugins by
    `converters.gazebo.plugins` (run as twin controllers or not run).
    """
    if ext.plugins:  # the plugin families are imported only for a model that has one
        from converters.gazebo.plugins import report_plugins

        report_plugins(ext.plugins, report)
    for blob in ext.model_blobs:
        _report_blob("model", blob, report)
    for link, link_ext in ext.links.items():
        for blob in link_ext.blobs:
            _report_blob(f"link '{link}'", blob, report)
    for joint, joint_ext in ext.joints.items():
        for blob in joint_ext.blobs:
            _report_blob(f"joint '{joint}'", blob, report)


def _report_blob(subject: str, blob: Blob, report: Report) -> None:
    reason = BLOB_REASONS.get(blob.tag, f"<{blob.tag}> is not a tag twin maps")
    label = " ".join(x for x in (blob.name and f"'{blob.name}'", blob.kind) if x)
    report.ignored(subject, f"<{blob.tag}> {label}: {reason}".replace("  ", " "), tag=blob.tag)
