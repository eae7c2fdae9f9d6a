"""Random serial chains for the tests, built twice: as a vereshchagin.Chain and as a Pinocchio model.

KDL semantics (what the vereshchagin Chain means):

* a segment is a joint followed by a tip frame; the joint acts in the segment's root frame, which is
  the previous segment's tip frame (the base frame for the first segment);
* KDL's joint pose J(q): 'rot_x' / 'rot_y' / 'rot_z': Rot(axis, q); 'trans_x' / ...: Trans(axis * q);
  Joint.revolute(axis, origin): Trans(origin) * Rot(axis, q); Joint.prismatic(axis, origin):
  Trans(origin + axis * q); Joint.fixed(): identity;
* KDL::Segment stores the given tip as J(0)^-1 * tip, so the ``tip`` passed to add_segment is the
  tip pose *at q = 0* in the root frame, and tip_in_root(q) = J(q) * J(0)^-1 * tip. For a revolute
  joint that is Trans(origin) Rot(axis, q) Trans(-origin) tip: ``origin`` is a point on the
  rotation axis. For a prismatic joint it is Trans(axis * q) tip: ``origin`` has no effect.
  (Checked against Debian's liborocos-kdl 1.5.1 Segment::pose.)
* mass, com and inertia (about the com) are in the (moving) tip frame;
* rotor_inertia adds to the joint's diagonal entry of the mass matrix (Pinocchio: model.armature).

Pinocchio model: one joint per moving segment whose frame is the moved KDL joint frame, i.e. the
joint placement (in the parent Pinocchio joint's frame) is ``root_in_parent * Trans(origin)`` and
the joint motion is Rot(axis, q) / Trans(axis * q). The segment body is appended with placement
``Trans(-origin) * tip`` (its inertia is given in the tip frame), and an OP_FRAME sits on every
segment tip; the next segment's root is that same placement in this joint's frame. Bodies
of fixed segments are appended to the last moving joint before them (the universe if none).

Everything is drawn from a seeded ``numpy.random.Generator`` so a failure reproduces from its seed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

import vereshchagin as vs

G_EARTH = np.array([0.0, 0.0, -9.81])

_UNIT = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


# ----------------------------------------------------------------------------------------------
# Small numpy geometry (independent of both libraries)
# ----------------------------------------------------------------------------------------------
def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rot_axis(axis, angle):
    """Rotation matrix about the unit vector ``axis`` by ``angle`` (Rodrigues)."""
    k = skew(axis)
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def homogeneous(R=None, p=None):
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def random_rotation(rng):
    """Uniformly distributed rotation matrix (normalised Gaussian quaternion)."""
    w, x, y, z = rng.normal(size=4) / 1.0
    n = np.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def random_unit_vector(rng):
    while True:
        v = rng.uniform(-1.0, 1.0, 3)
        n = np.linalg.norm(v)
        if 0.1 < n <= 1.0:
            return v / n


def random_rotational_inertia(rng):
    """R diag(a, b, c) R^T with principal moments obeying the triangle inequality."""
    while True:
        a, b, c = rng.uniform(0.01, 0.5, 3)
        if a + b >= c and b + c >= a and a + c >= b:
            break
    R = random_rotation(rng)
    I = R @ np.diag([a, b, c]) @ R.T
    return 0.5 * (I + I.T)


def se3(T):
    return pin.SE3(np.array(T[:3, :3]), np.array(T[:3, 3]))


# ----------------------------------------------------------------------------------------------
# Chain description
# ----------------------------------------------------------------------------------------------
@dataclass
class SegmentSpec:
    kind: str  # 'rot_x', ..., 'trans_z', 'revolute', 'prismatic', 'fixed'
    axis: np.ndarray  # unit axis (zero for fixed)
    origin: np.ndarray  # joint origin in the segment root frame
    tip: np.ndarray  # 4x4
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # 3x3 about the com, tip axes
    rotor: float
    axis_given: np.ndarray | None = None  # the (unnormalised) axis passed to vereshchagin

    @property
    def moving(self):
        return self.kind != "fixed"

    @property
    def revolute(self):
        return self.kind.startswith("rot") or self.kind == "revolute"

    def joint_pose(self, q):
        """KDL Joint::pose(q): 4x4 pose of the moved joint frame in the segment root frame."""
        if self.kind == "fixed":
            return np.eye(4)
        if self.revolute:
            return homogeneous(rot_axis(self.axis, q), self.origin)
        return homogeneous(None, self.origin + self.axis * q)

    def pose(self, q):
        """KDL Segment::pose(q): the tip frame in the segment root frame."""
        return self.joint_pose(q) @ np.linalg.inv(self.joint_pose(0.0)) @ self.tip


def planar_rot_z_links(n, inertia, rotor):
    """n rot_z links of length 1 along x, 1 kg with the COM at mid-link (tip frame) and the given
    rotational inertia about it (3x3, tip axes) and rotor inertia: a planar arm along x at q = 0."""
    return [
        SegmentSpec(
            "rot_z",
            np.array([0.0, 0.0, 1.0]),
            np.zeros(3),
            homogeneous(None, [1.0, 0.0, 0.0]),
            1.0,
            np.array([-0.5, 0.0, 0.0]),
            np.asarray(inertia, dtype=float),
            rotor,
        )
        for _ in range(n)
    ]


@dataclass
class RandomChain:
    segments: list
    chain: vs.Chain
    model: pin.Model
    tip_frames: list  # Pinocchio frame id of each segment's tip
    seg_joint: list  # Pinocchio joint id carrying each segment's body (0 = universe)
    n_joints: int
    n_segments: int
    seed: object = None
    extra: dict = field(default_factory=dict)

    def solver(self, gravity=G_EARTH, **kw):
        self.model.gravity = pin.Motion(np.concatenate([np.asarray(gravity, float), np.zeros(3)]))
        return vs.Solver(self.chain, gravity=np.asarray(gravity, float), **kw)

    def data(self):
        return self.model.createData()

    def tip_poses(self, q):
        """Independent numpy forward kinematics of every segment tip (base frame), KDL semantics."""
        T = np.eye(4)
        out = []
        j = 0
        for s in self.segments:
            T = T @ s.pose(q[j] if s.moving else 0.0)
            j += s.moving
            out.append(T.copy())
        return out


def _random_segment(rng, kind_pool, rotor=True):
    kind = kind_pool[rng.integers(len(kind_pool))]
    origin = np.zeros(3)
    axis_given = None
    if kind in ("rot_x", "rot_y", "rot_z", "trans_x", "trans_y", "trans_z"):
        axis = _UNIT[kind[-1]].copy()
    elif kind in ("revolute", "prismatic"):
        axis = random_unit_vector(rng)
        axis_given = axis * rng.uniform(0.2, 5.0)  # the library must normalise it
        origin = rng.uniform(-0.3, 0.3, 3)
    else:
        axis = np.zeros(3)
    tip = homogeneous(random_rotation(rng), rng.uniform(-0.5, 0.5, 3))
    mass = rng.uniform(0.1, 5.0)
    com = rng.uniform(-0.3, 0.3, 3)
    inertia = random_rotational_inertia(rng)
    r = 0.0
    if rotor and kind != "fixed" and rng.random() < 0.5:
        r = rng.uniform(0.0, 0.5)
    return SegmentSpec(kind, axis, origin, tip, mass, com, inertia, r, axis_given)


REVOLUTE_KINDS = ("rot_x", "rot_y", "rot_z", "revolute")
ALL_KINDS = ("rot_x", "rot_y", "rot_z", "revolute", "trans_x", "trans_y", "trans_z", "prismatic")


def random_chain(rng, n_joints, prismatic=True, rotor=True, fixed_prob=0.0):
    """A random chain with ``n_joints`` moving joints (and fixed segments with prob. fixed_prob)."""
    pool = ALL_KINDS if prismatic else REVOLUTE_KINDS
    segments = []
    k = 0
    while k < n_joints:
        if fixed_prob > 0.0 and rng.random() < fixed_prob:
            segments.append(_random_segment(rng, ("fixed",), rotor))
            continue
        segments.append(_random_segment(rng, pool, rotor))
        k += 1
    if fixed_prob > 0.0 and rng.random() < fixed_prob:  # maybe a fixed segment last
        segments.append(_random_segment(rng, ("fixed",), rotor))
    return build(segments)


def build(segments, inertia_check="physical"):
    """Build both the vereshchagin Chain and the Pinocchio Model from segment specs
    (``inertia_check='joint_space'`` for identified, non-rigid-body inertias)."""
    chain = vs.Chain()
    for i, s in enumerate(segments):
        if s.kind == "revolute":
            joint = vs.Joint.revolute(s.axis_given if s.axis_given is not None else s.axis, s.origin)
        elif s.kind == "prismatic":
            joint = vs.Joint.prismatic(s.axis_given if s.axis_given is not None else s.axis, s.origin)
        elif s.kind == "fixed":
            joint = vs.Joint.fixed()
        else:
            joint = s.kind
        chain.add_segment(
            f"seg{i}",
            joint,
            tip=s.tip,
            mass=s.mass,
            com=s.com,
            inertia=s.inertia,
            rotor_inertia=s.rotor,
            inertia_check=inertia_check,
        )

    model = pin.Model()
    parent = 0
    root_in_parent = np.eye(4)  # current segment root frame in the parent Pinocchio joint frame
    tip_frames, seg_joint, armature = [], [], []
    for i, s in enumerate(segments):
        body = pin.Inertia(s.mass, np.array(s.com), np.eye(3))
        body.inertia = np.array(s.inertia)  # assigned: the constructor rejects identified (non-PSD) inertias
        if s.moving:
            placement = root_in_parent @ homogeneous(None, s.origin)
            if s.kind in ("rot_x", "rot_y", "rot_z"):
                jm = {"x": pin.JointModelRX, "y": pin.JointModelRY, "z": pin.JointModelRZ}[s.kind[-1]]()
            elif s.kind in ("trans_x", "trans_y", "trans_z"):
                jm = {"x": pin.JointModelPX, "y": pin.JointModelPY, "z": pin.JointModelPZ}[s.kind[-1]]()
            elif s.kind == "revolute":
                jm = pin.JointModelRevoluteUnaligned(np.array(s.axis))
            else:
                jm = pin.JointModelPrismaticUnaligned(np.array(s.axis))
            parent = model.addJoint(parent, jm, se3(placement), f"joint{i}")
            armature.append(s.rotor)
            tip_in_parent = homogeneous(None, -s.origin) @ s.tip
        else:
            tip_in_parent = root_in_parent @ s.tip
        if parent != 0:
            model.appendBodyToJoint(parent, body, se3(tip_in_parent))
        fid = model.addFrame(pin.Frame(f"tip{i}", parent, se3(tip_in_parent), pin.FrameType.OP_FRAME), False)
        tip_frames.append(fid)
        seg_joint.append(parent)
        root_in_parent = tip_in_parent
    model.armature = np.array(armature, dtype=float)
    model.gravity = pin.Motion(np.concatenate([G_EARTH, np.zeros(3)]))
    n_joints = sum(s.moving for s in segments)
    assert model.nv == n_joints == chain.n_joints
    assert chain.n_segments == len(segments)
    return RandomChain(segments, chain, model, tip_frames, seg_joint, n_joints, len(segments))


# ----------------------------------------------------------------------------------------------
# States, wrenches, conversions
# ----------------------------------------------------------------------------------------------
def random_state(rng, rc, qd_scale=2.0):
    n = rc.n_joints
    q = np.empty(n)
    j = 0
    for s in rc.segments:
        if s.moving:
            q[j] = rng.uniform(-np.pi, np.pi) if s.revolute else rng.uniform(-0.5, 0.5)
            j += 1
    qd = rng.uniform(-qd_scale, qd_scale, n)
    return q, qd


def random_f_ext(rng, rc, scale=5.0):
    return rng.uniform(-scale, scale, (rc.n_segments, 6))


def fext_to_pinocchio(rc, data, q, f_ext):
    """Our f_ext (base axes, moment about each segment's tip origin, applied TO the segment) ->
    Pinocchio's per-joint external forces (joint-local axes, moment about the joint origin).

    A wrench (f, n) about the point p (world axes) is the wrench (f, n + p x f) about the world
    origin; ``oMi.actInv`` then re-expresses that world-origin wrench in joint i's frame.
    Forces on bodies fixed to the universe have no effect and are dropped.
    """
    pin.forwardKinematics(rc.model, data, q)
    pin.updateFramePlacements(rc.model, data)
    fext = [pin.Force.Zero() for _ in range(rc.model.njoints)]
    for i in range(rc.n_segments):
        jid = rc.seg_joint[i]
        if jid == 0:
            continue
        p = data.oMf[rc.tip_frames[i]].translation
        f, n = f_ext[i, :3], f_ext[i, 3:]
        world = pin.Force(np.array(f), np.array(n + np.cross(p, f)))
        fext[jid] = fext[jid] + data.oMi[jid].actInv(world)
    return fext


def moving_frames(model):
    """The frames an ``f_ext`` dict may name on a Chain or Tree: the links merged into segments
    (first), then the segments; links merged into the base are not moving."""
    segments = list(model.segment_names)
    merged = []
    for link in model.link_names:
        if link in segments:
            continue
        try:
            model.segment_index(link)
        except vs.SolverError:
            continue  # merged into the base
        merged.append(link)
    return merged + segments


def fext_at_frames(model, data, q, wrenches):
    """An ``f_ext`` dict {frame name: (6,) wrench} (base axes, moment about that frame's origin,
    applied TO the body) -> Pinocchio's per-joint external forces, frames by Pinocchio's names."""
    pin.framesForwardKinematics(model, data, q)
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for name, w in wrenches.items():
        fid = model.getFrameId(name, pin.BODY)  # our segments and merged links are URDF links
        joint = model.frames[fid].parentJoint
        at_frame = pin.SE3(np.eye(3), data.oMf[fid].translation)  # base axes, the frame's origin
        fext[joint] += data.oMi[joint].actInv(at_frame.act(pin.Force(np.asarray(w[:3]), np.asarray(w[3:]))))
    return fext


def well_conditioned_task(A, Minv, ratio=1e-4):
    """True if the task rows A (m x n) couple through the inverse inertia Minv with every
    eigenvalue of A Minv A^T above ratio x the largest: a near-singular task would make a
    comparison measure its conditioning, not the solver."""
    ev = np.linalg.eigvalsh(A @ Minv @ A.T)
    return ev.min() >= ratio * ev.max()


def frame_jacobian(rc, data, q, segment=-1):
    """(6, n) LOCAL_WORLD_ALIGNED Jacobian of a segment's tip frame (Pinocchio returns (6,) if n == 1)."""
    J = pin.computeFrameJacobian(rc.model, data, q, rc.tip_frames[segment], pin.LOCAL_WORLD_ALIGNED)
    return np.reshape(J, (6, rc.n_joints))


def fext_generalized(rc, data, q, f_ext):
    """Generalised force of f_ext: sum_i J_i^T w_i with J_i the LOCAL_WORLD_ALIGNED Jacobian of
    segment i's tip frame (its linear part is the velocity of the tip origin, world axes)."""
    tau = np.zeros(rc.n_joints)
    for i in range(rc.n_segments):
        tau += frame_jacobian(rc, data, q, i).T @ f_ext[i]
    return tau


def random_alpha(rng, m):
    """6 x m random constraint directions with unit-norm columns."""
    A = rng.normal(size=(6, m))
    return A / np.linalg.norm(A, axis=0)


def assert_close(actual, expected, rtol=1e-9, what=""):
    """Norm-wise relative comparison: ||a - e|| <= rtol * max(||e||, 1)."""
    actual = np.asarray(actual, float)
    expected = np.asarray(expected, float)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} != {expected.shape}"
    err = np.linalg.norm(actual - expected)
    scale = max(np.linalg.norm(expected), 1.0)
    assert err <= rtol * scale, (
        f"{what}: |error| = {err:.3e} > {rtol:.0e} * {scale:.3e}\nactual={actual}\nexpected={expected}"
    )


def symmetric(M):
    """The symmetric matrix whose upper triangle is M's (Pinocchio's crba and computeMinverse
    fill only the upper triangle)."""
    M = np.array(M, dtype=float)
    return np.triu(M) + np.triu(M, 1).T


def pin_configuration(model, q):
    """Pinocchio configuration of joint positions q: continuous joints (nq = 2) as (cos, sin)."""
    out = []
    for joint, qi in zip(model.joints[1:], q):
        out += [np.cos(qi), np.sin(qi)] if joint.nq == 2 else [qi]
    return np.array(out)
