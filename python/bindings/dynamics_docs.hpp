// numpy-style docstrings of the dynamics companions, one text for Chain (dynamics_bindings.cpp)
// and Tree (tree_dynamics.cpp): each function takes the words in which the two differ (how the
// result is computed, in which order rows come, what a segment argument defaults to).
#pragma once

#include <string>

namespace vsbind {
namespace docs {

inline const std::string kQParam = R"doc(q : array_like, shape (n_joints,)
    Joint positions, rad or m.
)doc";

inline const std::string kQQdParam = R"doc(q, qd : array_like, shape (n_joints,)
    Joint positions (rad or m) and velocities (rad/s or m/s).
)doc";

inline const std::string kGravityParam = R"doc(gravity : array_like, shape (3,)
    Physical gravity in the base frame, m/s^2 (default ``[0, 0, -9.81]``).
)doc";

// how: the algorithm; q_order, f_ext_note, tau_order: model-specific remarks.
inline std::string inverseDynamicsDoc(const std::string& how, const std::string& q_order, const std::string& f_ext_note,
                                      const std::string& tau_order) {
  return "Joint torques that realise ``qdd`` (" + how + R"doc().

``tau = M(q) qdd + C(q, qd) qd + g(q) - sum_i J_i(q)^T f_ext[i]``, rotor inertia included
(``rotor_inertia * qdd`` on each joint's diagonal).

Parameters
----------
q, qd, qdd : array_like, shape (n_joints,)
    Joint positions (rad or m), velocities (rad/s or m/s) and accelerations (rad/s^2 or m/s^2))doc" +
         q_order + R"doc(.
f_ext : array_like, shape (n_segments, 6), or dict, optional
    Wrench ``[force, moment]`` (N, N m) applied ON each segment BY the environment, base-frame
    axes, moment about that segment's tip origin (the solver's convention)doc" +
         f_ext_note + R"doc(). ``J_i`` above is the base-axes Jacobian of segment i's tip.
    Dict: ``{segment: wrench (6,)}`` keyed by segment name, merged link name or index, the
    moment about the named frame's origin, as :meth:`Solver.solve` reads it.
)doc" + kGravityParam +
         R"doc(
Returns
-------
ndarray, shape (n_joints,)
    Joint torques / forces, N m or N)doc" +
         tau_order + ".\n";
}

inline std::string massMatrixDoc(const std::string& how, const std::string& note) {
  return "Joint-space mass matrix ``M(q)`` (" + how + ").\n\nParameters\n----------\n" + kQParam + R"doc(
Returns
-------
ndarray, shape (n_joints, n_joints)
    Symmetric positive definite, kg m^2 / kg m / kg; ``rotor_inertia`` is included on the diagonal
    (Pinocchio's ``armature``).)doc" +
         note + "\n";
}

inline std::string gravityTorquesDoc(const std::string& model, const std::string& how) {
  return "Generalised gravity ``g(q)``: the torques that hold the " + model + " still" + how +
         ".\n\nParameters\n----------\n" + kQParam + kGravityParam + R"doc(
Returns
-------
ndarray, shape (n_joints,)
    ``inverse_dynamics(q, 0, 0, gravity=gravity)``, N m or N.
)doc";
}

inline std::string coriolisTorquesDoc(const std::string& how) {
  return "Coriolis and centrifugal torques ``C(q, qd) qd``" + how + ".\n\nParameters\n----------\n" + kQQdParam +
         R"doc(
Returns
-------
ndarray, shape (n_joints,)
    ``inverse_dynamics(q, qd, 0, gravity=[0, 0, 0])``, N m or N.
)doc";
}

// call: the call as in `a = J qdd + call`; how: a line on how it is computed; segment_param:
// the `segment` entry.
inline std::string jacobianDotDoc(const std::string& call, const std::string& how, const std::string& segment_param) {
  return R"doc(Time derivative of the Jacobian times the joint velocities, ``(d/dt J(q)) qd``.

``J`` is :meth:`jacobian`: the (6, n) base-axes Jacobian ``[linear; angular]`` of the segment's
tip origin (or of a merged link's origin). The result is the acceleration of that point at
``qdd = 0`` without gravity: rows 0-2 the *classical* linear acceleration of the point (not the
spatial one: it includes ``omega x v``), rows 3-5 the angular acceleration, base-frame axes, so
that ``a = J qdd + )doc" +
         call + R"doc(``.
Pinocchio: ``getFrameJacobianTimeVariation(..., LOCAL_WORLD_ALIGNED) @ v``.
)doc" + how +
         "\n\nParameters\n----------\n" + kQQdParam + segment_param + R"doc(
Returns
-------
ndarray, shape (6,)
    m/s^2 and rad/s^2.
)doc";
}

inline std::string fkAllDoc(const std::string& order) {
  return "Pose of every segment's tip frame in the base frame.\n\nParameters\n----------\n" + kQParam + R"doc(
Returns
-------
ndarray, shape (n_segments, 4, 4)
    ``fk_all(q)[i] == fk(q, i)``: homogeneous transforms, metres)doc" +
         order + ".\n";
}

}  // namespace docs
}  // namespace vsbind
