// The recursive sweeps of tree_sweeps.hpp over a PyTree's parent array.
#include "tree_sweeps.hpp"

namespace vsbind {

namespace {

int parentOf(const PyTree& tree, int i) {
  return tree.robot.parent[static_cast<std::size_t>(i)];
}

double jointValue(const KDL::JntArray& x, int q_index) {
  return q_index < 0 ? 0.0 : x(static_cast<unsigned int>(q_index));
}

// Spatial inertia of segment i's body, base axes, about the base origin.
KDL::RigidBodyInertia bodyInertia(const PyTree& tree, const TreePlacement& at, int i) {
  return at.tip[static_cast<std::size_t>(i)] * tree.segment(i).getInertia();
}

}  // namespace

TreePlacement placeTree(const PyTree& tree, const KDL::JntArray& q) {
  const int ns = tree.segmentCount();
  TreePlacement at;
  at.tip.resize(static_cast<std::size_t>(ns));
  at.axis.assign(static_cast<std::size_t>(ns), KDL::Twist::Zero());
  at.q_index.assign(static_cast<std::size_t>(ns), -1);
  for (int i = 0; i < ns; ++i) {
    const int p = parentOf(tree, i);
    const KDL::Frame root = p < 0 ? KDL::Frame::Identity() : at.tip[static_cast<std::size_t>(p)];
    const KDL::Segment& seg = tree.segment(i);
    const KDL::Joint& joint = seg.getJoint();
    if (joint.getType() != KDL::Joint::None) at.q_index[static_cast<std::size_t>(i)] = static_cast<int>(tree.qIndex(i));
    at.tip[static_cast<std::size_t>(i)] = root * seg.pose(jointValue(q, at.q_index[static_cast<std::size_t>(i)]));
    if (joint.getType() == KDL::Joint::None) continue;
    const KDL::Vector u = root.M * joint.JointAxis();
    // Revolute about the line through point c along u: the body point at the base origin moves
    // with u x (0 - c) = c x u. Prismatic along u: every point moves with u.
    at.axis[static_cast<std::size_t>(i)] = isPrismatic(joint.getType())
                                               ? KDL::Twist(u, KDL::Vector::Zero())
                                               : KDL::Twist((root * joint.JointOrigin()) * u, u);
  }
  return at;
}

void treeMotion(const PyTree& tree, const TreePlacement& at, const KDL::JntArray& qd, const KDL::JntArray& qdd,
                const KDL::Twist& base_acc, std::vector<KDL::Twist>& v, std::vector<KDL::Twist>& a) {
  const int ns = tree.segmentCount();
  v.assign(static_cast<std::size_t>(ns), KDL::Twist::Zero());
  a.assign(static_cast<std::size_t>(ns), KDL::Twist::Zero());
  for (int i = 0; i < ns; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const int p = parentOf(tree, i);
    const KDL::Twist& v_parent = p < 0 ? KDL::Twist::Zero() : v[static_cast<std::size_t>(p)];
    const KDL::Twist& a_parent = p < 0 ? base_acc : a[static_cast<std::size_t>(p)];
    const KDL::Twist joint_rate = at.axis[k] * jointValue(qd, at.q_index[k]);
    v[k] = v_parent + joint_rate;
    // In a fixed frame dS/dt = v_i x S (the axis moves with the body): a = a_p + S qdd + v x S qd.
    a[k] = a_parent + at.axis[k] * jointValue(qdd, at.q_index[k]) + v[k] * joint_rate;
  }
}

KDL::JntArray treeInverseDynamics(const PyTree& tree, const TreePlacement& at, const KDL::JntArray& qd,
                                  const KDL::JntArray& qdd, const std::vector<KDL::Wrench>& f_ext,
                                  const KDL::Vector& gravity) {
  const int ns = tree.segmentCount();
  std::vector<KDL::Twist> v, a;
  treeMotion(tree, at, qd, qdd, KDL::Twist(-gravity, KDL::Vector::Zero()), v, a);
  std::vector<KDL::Wrench> f(static_cast<std::size_t>(ns));
  for (int i = 0; i < ns; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const KDL::RigidBodyInertia I = bodyInertia(tree, at, i);
    f[k] = I * a[k] + v[k] * (I * v[k]) - f_ext[k];  // d/dt(I v) = I a + v x* I v
  }
  KDL::JntArray tau(tree.robot.tree.getNrOfJoints());
  for (int i = ns - 1; i >= 0; --i) {  // children (larger indices) are done before their parent
    const auto k = static_cast<std::size_t>(i);
    const int j = at.q_index[k];
    if (j >= 0)
      tau(static_cast<unsigned int>(j)) =
          dot(at.axis[k], f[k]) + tree.segment(i).getJoint().getInertia() * qdd(static_cast<unsigned int>(j));
    const int p = parentOf(tree, i);
    if (p >= 0) f[static_cast<std::size_t>(p)] += f[k];
  }
  return tau;
}

Eigen::MatrixXd treeMassMatrix(const PyTree& tree, const TreePlacement& at) {
  const int ns = tree.segmentCount();
  const auto n = static_cast<Eigen::Index>(tree.robot.tree.getNrOfJoints());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  std::vector<KDL::RigidBodyInertia> composite(static_cast<std::size_t>(ns));
  for (int i = 0; i < ns; ++i) composite[static_cast<std::size_t>(i)] = bodyInertia(tree, at, i);
  for (int i = ns - 1; i >= 0; --i) {  // composite[i] is complete: its children were added already
    const auto k = static_cast<std::size_t>(i);
    const int p = parentOf(tree, i);
    if (p >= 0) composite[static_cast<std::size_t>(p)] = composite[static_cast<std::size_t>(p)] + composite[k];
    const int j = at.q_index[k];
    if (j < 0) continue;
    const KDL::Wrench F = composite[k] * at.axis[k];  // the wrench that accelerates it at unit qdd_j
    H(j, j) = dot(at.axis[k], F) + tree.segment(i).getJoint().getInertia();
    for (int s = p; s >= 0; s = parentOf(tree, s)) {
      const int r = at.q_index[static_cast<std::size_t>(s)];
      if (r < 0) continue;
      H(r, j) = H(j, r) = dot(at.axis[static_cast<std::size_t>(s)], F);
    }
  }
  return H;
}

}  // namespace vsbind
