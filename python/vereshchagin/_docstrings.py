"""Docstrings of the compiled module ``vereshchagin._core``, written once, here.

The bindings (``python/bindings``) attach ``DOCS[key]`` to the class, method or property named by
``key`` when the module is imported; the type stubs (``_core.pyi``) hold the signatures only. A key
is the Python-visible dotted name in ``_core`` (``"Chain.fk"``, ``"Tree.mass_matrix"``); the C++
core of the Python ``Solver`` class and the module's own names carry a ``_core.`` prefix
(``"_core.Solver.solve"``, ``"_core._beta_for"``). Texts that Chain and Tree share are written
once below and entered under both keys.
"""

# The texts keep their own line breaks (one docstring line per source line), which ruff format
# would rearrange around the long first lines: it leaves this file to the end alone.
# fmt: off

DOCS = {}

DOCS["_core"] = r"""C++ core of vereshchagin (Popov-Vereshchagin hybrid dynamics on KDL chains)."""

# ---- Joint (model_chain.cpp) ----

DOCS["Joint"] = r"""A joint type for :meth:`Chain.add_segment`, made by the static methods.

``Joint.revolute(axis, origin)`` and ``Joint.prismatic(axis, origin)`` give a rotation about, or
a translation along, the line through ``origin`` along ``axis`` (root-frame coordinates, m);
``Joint.fixed()`` a rigid connection. The strings ``'rot_x'`` ... ``'trans_z'`` and ``'fixed'``
name the axis-aligned cases.
"""

DOCS["Joint.revolute"] = r"""Rotation about the line through ``origin`` (3,), m, along ``axis`` (3,), normalised; root-frame coordinates."""

DOCS["Joint.prismatic"] = r"""Translation along ``axis`` (3,), normalised, root-frame coordinates (``origin`` only places the axis line)."""

DOCS["Joint.fixed"] = r"""A rigid connection (no joint variable)."""

# ---- Chain (model_bindings.cpp, model_chain.cpp) ----

DOCS["Chain"] = r"""A serial chain of segments (a joint followed by a rigid body), on a KDL::Chain.

Build it segment by segment with :meth:`add_segment`, or from a URDF with :meth:`from_urdf`
(fixed joints merged into their parent links). Joint metadata (limits, friction, damping, rotor
inertia) and the names of merged links are kept. Frames are addressed by segment name, merged link
name, or index (negative from the end); the base only by its link name (:attr:`root_link`).
Chains pickle and copy.
"""

DOCS["Chain.notes"] = r"""list of str: approximations made while building the chain (lumped branches, merged links)."""

DOCS["Chain.add_segment"] = r"""Append a segment (a joint followed by a rigid body).

Parameters
----------
name : str
    Segment (link) name.
joint : str or Joint
    'rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z' (about / along the axes of the
    segment's root frame, i.e. the previous segment's tip frame), 'fixed', or
    Joint.revolute(axis, origin) (rotation about the line through ``origin`` along ``axis``) /
    Joint.prismatic(axis) (translation along ``axis``), in the root frame.
tip : array_like, shape (4, 4), optional
    Pose of the segment's tip frame in its root frame when the joint is at 0 (KDL convention).
mass : float
    kg, >= 0.
com : array_like, shape (3,), optional
    Centre of mass in the tip frame, m.
inertia : array_like, shape (3, 3), optional
    Rotational inertia about the centre of mass, tip-frame axes, kg m^2 (symmetric PSD).
rotor_inertia : float
    Motor rotor inertia reflected to the joint (kg m^2 or kg), added to the joint's inertia.
joint_name : str, optional
    Defaults to ``name + '_joint'``.
inertia_check : {'physical', 'joint_space'}
    'physical' (default): the body must be a rigid body (PSD inertia whose principal moments obey
    the triangle inequality). 'joint_space': any symmetric inertia (identified models); the chain
    then remembers it (:attr:`inertia_check`) and a ``Solver`` of it checks that H(q) is positive
    definite at each solve.
"""

DOCS["Chain.from_urdf"] = r"""Build the serial chain from ``root`` to ``tip`` of a URDF (file path or XML text).

Fixed joints are merged into their parent link (masses and inertias combined); the last
segment's tip frame is the ``tip`` link's frame. Defaults: the URDF's root link and its single
leaf. Raises SolverError for malformed XML, unknown links, tip not below root, floating, planar
or mimic joints on the path, negative mass, or (``inertia_check='physical'``, the default) a
link inertia that no rigid body has (not PSD, or principal moments violating the triangle
inequality); ``inertia_check='joint_space'`` accepts identified models (any symmetric inertia;
the chain remembers the option, and a ``Solver`` of it uses the joint-space check).
"""

DOCS["Chain.n_joints"] = r"""int: number of moving joints n (the length of q, qd, tau_ff)."""

DOCS["Chain.n_segments"] = r"""int: number of segments (moving joints plus fixed-joint segments; rows of f_ext)."""

DOCS["Chain.segment_names"] = r"""list of str: segment names, base to tip (a URDF segment is named after its link)."""

DOCS["Chain.rotor_inertia"] = r"""ndarray (n,): motor rotor inertia reflected to each joint, kg m^2 or kg (settable; added to the joint's articulated inertia)."""

