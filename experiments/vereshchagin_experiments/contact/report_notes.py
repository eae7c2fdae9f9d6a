"""The contact report's fixed text: the setup, the gains and every way the simulation differs from Lau (2023).

:func:`setup_lines` and :func:`differences_lines` go into ``results/index.md``; docs/contact.md
states the same list. Numbers that come from constants are formatted from them, the measured
gain studies are quoted from :mod:`.controller`'s documentation of the gains.
"""

from __future__ import annotations

from .controller import CONTACT_GAINS, FREE_GAINS, REPORT_CONTACT_GAINS, REPORT_FREE_GAINS, ControllerConfig
from .metrics import STROKE_END
from .use_cases import CLEARANCE, DESCENT, JOINT_DAMPING, JOINT_FRICTION

__all__ = ["differences_lines", "gains_lines", "setup_lines"]


def _g(gains) -> str:
    return f"k_pos {{{gains.k_pos[0]:g}, {gains.k_pos[1]:g}}}, k_vel {{{gains.k_vel[0]:g}, {gains.k_vel[1]:g}}}"


def setup_lines(quick: bool) -> list[str]:
    """Plant and controller in one paragraph, then the mode."""
    cfg = ControllerConfig()
    return [
        "Plant: MuJoCo (1 kHz, implicitfast) model of the Kinova Gen3 + rigid Robotiq 2F-85 compiled from our "
        "URDF (same inertias as the controller's chain); joint friction (MuJoCo frictionloss, hard as the step "
        f"allows) {list(JOINT_FRICTION)} N m, damping {list(JOINT_DAMPING)} N m s/rad (joints 0-6); torque "
        "motors limited to ±39 N m (joints 0-3) / ±9 N m (joints 4-6); contact friction 0.3. Controller: the "
        f"report's cascaded P position -> velocity -> beta with our solver, twist saturated at {cfg.v_max} m/s / "
        f"{cfg.w_max} rad/s, z released on contact (|v_z| < 5 mm/s for 10 samples), friction-aware solve "
        f"(friction compensation, rest tolerance {cfg.friction_velocity_tolerance} rad/s: above the plant's creep "
        "under dry friction), f_ext with the model's normal-force estimate and mu = 0.3 against the sliding "
        "direction, a joint posture term in tau_ff for the self-motion.",
        "",
        f"Mode: {'quick (5 cm approach)' if quick else 'full (25 cm approach as in the report)'}. Joints are "
        "counted from 0 as in the report (0 base ... 6 last wrist joint; 1 shoulder, 3 elbow, 5 wrist).",
        "",
    ]


def gains_lines() -> list[str]:
    """Which gains each case uses and why they differ from the report's (measured, full mode)."""
    return [
        "Gains (report, use case 1: before contact " + _g(REPORT_FREE_GAINS) + ", after contact "
        f"{_g(REPORT_CONTACT_GAINS)}):",
        "",
        f"- Before contact (all cases): {_g(FREE_GAINS)}, the angular k_vel 40 instead of 2. Measured with 2: the "
        "full grasp completes (contact slide 99.4 mm, only the gripper touching the table), but in the quick "
        "grasp (5 cm descent) the wrist tilts on landing (the wrist links touch the table too, contact is "
        "detected 0.8 s late, the slide ends at 95.7 mm), and in writing the pen, pressed on the paper during "
        "the approach, turns the wrist (joint 5 from 55° to 122° before contact is detected) and the line is "
        "drawn 64 mm backwards; contactless both are fine with 2. The report's use case 3 failed the same way "
        "(a wrist joint rotating to its limit; its text blames the angular gain).",
        f"- After contact (grasp, writing): {_g(CONTACT_GAINS)}, the linear k_vel 15 instead of 4. With 4 the "
        "velocity loop corrects at most 4 × 0.05 = 0.2 m/s², less than the errors of the friction compensation "
        "under the ~50 N the arm's weight presses with after the 25 cm descent. Measured, full mode: with the "
        "report's exact gains the slide stops at 66 mm; with the angular k_vel 40 before contact and the linear "
        "k_vel after contact 4 / 7 / 10 / 15 it reaches 48 / 60 / 96 / 99.5 mm. The quick mode (5 cm descent) "
        "completes with 4.",
        "",
    ]


def differences_lines() -> list[str]:
    """Every way the simulated setup differs from the report's, one bullet each."""
    f = JOINT_FRICTION
    return [
        "What differs from the report (read every comparison below with these in mind):",
        "",
        "- No model error in the main runs: the plant is compiled from the controller's own URDF (same masses, "
        "inertias, friction). The section 'Model error' repeats the use cases on perturbed plants.",
        f"- The joint friction values are chosen, not measured (Kinova publishes none): {f[0]} N m on joints 0-3, "
        f"{f[4]} N m on joints 4-6, static = kinetic.",
        "- beta includes gravity and the velocity product (w × v terms) through `vs.task.beta_for`; the report "
        "set the acceleration set-points from the velocity loop alone.",
        "- tau_ff: zero in the report; here it carries the compensation of the plant's modelled viscous damping "
        "and a joint posture term (K, D) = (20, 3) (grasp, writing) or (0, 3) (elbow) that only acts in the "
        "unconstrained directions.",
        f"- Heights: the grasp starts with the gripper's lowest point {100 * DESCENT:g} cm (quick: 5 cm) above the "
        f"table; the report's arm moved about 25 cm down from its start pose. The contactless slide runs "
        f"{100 * CLEARANCE:g} cm above the table (the report gives no height). Writing: contact starts with the pen's "
        "axis end 1 cm above the paper (its rounded tip's lowest point 5 mm) and approaches until contact (the "
        "report started on the paper); contactless draws with the axis end 10 cm above the table (the tip's "
        "lowest point 9.5 cm; the report: the gripper's centre 10 cm above it).",
        "- The writing start pose is the grasp's start pose with a pen pointing down (the report gives no "
        "joint angles for writing, only photographs).",
        "- No object is grasped: the gripper is rigid, its closing command is only recorded, the table holds nothing.",
        "- Averaging windows include standing still: the slide's and the writing stroke's window is the "
        "motion's planned 2 s (0.10 m at 0.05 m/s) plus 1.5 s, so at least 1.5 s of it hold the goal; in the "
        f"writing table the stroke's last {1e3 * STROKE_END:g} mm (where the pen stops) are also shown apart.",
        "- Contact mode never ends: once detected, z stays released until the run ends (no lift-off phase; the "
        "grasp's closing happens in contact).",
        "- Power: ours is mechanical (τ q̇) or the copper-loss proxy ∫τ²; the report's Table 6.1 'power' is bus "
        "voltage times signed current, which follows signed torque (compared below).",
        "",
    ]
