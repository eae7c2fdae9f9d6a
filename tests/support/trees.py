"""Random kinematic trees written as URDF text, for the tree tests (model and solver).

:func:`random_tree_urdf` draws a tree from a seed: links attached one by one to a random earlier
link (so the tree branches), joints revolute, continuous, prismatic or fixed with random axes,
origins and limits, links with random masses and inertias (some without any). The URDF text is
what both vereshchagin and Pinocchio load; the :class:`RandomTree` record keeps the drawn values
so tests compare against them without parsing the text with the code under test. Joint names are
drawn so that their alphabetical order differs from their order in the document.

:func:`pin_model` loads URDF text or a file in Pinocchio without a free-flyer (the base fixed) and
:func:`pin_q` / :func:`pin_v_index` map our q (one value per joint, in ``tree.joint_names`` order)
to Pinocchio's configuration and velocity indices by joint name.

:class:`TreeCase` is one URDF tree loaded by both libraries, with the joint maps between them and
named sets of frames to constrain together; ``robot(name)`` gives the (cached) case of
``ROBOTS``: Baxter, Talos (``talos_reduced`` below ``base_link``) and three random trees.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

import vereshchagin as vs
from support.chains import G_EARTH as G
from vereshchagin.robots import example_robot_urdf

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")


@dataclass
class UrdfJoint:
    """One drawn joint: its URDF attributes (None: element absent)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray | None = None
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    friction: float | None = None
    damping: float | None = None


@dataclass
class RandomTree:
    """A drawn tree: URDF text plus the values it was written from."""

    urdf: str
    root: str
    links: list[str]
    masses: dict[str, float]
    joints: list[UrdfJoint] = field(default_factory=list)

    @property
    def moving(self) -> list[UrdfJoint]:
        """The non-fixed joints, in document order."""
        return [j for j in self.joints if j.type != "fixed"]

    @property
    def base_links(self) -> set[str]:
        """The root and every link attached to it through fixed joints only (the fixed base)."""
        base = {self.root}
        for j in self.joints:  # document order: parents come first
            if j.type == "fixed" and j.parent in base:
                base.add(j.child)
        return base

    @property
    def total_mass(self) -> float:
        """Mass of every link that moves (not in :attr:`base_links`), kg."""
        return sum(m for name, m in self.masses.items() if name not in self.base_links)

    @property
    def leaves(self) -> list[str]:
        """Links nothing hangs from, in document order."""
        parents = {j.parent for j in self.joints}
        return [link for link in self.links if link not in parents]

    def path(self, link: str) -> list[str]:
        """The links from ``link`` up to the root: ``link`` first, the root excluded."""
        parent = {j.child: j.parent for j in self.joints}
        out = []
        while link in parent:
            out.append(link)
            link = parent[link]
        return out

    def below(self, link: str) -> list[UrdfJoint]:
        """The joints of the sub-tree below ``link``, in document order."""
        inside, out = {link}, []
        for j in self.joints:
            if j.parent in inside:
                inside.add(j.child)
                out.append(j)
        return out


def _fmt(v) -> str:
    return " ".join(repr(float(x)) for x in np.atleast_1d(v))


def _inertial(rng: np.random.Generator) -> tuple[float, str]:
    """A random rigid body: mass, com, principal moments obeying the triangle inequality, axes."""
    mass = float(rng.uniform(0.2, 3.0))
    a, b = (float(x) for x in rng.uniform(0.005, 0.05, 2))
    c = float(rng.uniform(abs(a - b), a + b))
    xml = (
        f"<inertial><origin xyz='{_fmt(rng.uniform(-0.1, 0.1, 3))}' rpy='{_fmt(rng.uniform(-np.pi, np.pi, 3))}'/>"
        f"<mass value='{mass!r}'/><inertia ixx='{a!r}' ixy='0' ixz='0' iyy='{b!r}' iyz='0' izz='{c!r}'/>"
        "</inertial>"
    )
    return mass, xml


def _axis(rng: np.random.Generator) -> np.ndarray:
    if rng.random() < 0.3:
        return np.eye(3)[rng.integers(3)] * rng.choice([-1.0, 1.0])
    return rng.normal(size=3)  # not normalised: the loaders normalise


def _joint(rng: np.random.Generator, name: str, type_: str, parent: str, child: str) -> UrdfJoint:
    j = UrdfJoint(name, type_, parent, child, rng.uniform(-0.3, 0.3, 3), rng.uniform(-np.pi, np.pi, 3))
    if type_ == "fixed":
        return j
    j.axis = _axis(rng)
    if type_ != "continuous":
        j.lower = float(rng.uniform(-2.0, 0.0))
        j.upper = float(rng.uniform(0.0, 2.0))
    j.effort = float(rng.uniform(1.0, 100.0))
    j.velocity = float(rng.uniform(0.5, 5.0))
    if rng.random() < 0.7:
        j.friction = float(rng.uniform(0.0, 2.0))
        j.damping = float(rng.uniform(0.0, 0.5))
    return j