DOCS["Chain.fk"] = r"""Pose of a frame in the base frame.

Parameters
----------
q : array_like, shape (n,)
    Joint positions, rad or m.
segment : str or int, optional
    Segment name or index (negative from the end; default: the last segment's tip), a link
    merged into a segment (its own frame), or the base link's name (identity).

Returns
-------
ndarray, shape (4, 4)
    Homogeneous transform of the frame in the base frame (m).
"""

DOCS["Chain.jacobian"] = r"""Geometric Jacobian of a frame.

Parameters
----------
q : array_like, shape (n,)
segment : str or int, optional
    As in :meth:`fk` (default: the last segment's tip).

Returns
-------
ndarray, shape (6, n)
    Rows ``[linear; angular]``: the velocity of the frame's origin and the angular velocity,
    base-frame axes, per unit joint velocity (zero for the base).
"""

DOCS["Chain.twist"] = r"""Velocity of a frame.

Parameters
----------
q, qd : array_like, shape (n,)
segment : str or int, optional
    As in :meth:`fk` (default: the last segment's tip).

Returns
-------
ndarray, shape (6,)
    ``[v; omega]``: linear velocity of the frame's origin (m/s) and angular velocity (rad/s),
    base-frame axes; ``jacobian(q, segment) @ qd``.
"""

DOCS["Chain.segment_spec"] = r"""One segment described by the arguments of :meth:`add_segment`.

Parameters
----------
segment : str or int
    Segment name or index (negative from the end), or a merged link's name (its segment).

Returns
-------
dict
    ``name`` (str); ``joint_type`` ('rot_x', 'rot_y', 'rot_z', 'trans_x', 'trans_y', 'trans_z',
    'revolute', 'prismatic' or 'fixed'); ``axis`` (ndarray (3,), unit, segment root frame; None
    for a fixed joint); ``origin`` (ndarray (3,), m: a point on a 'revolute' axis, root frame;
    zeros for the other types); ``joint_name`` (str); ``tip`` (ndarray (4, 4), tip pose in the
    root frame at joint position 0); ``mass`` (kg); ``com`` (ndarray (3,), m, tip frame);
    ``inertia`` (ndarray (3, 3), kg m^2, about the centre of mass, tip-frame axes);
    ``rotor_inertia`` (kg m^2 or kg; 0 for a fixed joint).
"""

# ---- Tree (model_bindings.cpp) ----

DOCS["Tree"] = r"""A kinematic tree of segments (a joint followed by a rigid body), on a KDL::Tree.

Load it from a URDF with :meth:`from_urdf`: every link below the root, fixed joints merged into
their parent links exactly as :meth:`Chain.from_urdf` merges them, so every segment has a moving
joint. Segment order: depth-first preorder from the base, at every link the children in the
alphabetical order of their joints' names; ``parent[i] < i`` (-1: a child of the base). Joint
order (q) = segment order. Frames are addressed as for :class:`Chain`: segment name, merged link
name, index (negative from the end); the base only by its link name (:attr:`root_link`).
Trees pickle and copy.
"""

DOCS["Tree.from_urdf"] = r"""Load the tree below ``root`` of a URDF (file path or XML text).

Parameters
----------
source : str or os.PathLike
    URDF XML text (anything containing '<') or the path of a URDF file.
root : str, optional
    The base link (default: the URDF's root link). Its links fixed to it form the base.
inertia_check : {'physical', 'joint_space'}
    As for :meth:`Chain.from_urdf`: 'physical' (default) rejects link inertias that no rigid
    body has; 'joint_space' accepts identified models (any symmetric inertia).
base : {'fixed', 'free', 'planar'}
    How the root link moves (docs/floating-base.md): 'fixed' (default) welds it to the world;
    'free' is a free-flyer (q = (x, y, z, qx, qy, qz, qw, joints), qd = (v, omega in the base
    frame, joints): :attr:`nq` = n + 7, :attr:`nv` = n + 6); 'planar' moves it in the world's
    x-y plane (q = (x, y, cos yaw, sin yaw, joints), qd = (v_x, v_y in the base frame, omega_z,
    joints)). The root link and the links fixed to it are then the base body, with their mass.

Returns
-------
Tree

Raises
------
SolverError
    Malformed XML, an unknown root link, no moving joint below it, a floating or planar joint
    below it (the message names the joint and a ``root=`` below it), invalid limits, friction,
    damping or inertias. Mimic joints are loaded as independent joints (listed in
    :attr:`notes`), as Pinocchio's URDF parser does by default.
"""

DOCS["Tree.n_joints"] = r"""int: number of moving joints n (the length of q, qd)."""

DOCS["Tree.n_segments"] = r"""int: number of segments (one per moving joint)."""

DOCS["Tree.segment_names"] = r"""list of str: segment names in segment order (a segment is named after its tip link)."""

DOCS["Tree.base"] = r"""str: how the base moves: 'fixed', 'free' (free-flyer) or 'planar' (``from_urdf(base=...)``)."""

DOCS["Tree.nq"] = r"""int: length of q: n_joints, plus 7 on a free-flyer base, 4 on a planar base."""

DOCS["Tree.nv"] = r"""int: length of qd, tau_ff, qdd and tau_command: n_joints, plus 6 (free-flyer) or 3 (planar)."""

