// solveBatch (batch.hpp): the rows of a BatchInput in contiguous chunks over threads, one Data
// per thread, the lowest failing row reported; secondsPerSolve, the benchmark of one row.
#include <algorithm>
#include <chrono>
#include <limits>
#include <system_error>
#include <thread>

#include "vereshchagin/batch.hpp"

namespace vereshchagin {

namespace {

// Rows begin .. end - 1 on one workspace; the first failure (row and message) goes to `failure`.
void solveChunk(const Model& model, const BatchInput& input, const BatchOutput& out, BatchWorkspace& w,
                std::ptrdiff_t begin, std::ptrdiff_t end, BatchFailure& failure) {
  const int columns = input.columns();
  for (std::ptrdiff_t b = begin; b < end; ++b) {
    input.fillRow(b, w.input);
    const Status s = solve(model, w.data, w.input);
    const char* message = s ? nullptr : s.message();
    if (!message && !out.write(b, w.data, columns, w.input.friction != nullptr))
      message = "the results overflow: gauss_value is beyond the double range";
    if (message) {
      failure = BatchFailure{b, "batch row " + std::to_string(b) + ": " + message};
      return;
    }
  }
}

}  // namespace

BatchFailure solveBatch(const Model& model, const BatchInput& input, const BatchOutput& out,
                        const std::vector<BatchWorkspace*>& workspaces) {
  const std::ptrdiff_t B = input.rows,
                       threads = std::max<std::ptrdiff_t>(1, static_cast<std::ptrdiff_t>(workspaces.size()));
  const std::ptrdiff_t chunk = (B + threads - 1) / threads;
  std::vector<BatchFailure> failures(static_cast<std::size_t>(threads));
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads));
  auto run = [&](std::ptrdiff_t t) {
    solveChunk(model, input, out, *workspaces[t], std::min(B, t * chunk), std::min(B, (t + 1) * chunk), failures[t]);
  };
  try {
    for (std::ptrdiff_t t = 1; t < threads; ++t) pool.emplace_back(run, t);
  } catch (const std::system_error& e) {
    for (auto& th : pool) th.join();
    return BatchFailure{-1, "solve_batch could not start thread " + std::to_string(pool.size() + 1) + " of " +
                                std::to_string(threads) + " (" + e.what() + "): pass fewer threads"};
  }
  run(0);
  for (auto& th : pool) th.join();
  for (const BatchFailure& f : failures)  // in thread order: the first failure is the lowest row
    if (!f.ok()) return f;
  // Workspace 0 solved the last row unless the rows were spread over threads: then once more.
  if (threads > 1 && B > 0) {
    input.fillRow(B - 1, workspaces[0]->input);
    if (const Status s = solve(model, workspaces[0]->data, workspaces[0]->input); !s)
      return BatchFailure{B - 1, "batch row " + std::to_string(B - 1) + ": " + s.message()};
  }
  return BatchFailure{};
}

double secondsPerSolve(const Model& model, const BatchInput& input, BatchWorkspace& w, long reps) {
  const Eigen::Index n = model.nrOfJoints(), ns = model.nrOfSegments();
  const int columns = input.columns();
  const bool friction = input.frictionOf(0) != nullptr;
  Eigen::VectorXd qdd(n), tau(n), nu(std::max(columns, 1)), fr(n), lim(n);
  Eigen::Matrix<double, 6, Eigen::Dynamic> acc(6, ns + 1);
  std::vector<int> status(n);
  int rank, iterations;
  double smin, gauss;
  const BatchOutput out{qdd.data(), tau.data(), nu.data(),     acc.data(), &smin, &rank, friction ? fr.data() : nullptr,
                        lim.data(), &gauss,     status.data(), &iterations};
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < reps; ++k) {
    input.fillRow(0, w.input);
    if (!solve(model, w.data, w.input)) return std::numeric_limits<double>::quiet_NaN();
    out.write(0, w.data, columns, friction);
  }
  const std::chrono::duration<double> dt = std::chrono::steady_clock::now() - t0;
  return dt.count() / static_cast<double>(reps);
}

}  // namespace vereshchagin