def _joint_xml(j: UrdfJoint) -> str:
    out = (
        f"<joint name='{j.name}' type='{j.type}'><parent link='{j.parent}'/><child link='{j.child}'/>"
        f"<origin xyz='{_fmt(j.xyz)}' rpy='{_fmt(j.rpy)}'/>"
    )
    if j.axis is not None:
        out += f"<axis xyz='{_fmt(j.axis)}'/>"
    if j.effort is not None:
        bounds = "" if j.lower is None else f" lower='{j.lower!r}' upper='{j.upper!r}'"
        out += f"<limit{bounds} effort='{j.effort!r}' velocity='{j.velocity!r}'/>"
    if j.friction is not None:
        out += f"<dynamics damping='{j.damping!r}' friction='{j.friction!r}'/>"
    return out + "</joint>"


def random_tree_urdf(seed: int, n_links: int = 14, p_fixed: float = 0.25) -> RandomTree:
    """Draw a random tree of ``n_links`` links below a root link ``base``.

    Parameters
    ----------
    seed : int
        Seed of the ``numpy.random.Generator``: the same seed gives the same text.
    n_links : int
        Links besides the root; each hangs from a uniformly drawn earlier link.
    p_fixed : float
        Probability of a fixed joint; the rest split evenly between revolute, continuous and
        prismatic. At least one joint is made moving.

    Returns
    -------
    RandomTree
    """
    rng = np.random.default_rng(seed)
    links = ["base"]
    masses = {"base": 0.0}
    bodies = ["<link name='base'/>"]
    joints: list[UrdfJoint] = []
    for k in range(1, n_links + 1):
        name = f"link{k}"
        parent = links[int(rng.integers(len(links)))]
        moving = ["revolute", "continuous", "prismatic"]
        type_ = "fixed" if rng.random() < p_fixed else moving[int(rng.integers(3))]
        if k == 1 and type_ == "fixed":
            type_ = "revolute"
        jname = f"j{int(rng.integers(100, 1000))}_{k}"  # alphabetical order != document order
        joints.append(_joint(rng, jname, type_, parent, name))
        if rng.random() < 0.85:
            mass, inertial = _inertial(rng)
        else:
            mass, inertial = 0.0, ""
        masses[name] = mass
        bodies.append(f"<link name='{name}'>{inertial}</link>")
        links.append(name)
    urdf = f"<robot name='random_tree_{seed}'>" + "".join(bodies) + "".join(_joint_xml(j) for j in joints) + "</robot>"
    return RandomTree(urdf=urdf, root="base", links=links, masses=masses, joints=joints)


def every_joint_moves_mass(drawn: RandomTree) -> bool:
    """Every moving joint of the drawn tree carries some mass (read from the drawn record), so the
    tree's motion is unique (no zero articulated inertia)."""
    for j in drawn.moving:
        below = {j.child} | {k.child for k in drawn.below(j.child)}
        if not any(drawn.masses[link] > 0.0 for link in below):
            return False
    return True


def random_solvable_tree(seed: int, n_links: int = 14, p_fixed: float = 0.25) -> RandomTree:
    """:func:`random_tree_urdf`, redrawn (seed + 1000, + 2000, ...) until every joint moves mass."""
    drawn = random_tree_urdf(seed, n_links, p_fixed)
    while not every_joint_moves_mass(drawn):
        seed += 1000
        drawn = random_tree_urdf(seed, n_links, p_fixed)
    return drawn


def pin_model(source: str | Path) -> pin.Model:
    """Pinocchio model of URDF text or a URDF file, the root link fixed (no free-flyer)."""
    text = str(source)
    if "<" in text:
        return pin.buildModelFromXML(text)
    return pin.buildModelFromUrdf(text)


def pin_q(model: pin.Model, joint_names: list[str], q: np.ndarray) -> np.ndarray:
    """Pinocchio configuration of our q (continuous joints as cos, sin), mapped by joint name."""
    out = pin.neutral(model)
    for name, value in zip(joint_names, q):
        joint = model.joints[model.getJointId(name)]
        if joint.nq == 2:
            out[joint.idx_q : joint.idx_q + 2] = (np.cos(value), np.sin(value))
        else:
            out[joint.idx_q] = value
    return out


