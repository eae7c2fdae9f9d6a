// Solver.solve_batch: B rows, each argument either shared by all rows or with a leading batch
// axis; rows run on one engine per thread with the GIL released, through the same Engine::run as
// Solver.solve (so every row equals the single solve bit for bit).
#include <algorithm>
#include <system_error>
#include <thread>

#include "py_solver.hpp"

namespace vsbind {

namespace {

// An argument with an optional leading batch axis: row b starts at data + b * stride (stride 0:
// shared by all rows).
struct Batched {
  F64View view;
  const double* data = nullptr;
  py::ssize_t stride = 0;
  bool batched = false;
  const double* row(py::ssize_t b) const { return data ? data + b * stride : nullptr; }
};

// Decides and checks the batch size B across arguments; messages name argument and axis.
struct BatchSize {
  py::ssize_t B = -1;
  std::string first;
  void add(py::ssize_t rows, const std::string& name, const std::string& shape) {
    if (B < 0) {
      B = rows;
      first = name + " " + shape;
    } else if (rows != B) {
      raise(name + " has a batch axis (axis 0) of " + std::to_string(rows) + " rows (shape " + shape + "), but " +
            first + " has " + std::to_string(B));
    }
  }
};

// `single_ndim` is the number of dimensions of one row (e.g. 1 for q (n,)), `row_shape` its shape.
Batched fromView(F64View v, const std::string& name, int single_ndim, const std::vector<py::ssize_t>& row_shape,
                 BatchSize& bs) {
  std::string expect;
  for (std::size_t k = 0; k < row_shape.size(); ++k) expect += (k ? ", " : "") + std::to_string(row_shape[k]);
  if (row_shape.size() == 1) expect += ",";
  const bool batched = v.ndim == single_ndim + 1;
  bool fits = v.ndim == single_ndim || batched;
  for (int k = 0; fits && k < single_ndim; ++k) fits = v.shape[k + (batched ? 1 : 0)] == row_shape[k];
  if (!fits)
    raise(name + " must have shape (" + expect + ") (shared by all rows) or (B, " + expect + ") (one per row), got " +
          v.shapeString());
  const py::ssize_t n = v.size(), per_row = batched && v.shape[0] > 0 ? n / v.shape[0] : n;
  for (py::ssize_t k = 0; k < n; ++k)
    if (!std::isfinite(v.data[k]))
      raise((batched ? "batch row " + std::to_string(k / per_row) + ": " : std::string()) + name +
            " contains NaN or Inf (flat index " + std::to_string(batched ? k % per_row : k) + ")");
  Batched a;
  a.data = v.data;
  if (batched) {
    a.batched = true;
    a.stride = 1;
    for (int k = 0; k < single_ndim; ++k) a.stride *= row_shape[k];
    bs.add(v.shape[0], name, v.shapeString());
  }
  a.view = std::move(v);
  return a;
}

Batched batchedArg(PyObject* obj, const std::string& name, int single_ndim, const std::vector<py::ssize_t>& row_shape,
                   BatchSize& bs) {
  return fromView(asF64(obj, name.c_str()), name, single_ndim, row_shape, bs);
}

// beta (m,) or (B, m); for m = 1 also a scalar or (B,).
Batched betaArg(PyObject* obj, const std::string& name, py::ssize_t m, BatchSize& bs) {
  F64View v = asF64(obj, name.c_str());
  if (m == 1 && v.ndim == 0) {
    v.ndim = 1;
    v.shape[0] = 1;
  } else if (m == 1 && v.ndim == 1 && v.shape[0] != 1) {
    v.ndim = 2;
    v.shape[1] = 1;
  }
  return fromView(std::move(v), name, 1, {m}, bs);
}

// alpha (6, m), (6,) (one column) or (B, 6, m); m <= 6.
Batched alphaArg(PyObject* obj, const std::string& name, BatchSize& bs, py::ssize_t& m) {
  F64View v = asF64(obj, name.c_str());
  if (v.ndim == 1 && v.shape[0] == 6) {
    v.ndim = 2;
    v.shape[1] = 1;
  }
  m = v.ndim >= 2 ? v.shape[v.ndim - 1] : 0;
  if (m > 6) raise(name + " has " + std::to_string(m) + " columns; at most 6 constraints per segment");
  return fromView(std::move(v), name, 2, {6, m}, bs);
}

}  // namespace

struct BatchRunner {
  PySolver& s;
  BatchSize bs;
  Batched q, qd, f_ext, tau, f_ext_pass_through, tau_ff_pass_through;
  std::vector<Batched> alpha, beta;             // one per block (end segment first)
  std::vector<ConstraintBlock> block_template;  // segment, cols, offset per block
  std::vector<py::object> block_keys;
  std::vector<int> key_block;  // constraints= key k -> block index
  std::vector<Batched> link_wrench_rows;
  std::vector<LinkWrench> link_wrench_template;
  std::vector<double> f_ext_dense;  // dict f_ext without merged links: (B or 1, ns, 6)
  bool f_ext_dense_batched = false;
  std::vector<vereshchagin::FrictionModel> friction;  // empty, one shared, or one per row
  std::vector<char> row_has_friction;
  bool any_friction = false;
  py::ssize_t B = 0, M = 0;