DOCS["Tree.base_name"] = r"""str: the same as :attr:`root_link`."""

DOCS["Tree.parent"] = r"""ndarray of int64 (n_segments,): index of each segment's parent segment, -1 for the children of the base; parent[i] < i."""

DOCS["Tree.notes"] = r"""list of str: approximations made while building the tree (mimic joints modelled as independent joints)."""

DOCS["Tree.rotor_inertia"] = r"""ndarray (n,): motor rotor inertia reflected to each joint, kg m^2 or kg, q order (settable; added to the joint's articulated inertia; a Solver built afterwards uses it, one built before keeps its own copy)."""

DOCS["Tree.fk"] = r"""Pose of a frame in the base frame.

Parameters
----------
q : array_like, shape (n,)
    Joint positions in q order, rad or m.
segment : str or int
    Segment name or index (negative from the end), a link merged into a segment (its own
    frame), or the base link's name (identity).

Returns
-------
ndarray, shape (4, 4)
    Homogeneous transform of the frame in the base frame (m).
"""

DOCS["Tree.jacobian"] = r"""Geometric Jacobian of a frame.

Parameters
----------
q : array_like, shape (n,)
    Joint positions in q order, rad or m.
segment : str or int
    As in :meth:`fk`.

Returns
-------
ndarray, shape (6, n)
    Rows ``[linear; angular]``: the velocity of the frame's origin and the angular velocity,
    base-frame axes, per unit joint velocity; zero columns for joints off the path from the
    base (all zero for the base).
"""

DOCS["Tree.twist"] = r"""Velocity of a frame.

Parameters
----------
q, qd : array_like, shape (n,)
    Joint positions (rad or m) and velocities (rad/s or m/s) in q order.
segment : str or int
    As in :meth:`fk`.

Returns
-------
ndarray, shape (6,)
    ``[v; omega]``: linear velocity of the frame's origin (m/s) and angular velocity (rad/s),
    base-frame axes; ``jacobian(q, segment) @ qd``.
"""

DOCS["Tree.chain"] = r"""The serial chain from the base to a segment.

Parameters
----------
tip : str or int
    A segment (name, merged link name or index); the chain ends at that segment's tip frame.

Returns
-------
Chain
    The path's segments (bit for bit), their joints (limits, friction, damping) and merged
    links; ``root_link`` is the tree's. Segments off the path, and their masses, are left out
    (a note says so): unlike ``Chain.from_urdf(root, tip)``, which lumps side branches rigidly
    into the path, the arms of a two-arm robot become independent chains.
"""

# ---- Chain and Tree alike (model_bindings.cpp) ----

_SHARED = {}

_SHARED["joint_names"] = r"""list of str: moving joint names in q order."""

_SHARED["joint_types"] = r"""list of str: 'revolute', 'continuous' or 'prismatic' per moving joint."""

_SHARED["lower"] = r"""ndarray (n,): lower position limits, rad or m (-inf: none; URDF continuous joints have none)."""

_SHARED["upper"] = r"""ndarray (n,): upper position limits, rad or m (+inf: none)."""

_SHARED["velocity_limit"] = r"""ndarray (n,): URDF velocity limits, rad/s or m/s (inf: none). Not enforced by the solver."""

_SHARED["effort_limit"] = r"""ndarray (n,): URDF effort limits, N m or N (inf: none). Not enforced by the solver."""

_SHARED["friction"] = r"""ndarray (n,): static (breakaway) friction per joint, N m or N (URDF <dynamics friction>); used by friction=True."""

_SHARED["damping"] = r"""ndarray (n,): viscous damping per joint, N m s/rad or N s/m (URDF <dynamics damping>); not applied by the solver."""

_SHARED["root_link"] = r"""str: name of the base link (the base frame); the base is addressed by this name only."""

_SHARED["inertia_check"] = r"""str: the inertia check the model was built with, 'physical' or 'joint_space' (once any part was accepted only by 'joint_space': from_kdl, or from_urdf / add_segment with that option). A Solver uses it unless given inertia_check."""

_SHARED["link_names"] = r"""list of str: every URDF link of the model (segments, merged links, base links); segment and merged link names address frames in fk, jacobian, twist, constraints= and f_ext dicts; base links only in fk, jacobian and twist."""

_SHARED["segment_index"] = r"""Index of a segment.

Parameters
----------
name : str or int
    A segment name, the name of a link merged into a segment by fixed joints (its segment's
    index), or an index (negative from the end).

Returns
-------
int
    In ``0 .. n_segments - 1``.

Raises
------
SolverError
    Unknown names (the message lists the segments), indices out of range, and the base link
    (it is no segment; ``fk``, ``jacobian`` and ``twist`` accept it by name).
"""

_SHARED["joint_index"] = r"""Index of a moving joint in q.

Parameters
----------
name : str or int
    A joint name or an index (negative from the end).

Returns
-------
int
    In ``0 .. n_joints - 1``.
"""

_SHARED["_joints"] = r"""list of tuple: every moving joint in q order as (name, type, lower, upper, velocity_limit, effort_limit, friction, damping, segment index); vereshchagin/_models.py's joint properties read it."""

