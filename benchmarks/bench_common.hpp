// Shared parts of the C++ benchmarks (bench_solver.cpp, bench_friction.cpp): deterministic random
// numbers, the Kinova Gen3 7-DoF chain and the seeded random chains, the interleaved-batch timer
// and the report helpers. Header-only (inline), one translation unit per benchmark executable.
#pragma once

// Build facts passed by benchmarks/CMakeLists.txt (defaults when built otherwise).
#ifndef BENCH_CXX_FLAGS
#define BENCH_CXX_FLAGS "(unknown)"
#endif
#ifndef BENCH_BUILD_TYPE
#define BENCH_BUILD_TYPE "(unknown)"
#endif
#ifndef BENCH_CXX_COMPILER
#define BENCH_CXX_COMPILER "(unknown)"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>

namespace bench {

constexpr int kStates = 64;              // pre-generated random states per chain
constexpr int kBatches = 61;             // timed batches per measurement (median reported)
constexpr double kBatchSeconds = 0.008;  // target duration of one batch
constexpr double kWarmupSeconds = 0.02;
constexpr double kGravity = 9.81;
constexpr double kPi = 3.14159265358979323846;

inline double g_sink = 0.0;  // printed at the end: keeps every timed result observable

// ---------------------------------------------------------------------------------------------
// Deterministic random numbers: std::mt19937_64's output sequence is fixed by the standard; the
// conversion to doubles is done here (std::uniform_real_distribution is implementation-defined).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int index(int count) { return static_cast<int>(uniform() * count); }

 private:
  std::mt19937_64 engine_;
};

// ---------------------------------------------------------------------------------------------
// Chains

struct Gen3Link {
  const char* joint;
  double xyz[3];                        // URDF joint origin translation (parent link frame)
  double rpy[3];                        // URDF joint origin roll, pitch, yaw
  double mass;                          // child link
  double com[3];                        // child link COM in the child link frame
  double ixx, iyy, izz, ixy, ixz, iyz;  // about the COM, axes parallel to the child link frame
};

// Kinova Gen3 7-DoF; see the file comment for the source. All joint axes are +z of the joint frame.
inline const Gen3Link kGen3[7] = {
    {"joint_1",
     {0.0, 0.0, 0.15643},
     {3.1416, 2.7629e-18, -4.9305e-36},
     1.3773,
     {-2.3e-05, -0.010364, -0.07336},
     0.00457,
     0.004831,
     0.001409,
     1e-06,
     2e-06,
     0.000448},
    {"joint_2",
     {0.0, 0.005375, -0.12838},
     {1.5708, 2.1343e-17, -1.1102e-16},
     1.1636,
     {-4.4e-05, -0.09958, -0.013278},
     0.011088,
     0.001072,
     0.011255,
     5e-06,
     0.0,
     -0.000691},
    {"joint_3",
     {0.0, -0.21038, -0.006375},
     {-1.5708, 1.2326e-32, -2.9122e-16},
     1.1636,
     {-4.4e-05, -0.006641, -0.117892},
     0.010932,
     0.011127,
     0.001043,
     0.0,
     -7e-06,
     0.000606},
    {"joint_4",
     {0.0, 0.006375, -0.21038},
     {1.5708, -6.6954e-17, -1.6653e-16},
     0.9302,
     {-1.8e-05, -0.075478, -0.015006},
     0.008147,
     0.000631,
     0.008316,
     -1e-06,
     0.0,
     -0.0005},
    {"joint_5",
     {0.0, -0.20843, -0.006375},
     {-1.5708, 2.2204e-16, -6.373e-17},
     0.6781,
     {1e-06, -0.009432, -0.063883},
     0.001596,
     0.001607,
     0.000399,
     0.0,
     0.0,
     0.000256},
    {"joint_6",
     {0.0, 0.00017505, -0.10593},
     {1.5708, 9.2076e-28, -8.2157e-15},
     0.6781,
     {1e-06, -0.045483, -0.00965},
     0.001641,
     0.00041,
     0.001641,
     0.0,
     0.0,
     -0.000278},
    {"joint_7",
     {0.0, -0.10593, -0.00017505},
     {-1.5708, -5.5511e-17, 9.6396e-17},
     0.364,
     {-9.3e-05, 0.000132, -0.022905},
     0.000214,
     0.000223,
     0.00024,
     0.0,
     1e-06,
     -2e-06},
};

// URDF joint -> KDL segment: the joint rotates about the joint frame's z axis through the joint
// origin (both given in the parent link frame), the segment's tip frame is the child link frame at
// q = 0, and the link inertia is expressed in that tip frame.
inline KDL::Chain makeGen3Chain() {
  KDL::Chain chain;
  for (const Gen3Link& l : kGen3) {
    const KDL::Frame origin(KDL::Rotation::RPY(l.rpy[0], l.rpy[1], l.rpy[2]),
                            KDL::Vector(l.xyz[0], l.xyz[1], l.xyz[2]));
    const KDL::Joint joint(l.joint, origin.p, origin.M * KDL::Vector(0.0, 0.0, 1.0), KDL::Joint::RotAxis);
    const KDL::RigidBodyInertia inertia(l.mass, KDL::Vector(l.com[0], l.com[1], l.com[2]),
                                        KDL::RotationalInertia(l.ixx, l.iyy, l.izz, l.ixy, l.ixz, l.iyz));
    chain.addSegment(KDL::Segment(l.joint, joint, origin, inertia));
  }
  return chain;
}

