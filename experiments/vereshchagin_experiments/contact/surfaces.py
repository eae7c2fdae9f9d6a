"""The contact use cases' surfaces as the solver's point contacts (:class:`vereshchagin.Contact`), built from the scene.

Before the library had contacts, the controllers did "hand surgery" on the solver's results: an
estimated table force in ``f_ext``, a constraint's share removed from the command when its sign
said the surface pushes. Here the surfaces go into the solve instead
(``solve(..., contacts=[...])``): the solver finds the contact forces, ``tau_command`` is the
motors' share only.

- :class:`ContactPoint`: one point of the scene the robot touches (a link, a point on it, or the
  lowest point of a sphere on it; the surface's normal, friction coefficient and, for a pen,
  a normal-force set-point);
- :class:`SceneContacts`: the contacts of a scene for one control cycle, ``(q, qd) -> (contacts,
  qd_solve)``, optionally only while a condition holds (the controller in contact mode);
- the points of the use cases: :func:`tool_support` (the gripper's lowest edge on the table),
  :func:`pen_setpoint` (the pen tip pressing with a set force), :func:`elbow_support` (the elbow
  sphere on its support), :func:`wrist_support` (the gripper resting on a table under the wrist).

Velocity tolerance (a workaround): the solver treats a support as touching while its normal
velocity is at most ``SolveInput::contact_velocity_tolerance`` (1e-6 m/s; the Python ``solve``
has no argument for it), refuses a support that approaches faster (an impact) and lets a point
slide whose tangential speed exceeds it. A point on MuJoCo's soft contact is never that still: it
sinks and creeps by 0.1-5 mm/s. :class:`SceneContacts` therefore hands the solve a
contact-consistent velocity: the measured ``qd`` minus the least-norm joint velocity that moves
each contact point with its normal velocity (a sliding point keeps its tangential velocity), or
with its whole velocity if it is slower than ``rest_speed`` (resting: sticking is then possible).

Sliding direction (a second workaround, optional): the solver puts a sliding point's friction
against its tangential velocity, a discontinuous function of it. The gripper on MuJoCo's table
wobbles (its measured point velocity swings by +-30 mm/s sideways at 1 kHz); friction set from
the last sample lags the plant's and pumped the wobble up until the wrist rolled and the tool left
its line by up to 18 cm. With ``reference`` (the velocity the controller asks for, the desired
twist's linear part) a tracked point slides in the solve along the reference's tangential
direction, as the old ``f_ext`` friction compensation did, at its measured speed along it but at
least 1.5 ``rest_speed`` (so that a slide just starting is not taken for a resting point the task
drags: that stalled the full grasp); a reference slower than ``rest_speed`` makes it rest. Using
the reference's speed itself instead made the solve's joint velocities far from the measured ones
(the full grasp then crawled at 20 mm/s and stopped 15 mm short). What the loop measures is otherwise unchanged.

Units SI; points in the link's own frame (m), normals in base axes (unit, from the surface into
the robot), forces in N.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from vereshchagin import Contact
from .controller import CONTROL_PERIOD

__all__ = [
    "RESTING_SPEED",
    "WRITING_FORCE",
    "ContactPoint",
    "SceneContacts",
    "elbow_support",
    "pen_setpoint",
    "point_jacobian",
    "tool_support",
    "wrist_support",
]

RESTING_SPEED = 5e-3
"""m/s: a contact point slower than this counts as resting (the controller's contact threshold)."""
WRITING_FORCE = 20.0
"""N: the pen's normal-force set-point. Lau (2023) gives none (its pen pressed with what gravity
left along the released z); 5 N is a firm handwriting pressure."""
FACETS = 32
"""Vertices of the friction polygons. A sliding point's friction sits at the polygon's vertex most
opposed to its velocity: with the default 4 the friction of a gripper sliding diagonally points
up to 45 degrees off its velocity, and in the grasp's slide that error grew into a sideways drift
(the tool ended 46 mm off its line, 55 mm short). 32 vertices: at most 5.6 degrees off."""
CONTACT_CONFIG = {"time_step": CONTROL_PERIOD}
"""Controller settings (:class:`~.controller.ControllerConfig` fields) of the runs with contacts: the
discrete-time mode (the solve over the next 1 ms control period). At the end of a slide the P
loop's tiny corrections change sign every few cycles; at the instant each needs the full sliding
friction (mu f_n, 11 N on the gripper) the other way, and the command jumped by 5 N m per step at
the shoulder. Over a step the point whose end velocity friction can stop gets the force that
holds it, continuous in the correction (the earlier fix, a hold band of 1 mm / 0.01 rad inside
which the task asked for zero acceleration, is :data:`BAND_CONFIG`)."""
BAND_CONFIG = {"hold_band": (1e-3, 1e-2)}
"""The contact runs' settings before the discrete-time mode: the solve at the instant and a hold band
of 1 mm / 0.01 rad (zero task acceleration inside), for the before / after comparison."""
STICK_MARGIN = 0.5
"""Factor on a resting point's friction coefficient in the solve. Where the contact forces are not
unique (a resting point whose motion the task also fixes) the solver takes those of least motor
effort, which load static friction up to the cone's edge; MuJoCo's soft friction, built up by
creep, then slips: the dual-arm's resting hand crept 71 mm with the full mu. Half the cone leaves
the plant a margin (an engineer's safety factor on a friction coefficient); a sliding point keeps
the full mu (its friction is compensated)."""
UP = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class ContactPoint:
    """One point of the robot on a surface of the scene.

    Attributes
    ----------
    frame : str
        The link (or frame merged into a segment) the point moves with.
    point : (float, float, float)
        In that link's frame (m): the point itself, or the centre of a sphere when ``radius`` > 0.
    mu : float
        Coulomb friction coefficient of the surface (>= 0).
    radius : float
        m; > 0: the point is the sphere's point farthest along ``-normal`` (the lowest point of an
        elbow housing on a horizontal support), recomputed every cycle.
    normal : (float, float, float)
        Unit, base axes: the direction the surface pushes the robot (default +z, a table).
    force : float or None
        None: a support (the solver finds its force >= 0). A number: a normal-force set-point (N).
    facets : int
        Vertices of the friction polygon (default :data:`FACETS`).
    tracked : bool
        The point moves with the controlled frame: its tangential velocity in the solve is the
        reference's (:class:`SceneContacts`), not the measured one.
    """

    frame: str
    point: tuple = (0.0, 0.0, 0.0)
    mu: float = 0.3
    radius: float = 0.0
    normal: tuple = UP
    force: Optional[float] = None
    facets: int = 0
    tracked: bool = False

    def local_point(self, T) -> np.ndarray:
        """The contact point in the link frame (m) when the link's pose is ``T`` (4, 4, base frame)."""
        p = np.asarray(self.point, float)
        if self.radius > 0.0:
            p = p - self.radius * (np.asarray(T)[:3, :3].T @ np.asarray(self.normal, float))
        return p

    def contact(self, T, resting: bool = False) -> Contact:
        """The solver's :class:`vereshchagin.Contact` for the link pose ``T`` (4, 4, base frame).

        ``resting``: the point rests; its friction cone is then ``STICK_MARGIN * mu`` wide.
        """
        mu = self.mu * (STICK_MARGIN if resting else 1.0)
        facets = self.facets or FACETS
        return Contact(
            self.frame, point=self.local_point(T), normal=self.normal, mu=mu, facets=facets, force=self.force
        )


def point_jacobian(model, q, frame: str, point) -> np.ndarray:
    """Linear Jacobian (3, n) of a point fixed in ``frame`` (coordinates ``point`` in that frame, m), base axes."""
    T = np.asarray(model.fk(q, frame))
    J = np.asarray(model.jacobian(q, frame))
    r = T[:3, :3] @ np.asarray(point, float)
    return J[:3] - np.cross(r, J[3:].T).T


class SceneContacts:
    """The contacts of a scene for one control cycle: ``(q, qd) -> (contacts, qd_solve)``.

    Parameters
    ----------
    model : Chain or Tree
        The controller's model (``fk``, ``jacobian`` by link name).
    points : sequence of ContactPoint
        The scene's contact points.
    active : callable, optional
        ``active() -> bool``: the points touch now (e.g. the controller is in contact mode);
        None: always.
    rest_speed : float
        m/s, see the module doc.
    reference : callable, optional
        ``reference() -> (3,)``: the velocity the controller wants the tracked points
        (``ContactPoint.tracked``) to move with (m/s, base axes). Given, their tangential velocity
        in the solve points along this one's tangential part (module doc); None: the measured one.

    Attributes
    ----------
    last : list of Contact
        The contacts of the last call (empty when inactive).
    """

    def __init__(
        self,
        model,
        points,
        active: Optional[Callable[[], bool]] = None,
        rest_speed: float = RESTING_SPEED,
        reference: Optional[Callable[[], np.ndarray]] = None,
    ):
        self.model = model
        self.points = tuple(points)
        self.active = active
        self.rest_speed = float(rest_speed)
        self.reference = reference
        self.last: list = []

    def __call__(self, q, qd) -> tuple[list, np.ndarray]:
        """Contacts (list of :class:`vereshchagin.Contact`) at ``q`` (rad) and the velocity ``qd`` (rad/s) to solve with."""
        q, qd = np.asarray(q, float), np.asarray(qd, float)
        if self.active is not None and not self.active():
            self.last = []
            return [], qd
        contacts, rows, removed = [], [], []
        for p in self.points:
            T = np.asarray(self.model.fk(q, p.frame))
            local = p.local_point(T)
            Jp = point_jacobian(self.model, q, p.frame, local)
            n = np.asarray(p.normal, float)
            v = Jp @ qd
            vt = v - n * (n @ v)
            if p.tracked and self.reference is not None:
                r = np.asarray(self.reference(), float)
                r = r - n * (n @ r)
                if np.linalg.norm(r) >= self.rest_speed:  # slides along r, at the measured speed along it (or more)
                    u = r / np.linalg.norm(r)
                    vt = u * max(float(vt @ u), 1.5 * self.rest_speed)
                else:
                    vt = np.zeros(3)
            resting = bool(np.linalg.norm(vt) < self.rest_speed)
            contacts.append(p.contact(T, resting))
            rows.append(Jp)
            # remove the normal velocity; keep the tangential one of a sliding point (or the reference's)
            removed.append(v if resting else v - vt)
        self.last = contacts
        return contacts, qd - np.linalg.lstsq(np.vstack(rows), np.concatenate(removed), rcond=None)[0]


def tool_support(frame: str, tool_point, mu: float) -> ContactPoint:
    """The gripper's lowest edge (``tool_point`` in ``frame``, m) resting on or sliding along a table."""
    return ContactPoint(frame, tuple(float(x) for x in tool_point), mu=mu, tracked=True)


def pen_setpoint(frame: str, tip, mu: float, force: float = WRITING_FORCE) -> ContactPoint:
    """The pen tip (``tip`` in ``frame``, m) pressing on the paper with ``force`` (N)."""
    return ContactPoint(frame, tuple(float(x) for x in tip), mu=mu, force=float(force), tracked=True)


def elbow_support(frame: str, radius: float, mu: float) -> ContactPoint:
    """The lowest point of the elbow's sphere (centre: ``frame``'s origin, ``radius`` m) on its support."""
    return ContactPoint(frame, mu=mu, radius=float(radius))


def wrist_support(frame: str, low_point, mu: float) -> ContactPoint:
    """The gripper under the wrist (its lowest edge, ``low_point`` in ``frame``, m) resting on a table."""
    return ContactPoint(frame, tuple(float(x) for x in low_point), mu=mu, tracked=True)