_SHARED["segment_masses"] = r"""ndarray (n_segments,): mass of each segment's rigid body (merged links included), kg."""

for _model in ("Chain", "Tree"):
    for _name, _text in _SHARED.items():
        DOCS[f"{_model}.{_name}"] = _text

# ---- Dynamics companions of Chain and Tree (companions.cpp) ----
# One text for both models; the arguments are the words in which the two differ (how the result
# is computed, in which order rows come, what a segment argument defaults to).

_Q_PARAM = r"""q : array_like, shape (n_joints,)
    Joint positions, rad or m.
"""

_Q_QD_PARAM = r"""q, qd : array_like, shape (n_joints,)
    Joint positions (rad or m) and velocities (rad/s or m/s).
"""

_GRAVITY_PARAM = r"""gravity : array_like, shape (3,)
    Physical gravity in the base frame, m/s^2 (default ``[0, 0, -9.81]``).
"""


def _inverse_dynamics(how, q_order="", f_ext_note="", tau_order=""):
    """how: the algorithm; q_order, f_ext_note, tau_order: model-specific remarks."""
    return rf"""Joint torques that realise ``qdd`` ({how}).

``tau = M(q) qdd + C(q, qd) qd + g(q) - sum_i J_i(q)^T f_ext[i]``, rotor inertia included
(``rotor_inertia * qdd`` on each joint's diagonal).

Parameters
----------
q, qd, qdd : array_like, shape (n_joints,)
    Joint positions (rad or m), velocities (rad/s or m/s) and accelerations (rad/s^2 or m/s^2){q_order}.
f_ext : array_like, shape (n_segments, 6), or dict, optional
    Wrench ``[force, moment]`` (N, N m) applied ON each segment BY the environment, base-frame
    axes, moment about that segment's tip origin (the solver's convention{f_ext_note}). ``J_i`` above is the base-axes Jacobian of segment i's tip.
    Dict: ``{{segment: wrench (6,)}}`` keyed by segment name, merged link name or index, the
    moment about the named frame's origin, as :meth:`Solver.solve` reads it.
{_GRAVITY_PARAM}
Returns
-------
ndarray, shape (n_joints,)
    Joint torques / forces, N m or N{tau_order}.
"""


def _mass_matrix(how, note=""):
    return rf"""Joint-space mass matrix ``M(q)`` ({how}).

Parameters
----------
{_Q_PARAM}
Returns
-------
ndarray, shape (n_joints, n_joints)
    Symmetric positive definite, kg m^2 / kg m / kg; ``rotor_inertia`` is included on the diagonal
    (Pinocchio's ``armature``).{note}
"""


def _gravity_torques(model):
    return rf"""Generalised gravity ``g(q)``: the torques that hold the {model} still.

Parameters
----------
{_Q_PARAM}{_GRAVITY_PARAM}
Returns
-------
ndarray, shape (n_joints,)
    ``inverse_dynamics(q, 0, 0, gravity=gravity)``, N m or N.
"""


_CORIOLIS_TORQUES = rf"""Coriolis and centrifugal torques ``C(q, qd) qd``.

Parameters
----------
{_Q_QD_PARAM}
Returns
-------
ndarray, shape (n_joints,)
    ``inverse_dynamics(q, qd, 0, gravity=[0, 0, 0])``, N m or N.
"""


def _jacobian_dot_times_qd(call, how, segment_param):
    """call: the call as in ``a = J qdd + call``; how: a line on how it is computed; segment_param:
    the ``segment`` entry."""
    return rf"""Time derivative of the Jacobian times the joint velocities, ``(d/dt J(q)) qd``.

``J`` is :meth:`jacobian`: the (6, n) base-axes Jacobian ``[linear; angular]`` of the segment's
tip origin (or of a merged link's origin). The result is the acceleration of that point at
``qdd = 0`` without gravity: rows 0-2 the *classical* linear acceleration of the point (not the
spatial one: it includes ``omega x v``), rows 3-5 the angular acceleration, base-frame axes, so
that ``a = J qdd + {call}``.
Pinocchio: ``getFrameJacobianTimeVariation(..., LOCAL_WORLD_ALIGNED) @ v``.
{how}

Parameters
----------
{_Q_QD_PARAM}{segment_param}
Returns
-------
ndarray, shape (6,)
    m/s^2 and rad/s^2.
"""


def _fk_all(order=""):
    return rf"""Pose of every segment's tip frame in the base frame.

Parameters
----------
{_Q_PARAM}
Returns
-------
ndarray, shape (n_segments, 4, 4)
    ``fk_all(q)[i] == fk(q, i)``: homogeneous transforms, metres{order}.
"""


