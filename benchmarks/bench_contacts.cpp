// Contacts (SolveInput::contacts) on the Kinova Gen3: a 3-D task on the tool (its position held)
// with 4 point contacts on the forearm and the wrist, against the plain solves of the same state
// (the task alone, and the tool's full 6-D hold). Cases: 4 frictionless supports; 4 supports with
// friction that stick; 4 supports with friction of which some slide (the full complementarity
// problem); 4 force set-points with friction. States are drawn at random near a pose where the
// forearm lies on a table, and kept only when they give the case's statuses (so each row times
// what its name says). Prints a markdown report (stdout, or the file given as argv[1]).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench_common.hpp"
#include "vereshchagin/data.hpp"
#include "vereshchagin/kinematics.hpp"

using namespace vereshchagin;

namespace {

struct State {
  Eigen::VectorXd q, qd;
};

enum class Case { Plain3, Plain6, Frictionless, Sticking, Sliding, SetPoints };

// The contacts: two points under the forearm (segment 3), two under the wrist (segment 5), the
// table's normal +z. The set-points press with 5 N each.
void addContacts(SolveInput& in, Case c) {
  const double mu = c == Case::Frictionless ? 0.0 : 0.6;
  const int seg[4] = {2, 3, 4, 5};
  const double z[4] = {-0.05, -0.15, -0.02, -0.08};
  for (int k = 0; k < 4; ++k) {
    PointContact p;
    p.segment = seg[k];
    p.point = Vector3(0.03 * (k % 2 ? 1 : -1), 0.02 * (k < 2 ? 1 : -1), z[k]);
    p.normal = Vector3::UnitZ();
    p.mu = mu;
    if (c == Case::SetPoints) p.force = 5.0;
    in.contacts.push_back(p);
  }
}

void setTask(SolveInput& in, const Model& model, bool six) {
  ConstraintBlock b;
  b.segment = static_cast<int>(model.nrOfSegments()) - 1;
  b.columns = six ? 6 : 3;
  for (int c = 0; c < b.columns; ++c) b.alfa(c, c) = 1.0;
  b.beta.head(3) << 0.0, 0.0, 9.81;  // the tool held (gravity's spatial acceleration)
  in.constraints.push_back(b);
}

// True when the solve of `in` succeeds with statuses as `c` wants.
bool wanted(const Model& model, Data& data, const SolveInput& in, Case c) {
  if (!solve(model, data, in)) return false;
  if (c == Case::Plain3 || c == Case::Plain6) return true;
  int sticking = 0, sliding = 0, separating = 0;
  for (ContactStatus s : data.contactStatus()) {
    sticking += s == ContactStatus::Sticking;
    sliding += s == ContactStatus::Sliding;
    separating += s == ContactStatus::Separating;
  }
  switch (c) {
    case Case::Frictionless:
      return separating == 0;
    case Case::Sticking:
      return sticking == 4;
    case Case::Sliding:
      return sliding >= 1 && separating <= 1;
    default:
      return separating == 0;
  }
}

std::vector<State> states(const Model& model, Case c, bench::Rng& rng) {
  Data data(model);
  std::vector<State> out;
  const double pose[7] = {0.0, 0.9, 0.0, 1.9, 0.0, 0.4, 1.57};
  for (int tries = 0; tries < 200000 && static_cast<int>(out.size()) < bench::kStates; ++tries) {
    State s{Eigen::VectorXd(7), Eigen::VectorXd::Zero(7)};
    for (int j = 0; j < 7; ++j) s.q(j) = pose[j] + rng.uniform(-0.3, 0.3);
    if (c == Case::Sliding)
      for (int j = 0; j < 7; ++j) s.qd(j) = rng.uniform(-0.5, 0.5);
    SolveInput in(model);
    in.q = s.q;
    in.q_dot = s.qd;
    setTask(in, model, c == Case::Plain6);
    if (c != Case::Plain3 && c != Case::Plain6) addContacts(in, c);
    if (c == Case::Sliding) {
      // Project qd so that every contact point stays on its surface (zero normal velocity).
      KinematicsData kin(model);
      Eigen::MatrixXd jn(4, 7), jac(6, 7);
      (void)forwardKinematics(model, kin, JointPositions(s.q), JointVelocities(s.qd));
      for (int k = 0; k < 4; ++k) {
        const PointContact& p = in.contacts[k];
        (void)frameJacobian(model, kin,
                            FrameRef{p.segment, KDL::Frame(KDL::Vector(p.point(0), p.point(1), p.point(2)))}, jac);
        jn.row(k) = jac.row(2);
      }
      s.qd -= jn.transpose() * (jn * jn.transpose()).ldlt().solve(jn * s.qd);
      in.q_dot = s.qd;
    }
    if (wanted(model, data, in, c)) out.push_back(s);
  }
  return out;
}

const char* caseName(Case c) {
  switch (c) {
    case Case::Plain3:
      return "plain solve, 3-D task (m = 3)";
    case Case::Plain6:
      return "plain solve, 6-D hold (m = 6)";
    case Case::Frictionless:
      return "4 frictionless supports + 3-D task";
    case Case::Sticking:
      return "4 supports with friction, all sticking + 3-D task";
    case Case::Sliding:
      return "4 supports with friction, some sliding + 3-D task";
    default:
      return "4 force set-points with friction + 3-D task";
  }
}

}  // namespace