inline KDL::Chain makeRandomChain(int n, std::uint64_t seed) {
  Rng rng(seed);
  KDL::Chain chain;
  const KDL::Joint::JointType axes[3] = {KDL::Joint::RotX, KDL::Joint::RotY, KDL::Joint::RotZ};
  for (int i = 0; i < n; ++i) {
    const KDL::Joint joint(axes[rng.index(3)]);
    const KDL::Rotation tip_rot =
        KDL::Rotation::RPY(rng.uniform(-kPi, kPi), rng.uniform(-kPi / 2, kPi / 2), rng.uniform(-kPi, kPi));
    const KDL::Vector tip_pos(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rng.uniform(0.08, 0.2));
    const double mass = rng.uniform(0.5, 2.0);
    const KDL::Vector com = tip_pos * rng.uniform(0.3, 0.7) +
                            KDL::Vector(rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01));
    // Principal moments m (b + c), m (a + c), m (a + b) from second moments a, b, c > 0 satisfy the
    // triangle inequalities; rotate them by a random rotation.
    const double a = rng.uniform(2e-4, 5e-3), b = rng.uniform(2e-4, 5e-3), c = rng.uniform(2e-4, 5e-3);
    const Eigen::Vector3d principal(mass * (b + c), mass * (a + c), mass * (a + b));
    const KDL::Rotation r =
        KDL::Rotation::RPY(rng.uniform(-kPi, kPi), rng.uniform(-kPi / 2, kPi / 2), rng.uniform(-kPi, kPi));
    Eigen::Matrix3d rm;
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) rm(row, col) = r(row, col);
    const Eigen::Matrix3d ic = rm * principal.asDiagonal() * rm.transpose();
    const KDL::RigidBodyInertia inertia(
        mass, com, KDL::RotationalInertia(ic(0, 0), ic(1, 1), ic(2, 2), ic(0, 1), ic(0, 2), ic(1, 2)));
    chain.addSegment(KDL::Segment("link_" + std::to_string(i), joint, KDL::Frame(tip_rot, tip_pos), inertia));
  }
  return chain;
}

inline KDL::JntArray toJnt(const Eigen::VectorXd& v) {
  KDL::JntArray out(static_cast<unsigned int>(v.size()));
  out.data = v;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Timing

using Clock = std::chrono::steady_clock;

struct Bench {
  std::string name;
  std::function<void(int reps)> run;  // reps x kStates calls; the loop is inside the callable
  int reps = 1;
  std::vector<double> us;  // per-call microseconds, one entry per batch
};

inline void addBench(std::vector<Bench>& group, const std::string& name, std::function<void(int)> run) {
  Bench b;
  b.name = name;
  b.run = std::move(run);
  group.push_back(std::move(b));
}

// A benchmark body: `reps` passes over `items`, summing what `call` returns into g_sink so that
// no timed result can be optimised away.
template <class Items, class Call>
std::function<void(int)> overStates(const Items& items, Call call) {
  return [&items, call](int reps) mutable {
    double acc = 0.0;
    for (int r = 0; r < reps; ++r)
      for (const auto& item : items) acc += call(item);
    g_sink += acc;
  };
}

inline double secondsOf(const std::function<void(int)>& run, int reps) {
  const auto t0 = Clock::now();
  run(reps);
  const auto t1 = Clock::now();
  return std::chrono::duration<double>(t1 - t0).count();
}

inline double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

inline double quantile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double pos = p * (v.size() - 1);
  const size_t lo = static_cast<size_t>(pos);
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

inline double g_worst_spread = 0.0;  // largest (p75 - p25) / median seen, for the report
inline std::string g_worst_spread_name;

// Warm up and calibrate every bench, then run kBatches interleaved rounds.
inline void runGroup(std::vector<Bench>& group, const std::string& label) {
  for (Bench& b : group) {
    double elapsed = 0.0;
    int calls = 0;
    while (elapsed < kWarmupSeconds) {
      elapsed += secondsOf(b.run, 1);
      calls += kStates;
    }
    const double per_call = elapsed / calls;
    b.reps = std::max(1, static_cast<int>(std::lround(kBatchSeconds / (per_call * kStates))));
    b.us.clear();
  }
  for (int batch = 0; batch < kBatches; ++batch)
    for (Bench& b : group) b.us.push_back(secondsOf(b.run, b.reps) * 1e6 / (double(b.reps) * kStates));
  for (const Bench& b : group) {
    const double spread = (quantile(b.us, 0.75) - quantile(b.us, 0.25)) / median(b.us);
    if (spread > g_worst_spread) {
      g_worst_spread = spread;
      g_worst_spread_name = label + ", " + b.name;
    }
  }
}

// Median over batches of the per-batch ratio a/b (the batches of a and b are interleaved).
inline double pairedRatio(const Bench& a, const Bench& b) {
  std::vector<double> r;
  for (size_t i = 0; i < a.us.size() && i < b.us.size(); ++i) r.push_back(a.us[i] / b.us[i]);
  return median(r);
}

// ---------------------------------------------------------------------------------------------
// Report helpers

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

inline std::string cpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) {
        std::string v = line.substr(colon + 1);
        v.erase(0, v.find_first_not_of(" \t"));
        return v;
      }
    }
  }
  return "(unknown)";
}

inline std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  double l1 = 0, l5 = 0, l15 = 0;
  if (in >> l1 >> l5 >> l15) return fmt("%.2f", l1) + " " + fmt("%.2f", l5) + " " + fmt("%.2f", l15);
  return "(unknown)";
}

inline std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buf;
}

struct ChainCase {
  std::string label;
  std::unique_ptr<KDL::Chain> chain;  // KDL's solvers keep a reference: must outlive them
  int n = 0;
};

}  // namespace bench