  explicit BatchRunner(PySolver& solver) : s(solver) {}

  void parseFExt(PyObject* obj) {
    if (!PyDict_Check(obj)) {
      f_ext = batchedArg(obj, "f_ext", 2, {static_cast<py::ssize_t>(s.ns), 6}, bs);
      return;
    }
    std::vector<std::pair<int, Batched>> direct;
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(obj, &pos, &key, &value)) {
      const std::string label = "f_ext[" + py::repr(key).cast<std::string>() + "]";
      const FrameTarget t = s.model_->resolveMoving(key, label);
      Batched w = batchedArg(value, label, 1, {6}, bs);
      if (t.merged) {
        LinkWrench lw;
        lw.segment = t.segment;
        lw.offset = t.link_in_tip.p;
        link_wrench_template.push_back(lw);
        link_wrench_rows.push_back(std::move(w));
      } else {
        direct.emplace_back(t.segment, std::move(w));
      }
    }
    if (direct.empty()) return;
    f_ext_dense_batched = false;
    for (const auto& d : direct) f_ext_dense_batched |= d.second.batched;
    pendingDirect = std::move(direct);
  }
  std::vector<std::pair<int, Batched>> pendingDirect;

  void finishFExt() {  // needs B
    if (pendingDirect.empty()) return;
    const py::ssize_t rows = f_ext_dense_batched ? B : 1;
    const py::ssize_t per = 6 * s.ns;
    f_ext_dense.assign(rows * per, 0.0);
    for (py::ssize_t b = 0; b < rows; ++b)
      for (const auto& d : pendingDirect)
        for (int k = 0; k < 6; ++k) f_ext_dense[b * per + 6 * d.first + k] += d.second.row(b)[k];
    f_ext.data = f_ext_dense.data();
    f_ext.stride = f_ext_dense_batched ? per : 0;
    f_ext.batched = f_ext_dense_batched;
  }

  void addBlock(int segment, PyObject* a_obj, PyObject* b_obj, const std::string& label, const FrameTarget* t) {
    py::ssize_t m = 0;
    Batched a = alphaArg(a_obj, label.empty() ? "alpha" : label + " alpha", bs, m);
    Batched b = betaArg(b_obj, label.empty() ? "beta" : label + " beta", m, bs);
    ConstraintBlock blk;
    blk.segment = segment;
    blk.cols = static_cast<int>(m);
    if (t) {
      blk.offset = t->link_in_tip.p;
      blk.has_offset = t->merged;
    }
    block_template.push_back(blk);
    alpha.push_back(std::move(a));
    beta.push_back(std::move(b));
    M += m;
  }