DOCS["Chain.inverse_dynamics"] = _inverse_dynamics("recursive Newton-Euler")
DOCS["Tree.inverse_dynamics"] = _inverse_dynamics(
    "recursive Newton-Euler over the tree",
    q_order=",\n    in q order (:attr:`joint_names`)",
    f_ext_note="; rows in\n    segment order, :attr:`segment_names`",
    tau_order=", in q order",
)
DOCS["Chain.mass_matrix"] = _mass_matrix("composite rigid bodies")
DOCS["Tree.mass_matrix"] = _mass_matrix(
    "composite rigid bodies over the tree",
    note="\n    Rows and columns in q order; the entries of two joints on different branches (neither on\n"
    "    the other's path to the base) are zero.",
)
DOCS["Chain.gravity_torques"] = _gravity_torques("chain")
DOCS["Tree.gravity_torques"] = _gravity_torques("tree")
DOCS["Chain.coriolis_torques"] = DOCS["Tree.coriolis_torques"] = _CORIOLIS_TORQUES
_COM_FRAME = """the world frame on a floating base (``Tree.from_urdf(...,
base='free' | 'planar')``, the base's pose from q), the base frame on a fixed base. Every body's
mass counts (a floating base body's too), rotor inertias do not."""
_COM_STATE = """q : array_like, shape (nq,)
    Positions: ``n_joints`` entries (:attr:`joint_names` order), on a floating base ``nq`` (the
    base's first, docs/floating-base.md).
"""
_COM_QD = """qd : array_like, shape (nv,)
    Velocities: ``n_joints`` entries, on a floating base ``nv`` (the base's LOCAL twist first).
"""
DOCS["Chain.center_of_mass"] = DOCS["Tree.center_of_mass"] = rf"""Centre of mass of the robot, m.

In {_COM_FRAME} Pinocchio: ``pin.centerOfMass``.

Parameters
----------
{_COM_STATE}
Returns
-------
ndarray, shape (3,)
"""
DOCS["Chain.center_of_mass_jacobian"] = DOCS["Tree.center_of_mass_jacobian"] = rf"""Jacobian ``J_c`` of
the centre of mass: its velocity is ``J_c @ qd``.

Axes of {_COM_FRAME} Pinocchio: ``pin.jacobianCenterOfMass``.

Parameters
----------
{_COM_STATE}
Returns
-------
ndarray, shape (3, nv)
    m per rad or per m (per m/s and rad/s of the base's LOCAL twist on a floating base).
"""
DOCS["Chain.center_of_mass_velocity"] = DOCS["Tree.center_of_mass_velocity"] = rf"""Velocity of the
centre of mass, m/s: ``center_of_mass_jacobian(q) @ qd``.

Axes of {_COM_FRAME}

Parameters
----------
{_COM_STATE}{_COM_QD}
Returns
-------
ndarray, shape (3,)
"""
DOCS["Chain.centroidal_momentum"] = DOCS["Tree.centroidal_momentum"] = rf"""Centroidal momentum
``[p; L_G]``: the linear momentum ``p`` (kg m/s, the total mass times the centre of mass's
velocity) and the angular momentum ``L_G`` about the centre of mass (kg m^2/s).

Axes of {_COM_FRAME} Pinocchio: ``pin.computeCentroidalMomentum`` (``data.hg``). Conserved by a
free-floating robot without gravity and external forces.

Parameters
----------
{_COM_STATE}{_COM_QD}
Returns
-------
ndarray, shape (6,)
"""
DOCS["Chain.integrate"] = DOCS["Tree.integrate"] = rf"""The configuration ``q (+) v`` reached from q
by moving with the constant velocity v for unit time (a time step: ``integrate(q, dt * qd)``).

The joints ``q + v``; a floating base (docs/floating-base.md) moves by the exponential of its
LOCAL twist: on SE(3) for a free-flyer (the quaternion stays unit), on SE(2) for a planar base.
Pinocchio: ``pin.integrate`` with the same root joint. The position update of
:meth:`Solver.step` and the :class:`Simulator`.

Parameters
----------
{_COM_STATE}v : array_like, shape (nv,)
    The velocity times the duration: rad or m, on a floating base the LOCAL twist's ``nv`` first.

Returns
-------
ndarray, shape (nq,)
"""
_FLOATING_DYNAMICS = """
Notes
-----
On a floating base (``Tree.from_urdf(..., base='free' | 'planar')``, docs/floating-base.md) q has
``tree.nq`` entries, qd, qdd and the result ``tree.nv`` (the mass matrix ``(nv, nv)``), the base's
first: its rows are the wrench on the base body in base axes (Pinocchio's LOCAL, as ``pin.rnea`` and
``pin.crba`` with a ``JointModelFreeFlyer`` or ``JointModelPlanar``). Gravity and the f_ext rows
are in world axes there, as in :meth:`Solver.solve`.
"""
for _name in ("inverse_dynamics", "mass_matrix", "gravity_torques", "coriolis_torques"):
    DOCS["Tree." + _name] += _FLOATING_DYNAMICS
DOCS["Chain.jacobian_dot_times_qd"] = _jacobian_dot_times_qd(
    "jacobian_dot_times_qd(q, qd)",
    "Computed from the joint axes and velocities of the frame's path to the base.",
    "segment : str or int, optional\n"
    "    As in :meth:`fk`: a segment name or index (negative from the end), or a merged link's name;\n"
    "    default the last segment. A base link gives zeros.\n",
)
DOCS["Tree.jacobian_dot_times_qd"] = _jacobian_dot_times_qd(
    "jacobian_dot_times_qd(q, qd, segment)",
    "Only the joints on the frame's path to the base contribute.",
    "segment : str or int\n"
    "    As in :meth:`fk`: a segment name or index (negative from the end), a merged link's name, or\n"
    "    the base link's name (zeros). Required: a tree has no last segment.\n",
)
DOCS["Chain.fk_all"] = _fk_all()
DOCS["Tree.fk_all"] = _fk_all(", in segment order")