int main(int argc, char** argv) {
  const KDL::Chain chain = bench::makeGen3Chain();
  const Model model(chain);
  bench::Rng rng(20261127);
  const Case cases[] = {Case::Plain3, Case::Plain6, Case::Frictionless, Case::Sticking, Case::Sliding, Case::SetPoints};
  std::vector<std::vector<State>> all;
  for (Case c : cases) all.push_back(states(model, c, rng));
  std::vector<bench::Bench> group;
  std::vector<std::unique_ptr<Data>> datas;
  std::vector<std::unique_ptr<SolveInput>> inputs;
  const char* only = std::getenv("BENCH_CONTACTS_CASE");  // profiling: a bit mask of the cases to time
  for (std::size_t i = 0; i < std::size(cases); ++i) {
    const Case c = cases[i];
    if (only != nullptr && !(std::atoi(only) >> i & 1)) all[i].clear();  // a bit mask of the cases
    datas.push_back(std::make_unique<Data>(model));
    inputs.push_back(std::make_unique<SolveInput>(model));
    SolveInput& in = *inputs.back();
    setTask(in, model, c == Case::Plain6);
    if (c != Case::Plain3 && c != Case::Plain6) addContacts(in, c);
    Data& data = *datas.back();
    bench::addBench(group, caseName(c), bench::overStates(all[i], [&model, &data, &in](const State& s) {
                      in.q = s.q;
                      in.q_dot = s.qd;
                      (void)solve(model, data, in);
                      return data.qdd()(0);
                    }));
  }
  bench::runGroup(group, "contacts");
  std::ostringstream md;
  md << "### Contacts (C++, `bench_contacts`)\n\n"
     << "The Kinova Gen3 with a 3-D task on the tool (its position held) and 4 point contacts (normal +z) under "
        "segments 2 to 5, against plain solves of the same states. States are drawn near a pose with the "
        "forearm over a table and kept when they give the case's statuses (all supports pushing; all sticking; "
        "some sliding, with joint velocities that keep every point on its surface). The task leaves joint 7 "
        "free and the contacts make the held columns redundant, so the least-effort programme runs in all "
        "cases but the sliding one. Target (contacts issue): at most 2x a plain m = 6 solve.\n\n";
  md << "| case | states | us per solve | vs plain m = 6 |\n|---|---:|---:|---:|\n";
  for (std::size_t i = 0; i < group.size(); ++i)
    md << "| " << group[i].name << " | " << all[i].size() << " | " << bench::fmt("%.2f", bench::median(group[i].us))
       << " | " << bench::fmt("%.2f", bench::pairedRatio(group[i], group[1])) << "x |\n";
  if (argc > 1) {
    std::ofstream(argv[1]) << md.str();
  } else {
    std::cout << md.str();
  }
  std::fprintf(stderr, "sink %g\n", bench::g_sink);
  return 0;
}