  void parseConstraints(PyObject* obj) {
    if (!PyDict_Check(obj)) raise("constraints must be a dict {segment name or index: (alpha (6, m_i), beta (m_i,))}");
    ConstraintKeys keys(*s.model_, static_cast<int>(s.ns), block_template.empty() ? 0 : block_template[0].cols);
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(obj, &pos, &key, &value)) {
      const std::string label = "constraints[" + py::repr(key).cast<std::string>() + "]";
      const FrameTarget t = keys.resolve(key, label);
      const auto [alpha_obj, beta_obj] =
          ConstraintKeys::pair(value, label, "(6, m_i) or (B, 6, m_i), beta (m_i,) or (B, m_i)");
      key_block.push_back(static_cast<int>(block_template.size()));
      addBlock(t.segment, alpha_obj, beta_obj, label, &t);
      keys.count(t.segment, block_template.back().cols, label);
    }
    block_keys = keys.keys();
  }

  void parseFrictionArg(PyObject* obj) {
    if (obj == Py_None || obj == Py_False) return;
    auto parseOne = [&](PyObject* item, const std::string& label) -> std::pair<bool, vereshchagin::FrictionModel> {
      ParsedSolve tmp;
      try {
        s.parseFriction(item, tmp);
      } catch (const SolverError& e) {
        raise(label + e.what());
      }
      if (!tmp.friction) return {false, {}};
      return {true, *tmp.friction};
    };
    if (PyList_Check(obj) || PyTuple_Check(obj)) {
      py::sequence seq = py::reinterpret_borrow<py::sequence>(obj);
      bs.add(static_cast<py::ssize_t>(seq.size()), "friction", "(a sequence of " + std::to_string(seq.size()) + ")");
      for (std::size_t b = 0; b < seq.size(); ++b) {
        auto r = parseOne(seq[b].ptr(), "friction[" + std::to_string(b) + "]: ");
        friction.push_back(std::move(r.second));
        row_has_friction.push_back(r.first);
        any_friction |= r.first;
      }
      return;
    }
    auto r = parseOne(obj, "");
    if (r.first) {
      friction.push_back(std::move(r.second));
      row_has_friction.push_back(1);
      any_friction = true;
    }
  }

  const vereshchagin::FrictionModel* frictionOf(py::ssize_t b) const {
    if (friction.empty()) return nullptr;
    const std::size_t k = friction.size() == 1 && row_has_friction.size() == 1 ? 0 : static_cast<std::size_t>(b);
    return row_has_friction[k] ? &friction[k] : nullptr;
  }

  // Inputs of row b, with blocks and wrenches written into the caller's scratch vectors.
  RowInputs rowInputs(py::ssize_t b, std::vector<ConstraintBlock>& blocks, std::vector<LinkWrench>& wrenches) const {
    RowInputs r;
    r.q = q.row(b);
    r.qd = qd.row(b);
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      blocks[k].alpha = alpha[k].row(b);
      blocks[k].beta = beta[k].row(b);
    }
    for (std::size_t k = 0; k < wrenches.size(); ++k) wrenches[k].wrench = link_wrench_rows[k].row(b);
    r.blocks = blocks.data();
    r.n_blocks = static_cast<int>(blocks.size());
    r.f_ext = f_ext.row(b);
    r.link_wrenches = wrenches.data();
    r.n_link_wrenches = static_cast<int>(wrenches.size());
    r.tau_ff = tau.row(b);
    r.friction = frictionOf(b);
    r.f_ext_pass_through = f_ext_pass_through.row(b);
    r.tau_ff_pass_through = tau_ff_pass_through.row(b);
    return r;
  }
};

namespace {

// solve_batch's threads: an int >= 0 (0: one per core), at most kMaxBatchThreads.
long threadsArg(const py::object& obj) {
  if (obj.is_none()) return 1;
  if (PyBool_Check(obj.ptr()) || !PyIndex_Check(obj.ptr()))
    raise("threads must be an int (0: one per core), got " + std::string(Py_TYPE(obj.ptr())->tp_name) + " " +
          py::repr(obj).cast<std::string>());
  const std::optional<long long> v = intWithin(obj.ptr(), 0, kMaxBatchThreads);
  if (!v)
    raise("threads must be in 0 .. " + std::to_string(kMaxBatchThreads) + " (0: one per core), got " +
          py::str(obj).cast<std::string>());
  if (*v == 0) return std::max(1u, std::thread::hardware_concurrency());
  return static_cast<long>(*v);
}

}  // namespace