# ---- Solver (solver_bindings.cpp): the C++ core of vereshchagin.Solver (solver.py) ----

DOCS["_core.Solver.solve"] = r"""solve($self, /, q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None, friction=None, constraints=None, f_ext_pass_through=None, tau_ff_pass_through=None, out=None, a_desired=None, contacts=None, time_step=None, contact_velocity_tolerance=None, contact_max_pivots=None)
--

Constrained hybrid dynamics of one state: the motion that minimises Gauss' acceleration energy
subject to the acceleration constraints (Popov-Vereshchagin), with optional static friction.

Parameters
----------
q, qd : array_like, shape (n,)
    Joint positions (rad or m) and velocities (rad/s or m/s), in ``chain.joint_names`` order.
    On a floating base (``Tree.from_urdf(..., base='free' | 'planar')``) q has ``tree.nq``
    entries and qd, tau_ff and the results ``tree.nv``, the base's first (docs/floating-base.md).
alpha : array_like, shape (6, m) or (6,), optional
    m <= 6 unit constraint wrenches on the **last** segment, one per column, rows
    ``[fx, fy, fz, mx, my, mz]``: base-frame axes, moment about the last segment's tip origin.
    A 1-D ``(6,)`` array is one column.
beta : array_like, shape (m,), or float when m = 1
    Acceleration set-points ``alpha.T @ a_N``, ``a_N`` the last segment's spatial acceleration
    ``[linear; angular]`` (base axes, tip origin) **including** ``-gravity``: holding the tip
    still along z against gravity needs ``beta = 9.81``, not 0 (the helpers in
    :mod:`vereshchagin.task` form beta for you). Required with ``alpha``, unless ``a_desired``
    is given instead.
f_ext : array_like, shape (n_segments, 6), or dict, optional
    External wrenches applied **on** the segments by the environment (N, N m). Array: row i is
    ``[fx, fy, fz, mx, my, mz]`` on segment i, base-frame axes, moment about segment i's tip
    origin (note: one row per segment, not KDL's one column per segment). Dict:
    ``{segment: wrench (6,)}`` keyed by segment name, link name or index; the moment is about
    the named frame's origin (a link merged into a segment by fixed joints, such as a tool
    frame, is moved to its segment at each solve). Gravity never goes here.
tau_ff : array_like, shape (n,), optional
    Feed-forward joint torques (N m or N), e.g. springs or known friction.
friction : None, bool or Friction, optional
    Static joint friction: ``True`` uses the chain's URDF friction and limits; a
    :class:`vereshchagin.Friction` sets them explicitly. Resting joints then get the exact
    max-min friction torques of Vukcevic (2018), and the least motor command among optima.
constraints : dict, optional
    ``{segment: (alpha_i (6, m_i), beta_i (m_i,))}``: acceleration constraints on any segments
    (Shakhimardanov's extension), keyed by segment or link name or index (negative from the
    end), with the end-segment conventions at that frame: base axes, moment about that frame's
    origin, ``beta_i`` including ``-gravity``. At most 6 columns per segment. Combines with
    ``alpha``/``beta``.
f_ext_pass_through, tau_ff_pass_through : array_like, shape (m_total,), optional
    Driver pass-through per constraint column, in the order of ``nu`` (Shakhimardanov 2015,
    eq. 3.42), each in [0, 1]: 0 (default) = the constraint compensates that driver (``f_ext``,
    respectively ``tau_ff``) along that column, as KDL does; 1 = the driver's own acceleration
    along that column passes through (``alpha^T a = beta + a_driver``: a commanded press on a
    table, a support); in between, linear. Friction is always compensated.
out : SolveResult, optional
    A result of an earlier solve with the same kind of arguments (same m, friction or not):
    its arrays are overwritten in place and it is returned (no allocation; for control loops).
a_desired : array_like, shape (6,), optional
    Instead of ``beta``: the **classical** acceleration ``[linear (m/s^2); angular (rad/s^2)]``
    of the last segment's tip origin, base axes, that ``alpha`` constrains. The solve forms
    ``beta = alpha.T @ [a_lin - omega x v - gravity; a_ang]`` itself, from the tip twist its own
    sweep computes at ``(q, qd)`` (what :func:`vereshchagin.task.beta_for` does, without the
    extra kinematics): ``a_desired = 0`` holds the tip still against gravity.
contacts : list of Contact, optional
    Point contacts (:class:`vereshchagin.Contact`): supports, whose normal force (>= 0) and
    friction the solve finds exactly with the motion (a point may lift off), and force
    set-points, which stay on their surface and push with a given normal force. The surfaces
    supply the contact forces, the motors only ``tau_command``; where the forces are not unique,
    the least motor effort, then the least contact force (docs: "Contacts"). With ``friction``,
    joint friction, joint limits and the contacts are solved as one problem.
time_step : float, optional
    dt > 0 (s): solve over a time step instead of at the instant. The conditions of joint
    friction, joint limits and contacts hold for the velocities at the end of the step,
    ``qd + dt qdd`` (``qdd`` is then the step's mean acceleration): a joint or contact point
    friction can hold ends the step at rest, a sliding one gets the full friction against its
    end velocity, a support ends the step not approaching its surface. :meth:`Solver.step`
    integrates. Default (None or 0): the instant.
contact_velocity_tolerance : float, optional
    Speed (m/s) at or below which a contact point is at rest along its normal, resp. not sliding
    (default 1e-6). A support approaching its surface faster is refused at the instant (an impact
    needs an impulse: solve over a ``time_step`` instead).
contact_max_pivots : int, optional
    The contact stage's real-time bound: Lemke pivots per run of its complementarity problem
    (None or -1, the default: 50 + 20 per unknown, never reached in the measurements; n > 0: n).
    A solve that reaches it returns the safe fallback of docs "Friction", "Real-time bound"
    ("Contact fallback": every touching support held along its normal, no friction at the
    contacts or the resting joints, no point moving into its surface) and warns with a
    ``RuntimeWarning`` of the message ("contacts: the real-time bound of n pivots ... was hit"),
    as the friction stage's bound (``Friction(max_iterations=...)``) does. 0, values below -1
    and non-integers raise :class:`SolverError`.

Returns
-------
SolveResult
    ``qdd``, ``tau_command``, ``nu``, ``link_acc``, ``constraint_rank``,
    ``smallest_singular_value``; with friction also ``friction_torque``, ``limit_torque``,
    ``status``, ``gauss_value``, ``iterations``; with ``constraints`` also ``segment_nu``; with
    ``contacts`` ``contact_force``, ``contact_status``, ``contact_outcome``.

Raises
------
SolverError
    Wrong shapes or dtypes, NaN or Inf, unknown segment names, more than 6 columns on one
    segment, invalid friction or contacts, or a solve that fails (the message says why: e.g.
    contacts whose conditions no forces meet).

Notes
-----
The GIL is released during the solve. One solver serialises concurrent calls; use one solver
per thread (or :meth:`solve_batch` with ``threads=``) for parallel work.
"""