def pin_q_free(model: pin.Model, joint_names: list[str], q: np.ndarray) -> np.ndarray:
    """Pinocchio configuration of our free-flyer q (base position, quaternion x y z w, joints)."""
    out = pin_q(model, joint_names, q[7:])
    out[:7] = q[:7]
    return out


def pin_v_scatter(model: pin.Model, v_index: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Pinocchio's velocity vector from ours, entry k of v into column v_index[k]."""
    out = np.zeros(model.nv)
    out[v_index] = v
    return out


def pin_v_index(model: pin.Model, joint_names: list[str]) -> np.ndarray:
    """For each of our joints, its column in Pinocchio's velocity vector."""
    return np.array([model.joints[model.getJointId(name)].idx_v for name in joint_names])


# ------------------------------------------------------------------------------------------------
# Robots of the tree tests
# ------------------------------------------------------------------------------------------------
class TreeCase:
    """Our tree and Pinocchio's model of one URDF, with the joint maps between them."""

    def __init__(self, name, source, tasks=()):
        self.name = name
        self.tree = vs.Tree.from_urdf(source)
        self.model = pin_model(source)
        self.model.gravity = pin.Motion(np.r_[G, 0.0, 0.0, 0.0])
        self.tasks = tasks  # named sets of frames to constrain together
        n = self.tree.n_joints
        assert self.model.nv == n, f"{name}: {self.model.nv} Pinocchio joints, {n} ours"
        self.idx_v = pin_v_index(self.model, list(self.tree.joint_names))

    @property
    def n(self):
        return self.tree.n_joints

    def pin_q(self, q):
        return pin_q(self.model, list(self.tree.joint_names), q)

    def pin_v(self, x):
        """Ours (n,) -> Pinocchio's velocity-space order."""
        out = np.zeros(self.model.nv)
        out[self.idx_v] = x
        return out

    def ours(self, x):
        """Pinocchio's velocity-space vector (nv,) or matrix (rows, nv) -> ours."""
        x = np.asarray(x)
        return x[..., self.idx_v]

    def random_state(self, rng, qd_scale=1.5):
        lo = np.maximum(np.asarray(self.tree.lower, float), -np.pi)
        hi = np.minimum(np.asarray(self.tree.upper, float), np.pi)
        return rng.uniform(lo, hi), rng.uniform(-qd_scale, qd_scale, self.n)

    def solver(self):
        return vs.Solver(self.tree, gravity=G)


def _baxter():
    return TreeCase(
        "baxter",
        example_robot_urdf("baxter"),
        tasks={
            "left hand": ("left_gripper",),
            "both hands": ("left_gripper", "right_gripper"),
            "hand and other elbow": ("left_gripper", "right_lower_elbow"),
            "hand and own elbow": ("right_gripper", "right_upper_forearm"),
            "hands and head": ("left_gripper", "right_gripper", "head"),
        },
    )


def _talos():
    return TreeCase(
        "talos",
        example_robot_urdf("talos_reduced"),
        tasks={
            "left hand": ("gripper_left_base_link",),
            "both hands": ("gripper_left_base_link", "gripper_right_base_link"),
            "hand and other elbow": ("gripper_left_base_link", "arm_right_4_link"),
            "feet and a hand": ("left_sole_link", "right_sole_link", "gripper_right_base_link"),
        },
    )


def _random(seed):
    """A random tree (random_solvable_tree) with tasks on leaves and inner links of different branches."""
    drawn = random_solvable_tree(seed, n_links=16, p_fixed=0.2)
    tree = vs.Tree.from_urdf(drawn.urdf)
    leaves = [link for link in drawn.leaves if link not in drawn.base_links]
    # an inner link (in document order) that is not on the first leaf's path
    parents, path = {j.parent for j in drawn.joints}, set(drawn.path(leaves[0]))
    inner = [x for x in drawn.links if x in parents and x not in path and x not in drawn.base_links] or [leaves[-1]]
    assert len(leaves) >= 2 and tree.n_joints >= 8, "seed gives too small a tree"
    return TreeCase(
        f"random_{seed}",
        drawn.urdf,
        tasks={
            "one leaf": (leaves[0],),
            "two leaves": (leaves[0], leaves[-1]),
            "leaf and inner link of another branch": (leaves[0], inner[0]),
        },
    )


ROBOTS = {"baxter": _baxter, "talos": _talos, **{f"random_{s}": (lambda s=s: _random(s)) for s in (3, 8, 11)}}
_CACHE = {}


def robot(name):
    if name not in _CACHE:
        _CACHE[name] = ROBOTS[name]()
    return _CACHE[name]