// response_columns() after a batch linearises around its last row: engine 0 solved it unless the
// rows were spread over threads; then it solves it once more (bit-identical rows).
void PySolver::keepLastRow(BatchRunner& br, long threads) {
  if (br.B == 0) return;
  if (threads > 1) {
    std::vector<ConstraintBlock> blocks = br.block_template;
    std::vector<LinkWrench> wrenches = br.link_wrench_template;
    const RowInputs row = br.rowInputs(br.B - 1, blocks, wrenches);
    py::gil_scoped_release release;
    if (engines_[0]->run(row) != ChainHdSolver::E_NOERROR) return;
  }
  last_state_ = true;
}

py::dict PySolver::solveBatch(const py::object& q_obj, const py::object& qd_obj, const py::object& alpha_obj,
                              const py::object& beta_obj, const py::object& f_ext_obj, const py::object& tau_obj,
                              const py::object& friction_obj, const py::object& constraints_obj,
                              const py::object& f_ext_pass_through_obj, const py::object& tau_ff_pass_through_obj,
                              const py::object& threads_obj) {
  auto lk = lock();
  beginStateCall();
  BatchRunner br(*this);
  const py::ssize_t n = nj;
  br.q = batchedArg(q_obj.ptr(), "q", 1, {n}, br.bs);
  br.qd = batchedArg(qd_obj.ptr(), "qd", 1, {n}, br.bs);
  if (!alpha_obj.is_none()) {
    if (tree_) raise(kTreeAlpha);
    if (beta_obj.is_none()) raise("beta is required when alpha is given");
    br.addBlock(static_cast<int>(ns) - 1, alpha_obj.ptr(), beta_obj.ptr(), "", nullptr);
    if (br.block_template.back().cols == 0) {  // no columns: nothing to constrain
      br.block_template.pop_back();
      br.alpha.pop_back();
      br.beta.pop_back();
    }
  } else if (!beta_obj.is_none()) {
    raise("beta given without alpha");
  }
  if (!f_ext_obj.is_none()) br.parseFExt(f_ext_obj.ptr());
  if (!tau_obj.is_none()) br.tau = batchedArg(tau_obj.ptr(), "tau_ff", 1, {n}, br.bs);
  if (!constraints_obj.is_none()) br.parseConstraints(constraints_obj.ptr());
  br.parseFrictionArg(friction_obj.ptr());
  const std::pair<const py::object*, const char*> weight_args[2] = {{&f_ext_pass_through_obj, "f_ext_pass_through"},
                                                                    {&tau_ff_pass_through_obj, "tau_ff_pass_through"}};
  Batched* weights[2] = {&br.f_ext_pass_through, &br.tau_ff_pass_through};
  for (int k = 0; k < 2; ++k) {
    if (weight_args[k].first->is_none()) continue;
    *weights[k] = betaArg(weight_args[k].first->ptr(), weight_args[k].second, br.M, br.bs);
    checkWeights(weights[k]->view.data, weights[k]->view.size(), weight_args[k].second);
  }
  br.B = br.bs.B < 0 ? 1 : br.bs.B;
  br.finishFExt();
  const py::ssize_t B = br.B, M = br.M;
  checkColumnCount(M);
  long threads = std::min<long>(threadsArg(threads_obj), std::max<py::ssize_t>(B, 1));
  for (long t = 0; t < threads; ++t) engine(static_cast<std::size_t>(t));

  py::array qdd = newDoubles({B, n}), tau = newDoubles({B, n}), nu = newDoubles({B, M});
  py::array acc = newDoubles({B, static_cast<py::ssize_t>(ns + 1), 6});
  py::array rank = newInts({B}), smin = newDoubles({B});
  py::array fr, lim, status, gauss, iters;
  if (br.any_friction) {
    fr = newDoubles({B, n});
    lim = newDoubles({B, n});
    status = newInts({B, n});
    gauss = newDoubles({B});
    iters = newInts({B});
  }
  struct Failure {
    py::ssize_t row = -1;
    std::string message;
  };
  std::vector<Failure> failures(threads);
  auto work = [&](long t, py::ssize_t begin, py::ssize_t end) {
    Engine& e = *engines_[t];
    std::vector<ConstraintBlock> blocks = br.block_template;
    std::vector<LinkWrench> wrenches = br.link_wrench_template;
    for (py::ssize_t b = begin; b < end; ++b) {
      const RowInputs row = br.rowInputs(b, blocks, wrenches);
      if (e.run(row) != ChainHdSolver::E_NOERROR) {
        failures[t] = {b, e.errorMessage()};
        return;
      }
      e.writeCore(doubles(qdd) + b * n, doubles(tau) + b * n, doubles(nu) + b * M, doubles(acc) + b * 6 * (ns + 1),
                  ints(rank) + b, doubles(smin) + b);
      if (!br.any_friction) continue;
      if (row.friction) {
        e.writeFriction(doubles(fr) + b * n, doubles(lim) + b * n, ints(status) + b * n, doubles(gauss) + b,
                        ints(iters) + b);
        if (!std::isfinite(doubles(gauss)[b])) {
          failures[t] = {b, "the results overflow: gauss_value is beyond the double range"};
          return;
        }
      } else {
        std::fill(doubles(fr) + b * n, doubles(fr) + (b + 1) * n, std::nan(""));
        std::fill(doubles(lim) + b * n, doubles(lim) + (b + 1) * n, std::nan(""));
        std::fill(ints(status) + b * n, ints(status) + (b + 1) * n, -1);
        doubles(gauss)[b] = std::nan("");
        ints(iters)[b] = -1;
      }
    }
  };
  last_state_ = false;  // until engine 0 holds the last row's state
  std::string start_failure;
  {
    py::gil_scoped_release release;
    if (threads <= 1) {
      work(0, 0, B);
    } else {
      std::vector<std::thread> pool;
      pool.reserve(static_cast<std::size_t>(threads));
      const py::ssize_t chunk = (B + threads - 1) / threads;
      try {
        for (long t = 1; t < threads; ++t)
          pool.emplace_back(work, t, std::min(B, t * chunk), std::min(B, (t + 1) * chunk));
      } catch (const std::system_error& e) {  // the OS refused a thread: join the started ones
        for (auto& th : pool) th.join();
        start_failure = "solve_batch could not start thread " + std::to_string(pool.size() + 1) + " of " +
                        std::to_string(threads) + " (" + e.what() + "): pass fewer threads";
      }
      if (start_failure.empty()) {
        work(0, 0, std::min(B, chunk));
        for (auto& th : pool) th.join();
      }
    }
  }
  if (!start_failure.empty()) raise(start_failure);
  for (const Failure& f : failures)  // rows are in thread order: the first failure is the lowest row
    if (f.row >= 0) raise("batch row " + std::to_string(f.row) + ": " + f.message);
  keepLastRow(br, threads);
  py::dict out;
  out["qdd"] = qdd;
  out["tau_command"] = tau;
  out["nu"] = nu;
  out["link_acc"] = acc;
  out["constraint_rank"] = rank;
  out["smallest_singular_value"] = smin;
  if (br.any_friction) {
    out["friction_torque"] = fr;
    out["limit_torque"] = lim;
    out["status"] = status;
    out["gauss_value"] = gauss;
    out["iterations"] = iters;
  }
  if (!br.block_keys.empty()) {
    py::dict per_key;
    py::ssize_t offset = 0;
    for (std::size_t k = 0; k < br.block_template.size(); ++k) {
      const py::ssize_t mk = br.block_template[k].cols;
      const auto it = std::find(br.key_block.begin(), br.key_block.end(), static_cast<int>(k));
      if (it != br.key_block.end())
        per_key[br.block_keys[it - br.key_block.begin()]] =
            nu[py::make_tuple(py::slice(0, B, 1), py::slice(offset, offset + mk, 1))];
      offset += mk;
    }
    out["segment_nu"] = per_key;
  }
  return out;
}

}  // namespace vsbind