DOCS["_core.Solver.solve_batch"] = r"""solve_batch(q, qd, alpha=None, beta=None, f_ext=None, tau_ff=None, friction=None, constraints=None, f_ext_pass_through=None, tau_ff_pass_through=None, threads=1, a_desired=None, contacts=None, time_step=None, contact_velocity_tolerance=None, contact_max_pivots=None)

Solve B states; see :meth:`vereshchagin.Solver.solve_batch` for the documented wrapper.
"""

DOCS["_core.Solver._whole_body"] = r"""_whole_body(q, qd, f_ext, tau_ff, actuated, supports, task) -> (tau, forces (3, k), qdd, effort, residual): whole-body least effort on the solver's kept C++ WholeBodySolver (internal; see vereshchagin.whole_body.least_effort, which resolves the task's keys into (label, segment, point, alpha, beta) tuples)."""
DOCS["_core.Solver.response_columns"] = r"""Affine response of the last solve to unit feed-forward torques (see the wrapper in vereshchagin.Solver)."""

DOCS["_core.Solver.gravity"] = r"""Physical gravity in the base frame, shape (3,), m/s^2 (settable; see :class:`Solver`)."""

DOCS["_core.Solver"] = r"""C++ core of :class:`vereshchagin.Solver` (use that class)."""

DOCS["_core.Solver.n_joints"] = r"""Number of moving joints n."""

DOCS["_core.Solver.n_segments"] = r"""Number of segments (moving and fixed-joint segments of the chain or tree)."""

DOCS["_core.Solver.model"] = r"""A copy of the solver's Chain or Tree."""


DOCS["_core.Solver.inertia_check"] = r"""str: 'physical' or 'joint_space' (see Solver)."""

DOCS["_core.Solver._time_cpp"] = r"""_time_cpp(reps, q, qd, ...) -> float: seconds per C++ solve of these arguments (benchmarks)."""

DOCS["_core.Solver.step"] = r"""step($self, /, q, qd, time_step, *, alpha=None, beta=None, f_ext=None, tau_ff=None, friction=None, constraints=None, f_ext_pass_through=None, tau_ff_pass_through=None, out=None, a_desired=None, contacts=None, contact_velocity_tolerance=None, contact_max_pivots=None)
--

One step of semi-implicit Euler over ``time_step`` with friction and contacts solved exactly.

The C++ ``step()`` (``data.hpp``), as :class:`Simulator` steps: :meth:`solve` with
``time_step``: the conditions of joint friction, joint limits and contacts hold for the
velocities at the end of the step, ``qd_next = qd + dt qdd``; then ``q_next = q + dt qd_next``.
A joint that friction holds (status 1, sticking) ends the step exactly at rest, so a held arm
keeps ``q`` bitwise (docs: "Friction in discrete time").

Parameters
----------
q, qd : array_like, shape (n,)
    Joint positions (rad or m) and velocities (rad/s or m/s) at the start of the step (on a
    floating base ``tree.nq`` and ``tree.nv`` entries).
time_step : float
    dt > 0, s.
alpha, beta, f_ext, tau_ff, friction, constraints, f_ext_pass_through, tau_ff_pass_through, a_desired, contacts, contact_velocity_tolerance, contact_max_pivots : optional
    Keywords only, as in :meth:`solve` (the task, the drivers, friction and contacts over the step).
out : SolveResult, optional
    A result of an earlier step or solve of the same kind, overwritten in place and returned
    as ``result`` (as in :meth:`solve`).

Returns
-------
q_next, qd_next : ndarray, shape (n,)
    The state at the end of the step (new arrays).
result : SolveResult
    The solve over the step: ``qdd`` is the step's mean acceleration, ``friction_torque``,
    ``limit_torque``, ``contact_force`` the step's (impulses over dt).

Raises
------
SolverError
    A ``time_step`` that is not a finite number > 0, a state after the step that overflows, or
    what :meth:`solve` raises.
TypeError
    A missing ``q``, ``qd`` or ``time_step``, more than three positional arguments, or an
    unknown keyword.

Notes
-----
A direct C++ entry (no Python wrapper); the GIL is released during the step.
"""

DOCS["_core.Solver._step_symplectic"] = r"""_step_symplectic(q, qd, ..., time_step=dt, out=p) -> (q_next, qd_next, p_next, SolveResult): the C++ stepSymplectic() from the momentum p (Simulator)."""

# ---- SolveResult (result_type.cpp) ----

DOCS["SolveResult"] = r"""Result of :meth:`Solver.solve`.

All arrays are float64 (``status``: int32). Frames: base-frame axes; moments and spatial
accelerations about each segment's tip origin. Results pickle and deep-copy.
"""

DOCS["SolveResult.qdd"] = r"""ndarray, shape (n,): joint accelerations, rad/s^2 or m/s^2."""

DOCS["SolveResult.tau_command"] = r"""ndarray, shape (n,): torques the motors add to ``tau_ff`` to realise ``qdd``, N m or N.

``-sum_i J_i^T alpha_i nu_i`` over the constrained segments; applied with ``tau_ff`` (and, with
friction, the friction torques acting) to the unconstrained arm under the same gravity and
``f_ext`` it reproduces ``qdd``. With friction: the least such command among the optima.
"""

DOCS["SolveResult.nu"] = r"""ndarray, shape (m,): constraint force magnitudes (N or N m per unit of alpha).

The wrench the constraints apply on their segment is ``-alpha @ nu``. Order: the end-segment
``alpha`` columns first, then each ``constraints`` entry's columns in dict order.
"""

DOCS["SolveResult.link_acc"] = r"""ndarray, shape (n_segments + 1, 6): spatial accelerations ``[linear, angular]``.

Row 0 is the base (its acceleration is ``-gravity``); row ``k + 1`` is segment k's tip frame:
base-frame axes, tip origin, including ``-gravity`` (m/s^2, rad/s^2).
"""

DOCS["SolveResult.constraint_rank"] = r"""int: rank of the coupling matrix ``K = A H^-1 A^T`` (``A = alpha^T J``) under the singularity policy."""

DOCS["SolveResult.smallest_singular_value"] = r"""float: smallest eigenvalue of ``K`` (0 when m = 0); small values flag a near-singular task."""

DOCS["SolveResult.friction_torque"] = r"""ndarray, shape (n,) or None: physical friction torques acting on the joints (N m or N).

Opposes motion on moving joints (kinetic friction); on resting joints the max-min value with
``|torque| <= static``. None for solves without ``friction``.
"""

DOCS["SolveResult.limit_torque"] = r"""ndarray, shape (n,) or None: reactions of joint position limits on resting joints at a limit (N m or N)."""

DOCS["SolveResult.status"] = r"""ndarray of int32, shape (n,) or None: 0 moving, 1 sticking, 2 slipping +, 3 slipping - (joints at rest)."""

DOCS["SolveResult.gauss_value"] = r"""float or None: Gauss' function at the optimum, ``Z0(qdd) + sum f_j |qdd_j|`` over resting joints."""

DOCS["SolveResult.iterations"] = r"""int or None: iterations of the friction max-min (bounded by ``Friction.max_iterations``;
see docs/friction.md, "Real-time bound")."""

DOCS["SolveResult.contact_force"] = r"""ndarray, shape (k, 3): the force each contact's surface applies to the robot at its point, base axes, N.

One row per entry of ``contacts`` (k = 0 without contacts); a set-point's normal force included.
Replaying ``tau_ff + tau_command`` and these forces (``J_c^T f_c``) through any forward dynamics
gives ``qdd``.
"""

DOCS["SolveResult.contact_status"] = r"""ndarray of int32, shape (k,): :class:`ContactStatus` codes, 0 separating, 1 sticking, 2 sliding."""

DOCS["SolveResult.contact_outcome"] = r"""ContactOutcome: NONE (no contacts), UNIQUE (no touching support has friction: unique accelerations) or CONSISTENT (one consistent answer by the documented rule)."""

DOCS["SolveResult.segment_nu"] = r"""dict or None: ``{key: nu_i}`` for each ``constraints`` key, views into ``nu``."""

# ---- helpers of the Python layer (companions.cpp, result_type.cpp) ----

DOCS["_core._beta_for"] = r"""task.beta_for's arithmetic (vereshchagin/task.hpp); None for inputs task.py checks itself."""


DOCS["_core._result_from_parts"] = r"""A SolveResult from the entries of a state vereshchagin/_results.py checked."""
