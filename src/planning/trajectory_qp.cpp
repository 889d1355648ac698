#include "gesture_formation/planning/trajectory_qp.hpp"

// First: ProxQP with its invariant checks on (before any other ProxQP header).
#include "gesture_formation/planning/detail/proxqp_checked.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <Eigen/Sparse>

namespace gesture_formation::planning {

// ---- NormPolygon ------------------------------------------------------------------------

Eigen::Matrix<double, NormPolygon::kRows, 3> NormPolygon::directions() const {
  const double s = std::sqrt(0.5);
  Eigen::Matrix<double, kRows, 3> d;
  d << 1, 0, 0,  //
      0, 1, 0,   //
      s, s, 0,   //
      s, -s, 0,  //
      0, 0, 1;
  return d;
}

Eigen::Matrix<double, NormPolygon::kRows, 1> NormPolygon::halfWidths() const {
  const double r = std::sqrt(std::max(0.0, max_norm * max_norm - max_vertical * max_vertical));
  const double apothem = r * std::cos(M_PI / 8.0);
  Eigen::Matrix<double, kRows, 1> h;
  h << apothem, apothem, apothem, apothem, max_vertical;
  return h;
}

bool NormPolygon::contains(const Eigen::Vector3d& x, double tolerance) const {
  const Eigen::Matrix<double, kRows, 1> r = directions() * x;
  return (r.cwiseAbs() - halfWidths()).maxCoeff() <= tolerance;
}

// ---- QP assembly ---------------------------------------------------------------------------

namespace {

constexpr double kInf = 1e20;  // ProxQP's "no bound"

/// Index of component `axis` of quantity q (0 p, 1 v, 2 a) of sample k ≥ 1.
inline int var(int k, int q, int axis) { return 9 * (k - 1) + 3 * q + axis; }

using Triplets = std::vector<Eigen::Triplet<double>>;

std::string checkProblem(const TrajectoryQpProblem& pr) {
  std::ostringstream e;
  if (!(pr.dt_s > 0.0) || !std::isfinite(pr.dt_s)) e << "dt_s must be > 0, got " << pr.dt_s << "; ";
  if (pr.intervals < 1) e << "intervals must be >= 1, got " << pr.intervals << "; ";
  if (static_cast<int>(pr.reference.size()) != pr.intervals + 1) {
    e << "reference has " << pr.reference.size() << " points, need intervals + 1 = " << pr.intervals + 1 << "; ";
  }
  if (!pr.p0.allFinite() || !pr.v0.allFinite() || !pr.a0.allFinite()) e << "initial state is not finite; ";
  for (std::size_t k = 1; k < pr.reference.size(); ++k) {
    if (!pr.reference[k].allFinite()) {
      e << "reference[" << k << "] is not finite; ";
      break;
    }
  }
  for (std::size_t i = 0; i < pr.constraints.size(); ++i) {
    const auto& c = pr.constraints[i];
    if (c.sample < 1 || c.sample > pr.intervals || !c.a.allFinite() || !std::isfinite(c.b)) {
      e << "constraint " << i << " (sample " << c.sample << ") is invalid; ";
      break;
    }
  }
  if (!(pr.solve_timeout_s > 0.0) || !std::isfinite(pr.solve_timeout_s)) {
    e << "solve_timeout_s must be > 0, got " << pr.solve_timeout_s << "; ";
  }
  if (!(pr.w_reference > 0.0) || pr.w_acceleration < 0.0 || pr.w_jerk < 0.0 || pr.w_terminal_velocity < 0.0) {
    e << "weights must be >= 0 (reference > 0); ";
  }
  return e.str();
}

/// One inequality row of the QP in the state of one sample k ≥ 1:
/// l ≤ wp·p_k + wv·v_k + wa·a_k ≤ u (zero weights: the variable is absent).
struct InequalityRow {
  int sample = 0;
  Eigen::Vector3d wp = Eigen::Vector3d::Zero(), wv = Eigen::Vector3d::Zero(), wa = Eigen::Vector3d::Zero();
  double l = -kInf, u = kInf;
};

/// Calls f(row) for every inequality of `pr` in the QP's row order — the position constraints,
/// then per sample k = 1..N and speed-polygon row r: v_k, the middle Bézier control point
/// v_k + a_k dt/2 of v on [t_k, t_k+1] (k < N), a_k. assemble(), condense() and maxViolation()
/// all read the rows from here.
template <class F>
void forEachInequality(const TrajectoryQpProblem& pr, F&& f) {
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  for (const auto& c : pr.constraints) f(InequalityRow{c.sample, c.a, z, z, -kInf, c.b});
  const int N = pr.intervals;
  const double dt = pr.dt_s;
  const auto dv = pr.velocity.directions();
  const auto hv = pr.velocity.halfWidths();
  const auto da = pr.acceleration.directions();
  const auto ha = pr.acceleration.halfWidths();
  for (int k = 1; k <= N; ++k) {
    for (int r = 0; r < NormPolygon::kRows; ++r) {
      const Eigen::Vector3d d = dv.row(r).transpose();
      f(InequalityRow{k, z, d, z, -hv(r), hv(r)});
      if (k < N) f(InequalityRow{k, z, d, d * (dt / 2.0), -hv(r), hv(r)});
      f(InequalityRow{k, z, z, da.row(r).transpose(), -ha(r), ha(r)});
    }
  }
}

int inequalityCount(const TrajectoryQpProblem& pr) {
  const int N = pr.intervals;
  return static_cast<int>(pr.constraints.size()) + NormPolygon::kRows * (N + (N - 1) + N);
}

}  // namespace

double TrajectoryQp::maxViolation(const TrajectoryQpProblem& pr, const std::vector<Eigen::Vector3d>& p,
                                  const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a) {
  const int N = pr.intervals;
  const double dt = pr.dt_s;
  double worst = -std::numeric_limits<double>::infinity();
  const auto upd = [&worst](double x) { worst = std::max(worst, std::isfinite(x) ? x : std::numeric_limits<double>::infinity()); };
  upd((p[0] - pr.p0).cwiseAbs().maxCoeff());
  upd((v[0] - pr.v0).cwiseAbs().maxCoeff());
  upd((a[0] - pr.a0).cwiseAbs().maxCoeff());
  for (int k = 0; k < N; ++k) {
    const Eigen::Vector3d ep = p[k + 1] - (p[k] + v[k] * dt + a[k] * (dt * dt / 3.0) + a[k + 1] * (dt * dt / 6.0));
    const Eigen::Vector3d ev = v[k + 1] - (v[k] + (a[k] + a[k + 1]) * (dt / 2.0));
    upd(ep.cwiseAbs().maxCoeff());
    upd(ev.cwiseAbs().maxCoeff());
  }
  forEachInequality(pr, [&](const InequalityRow& r) {
    const auto k = static_cast<std::size_t>(r.sample);
    const double x = r.wp.dot(p[k]) + r.wv.dot(v[k]) + r.wa.dot(a[k]);
    if (r.u < kInf) upd(x - r.u);
    if (r.l > -kInf) upd(r.l - x);
  });
  return worst;
}

double TrajectoryQp::cost(const TrajectoryQpProblem& pr, const std::vector<Eigen::Vector3d>& p,
                          const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a) {
  const double dt = pr.dt_s;
  double c = 0.0;
  for (int k = 1; k <= pr.intervals; ++k) {
    c += dt * (pr.w_reference * (p[k] - pr.reference[k]).squaredNorm() + pr.w_acceleration * a[k].squaredNorm() +
               pr.w_jerk * ((a[k] - a[k - 1]) / dt).squaredNorm());
  }
  c += pr.w_terminal_velocity * v[pr.intervals].squaredNorm();
  return c;
}

QpMatrices TrajectoryQp::assemble(const TrajectoryQpProblem& pr) {
  const int N = pr.intervals;
  const double dt = pr.dt_s;
  const int n = 9 * N;
  const int n_eq = 6 * N + (pr.terminal_rest ? 6 : 0);
  const int n_in = inequalityCount(pr);
  QpMatrices m;

  // Cost: ½xᵀHx + gᵀx; a term c‖Mx − m‖² adds 2c MᵀM to H and −2c Mᵀm to g.
  Triplets ht;
  ht.reserve(static_cast<std::size_t>(n) * 3);
  Eigen::VectorXd& g = m.g;
  g = Eigen::VectorXd::Zero(n);
  const double wr = 2.0 * dt * pr.w_reference;
  const double wa = 2.0 * dt * pr.w_acceleration;
  const double wj = 2.0 * pr.w_jerk / dt;  // dt·w/dt² per ‖Δa‖²
  const double wt = 2.0 * pr.w_terminal_velocity;
  for (int k = 1; k <= N; ++k) {
    for (int i = 0; i < 3; ++i) {
      ht.emplace_back(var(k, 0, i), var(k, 0, i), wr);
      g(var(k, 0, i)) -= wr * pr.reference[k](i);
      // acceleration + jerk (a_k − a_{k−1}); a_0 is fixed.
      const bool last = k == N;
      ht.emplace_back(var(k, 2, i), var(k, 2, i), wa + wj * (last ? 1.0 : 2.0));
      if (k > 1) {
        ht.emplace_back(var(k, 2, i), var(k - 1, 2, i), -wj);
        ht.emplace_back(var(k - 1, 2, i), var(k, 2, i), -wj);
      } else {
        g(var(k, 2, i)) -= wj * pr.a0(i);
      }
      if (last) ht.emplace_back(var(k, 1, i), var(k, 1, i), wt);
    }
  }
  m.H.resize(n, n);
  m.H.setFromTriplets(ht.begin(), ht.end());

  // Dynamics equalities.
  Triplets at;
  at.reserve(static_cast<std::size_t>(n_eq) * 5);
  Eigen::VectorXd& b = m.b;
  b = Eigen::VectorXd::Zero(n_eq);
  int row = 0;
  for (int k = 0; k < N; ++k) {
    for (int i = 0; i < 3; ++i) {
      // p_{k+1} − p_k − v_k dt − a_k dt²/3 − a_{k+1} dt²/6 = 0
      at.emplace_back(row, var(k + 1, 0, i), 1.0);
      at.emplace_back(row, var(k + 1, 2, i), -dt * dt / 6.0);
      if (k == 0) {
        b(row) = pr.p0(i) + pr.v0(i) * dt + pr.a0(i) * dt * dt / 3.0;
      } else {
        at.emplace_back(row, var(k, 0, i), -1.0);
        at.emplace_back(row, var(k, 1, i), -dt);
        at.emplace_back(row, var(k, 2, i), -dt * dt / 3.0);
      }
      ++row;
      // v_{k+1} − v_k − (a_k + a_{k+1}) dt/2 = 0
      at.emplace_back(row, var(k + 1, 1, i), 1.0);
      at.emplace_back(row, var(k + 1, 2, i), -dt / 2.0);
      if (k == 0) {
        b(row) = pr.v0(i) + pr.a0(i) * dt / 2.0;
      } else {
        at.emplace_back(row, var(k, 1, i), -1.0);
        at.emplace_back(row, var(k, 2, i), -dt / 2.0);
      }
      ++row;
    }
  }
  if (pr.terminal_rest) {  // v_N = 0, a_N = 0
    for (int j = 1; j <= 2; ++j) {
      for (int i = 0; i < 3; ++i) at.emplace_back(row++, var(N, j, i), 1.0);
    }
  }
  m.A.resize(n_eq, n);
  m.A.setFromTriplets(at.begin(), at.end());

  // Inequalities l ≤ Cx ≤ u.
  Triplets ct;
  ct.reserve(static_cast<std::size_t>(n_in) * 6);
  m.l.resize(n_in);
  m.u.resize(n_in);
  row = 0;
  forEachInequality(pr, [&](const InequalityRow& r) {
    for (int i = 0; i < 3; ++i) {
      if (r.wp(i) != 0.0) ct.emplace_back(row, var(r.sample, 0, i), r.wp(i));
      if (r.wv(i) != 0.0) ct.emplace_back(row, var(r.sample, 1, i), r.wv(i));
      if (r.wa(i) != 0.0) ct.emplace_back(row, var(r.sample, 2, i), r.wa(i));
    }
    m.l(row) = r.l;
    m.u(row) = r.u;
    ++row;
  });
  m.C.resize(n_in, n);
  m.C.setFromTriplets(ct.begin(), ct.end());

  // Constant of the cost: Σ dt·w_ref‖r_k‖² + dt·w_jerk‖a_0/dt‖² (the a_1 − a_0 term).
  for (int k = 1; k <= N; ++k) m.cost_constant += dt * pr.w_reference * pr.reference[static_cast<std::size_t>(k)].squaredNorm();
  m.cost_constant += pr.w_jerk / dt * pr.a0.squaredNorm();
  return m;
}

namespace {

/// The condensed form (trajectory_qp.hpp): per axis p_k = cp_k + Sp.row(k−1)·a_axis and
/// v_k = cv_k + Sv.row(k−1)·a_axis for k = 1..N; x = [a_x(1..N) a_y(1..N) a_z(1..N)].
struct Condensed {
  Eigen::MatrixXd Sp, Sv;      ///< N×N, lower triangular, shared by the axes
  Eigen::Matrix3Xd cp, cv;     ///< 3×N, the parts from p0, v0, a0
  Eigen::MatrixXd H, C;        ///< 3N×3N (block diagonal), n_in×3N
  Eigen::VectorXd g, l, u;
  double cost_constant = 0.0;
};

Condensed condense(const TrajectoryQpProblem& pr) {
  const int N = pr.intervals;
  const double dt = pr.dt_s;
  Condensed q;
  q.Sp = Eigen::MatrixXd::Zero(N, N);
  q.Sv = Eigen::MatrixXd::Zero(N, N);
  q.cp.resize(3, N);
  q.cv.resize(3, N);
  // Forward recursion of the dynamics over coefficient rows (row k−1 ↔ sample k; sample 0 is
  // the fixed initial state, a_0 = pr.a0 a constant).
  Eigen::RowVectorXd sv = Eigen::RowVectorXd::Zero(N), sp = Eigen::RowVectorXd::Zero(N);
  Eigen::Vector3d cv = pr.v0, cp = pr.p0;
  for (int k = 0; k < N; ++k) {
    Eigen::RowVectorXd sp_next = sp + dt * sv;
    Eigen::Vector3d cp_next = cp + dt * cv;
    Eigen::RowVectorXd sv_next = sv;
    Eigen::Vector3d cv_next = cv;
    if (k == 0) {
      cp_next += pr.a0 * (dt * dt / 3.0);
      cv_next += pr.a0 * (dt / 2.0);
    } else {
      sp_next(k - 1) += dt * dt / 3.0;
      sv_next(k - 1) += dt / 2.0;
    }
    sp_next(k) += dt * dt / 6.0;
    sv_next(k) += dt / 2.0;
    sp = std::move(sp_next);
    sv = std::move(sv_next);
    cp = cp_next;
    cv = cv_next;
    q.Sp.row(k) = sp;
    q.Sv.row(k) = sv;
    q.cp.col(k) = cp;
    q.cv.col(k) = cv;
  }

  // Cost, one N×N block per axis (the same for the three): a term c(s·x + e)² adds 2c sᵀs to
  // H, 2c e sᵀ to g and c e² to the constant.
  const int n = 3 * N;
  const double wr = dt * pr.w_reference, wa = dt * pr.w_acceleration, wj = pr.w_jerk / dt, wt = pr.w_terminal_velocity;
  Eigen::MatrixXd Hb = 2.0 * wr * (q.Sp.transpose() * q.Sp);
  Hb.diagonal().array() += 2.0 * wa + 4.0 * wj;  // jerk: a_k appears in (a_k − a_{k−1}) and (a_{k+1} − a_k)
  Hb(N - 1, N - 1) -= 2.0 * wj;                  // a_N has no successor
  for (int k = 1; k < N; ++k) {
    Hb(k, k - 1) -= 2.0 * wj;
    Hb(k - 1, k) -= 2.0 * wj;
  }
  Hb.noalias() += 2.0 * wt * q.Sv.row(N - 1).transpose() * q.Sv.row(N - 1);
  q.H = Eigen::MatrixXd::Zero(n, n);
  q.g = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < 3; ++i) {
    q.H.block(i * N, i * N, N, N) = Hb;
    Eigen::VectorXd e(N);  // p_k's constant minus the reference
    for (int k = 1; k <= N; ++k) e(k - 1) = q.cp(i, k - 1) - pr.reference[static_cast<std::size_t>(k)](i);
    auto gi = q.g.segment(i * N, N);
    gi.noalias() += 2.0 * wr * (q.Sp.transpose() * e);
    gi(0) -= 2.0 * wj * pr.a0(i);  // (a_1 − a_0)²
    gi.noalias() += 2.0 * wt * q.cv(i, N - 1) * q.Sv.row(N - 1).transpose();
    q.cost_constant += wr * e.squaredNorm() + wj * pr.a0(i) * pr.a0(i) + wt * q.cv(i, N - 1) * q.cv(i, N - 1);
  }

  // Inequalities, in assemble()'s order: p_k = cp_k + Sp.row(k−1)·a, v_k = cv_k + Sv.row(k−1)·a
  // (both depend on a_1..a_k only), a_k a variable.
  const int n_in = inequalityCount(pr);
  q.C = Eigen::MatrixXd::Zero(n_in, n);
  q.l.resize(n_in);
  q.u.resize(n_in);
  int row = 0;
  forEachInequality(pr, [&](const InequalityRow& r) {
    const int k = r.sample;
    double constant = 0.0;  // the row's part from the initial state
    for (int i = 0; i < 3; ++i) {
      auto coeffs = q.C.row(row).segment(i * N, k);
      if (r.wp(i) != 0.0) {
        coeffs.noalias() += r.wp(i) * q.Sp.row(k - 1).head(k);
        constant += r.wp(i) * q.cp(i, k - 1);
      }
      if (r.wv(i) != 0.0) {
        coeffs.noalias() += r.wv(i) * q.Sv.row(k - 1).head(k);
        constant += r.wv(i) * q.cv(i, k - 1);
      }
      if (r.wa(i) != 0.0) q.C(row, i * N + k - 1) += r.wa(i);
    }
    q.l(row) = r.l > -kInf ? r.l - constant : -kInf;
    q.u(row) = r.u < kInf ? r.u - constant : kInf;
    ++row;
  });
  // Row equilibration (each row of C to unit ∞-norm, its bounds with it): an equivalent problem.
  // ProxQP's own (Ruiz) costs ~4 ms here, and without any, its dense solver declared feasible QPs
  // of the power-tower mission primal infeasible (seed 5: 28 failed replannings instead of 4).
  for (int r = 0; r < n_in; ++r) {
    const double s = q.C.row(r).lpNorm<Eigen::Infinity>();
    if (!(s > 0.0)) continue;
    q.C.row(r) /= s;
    if (q.l(r) > -kInf) q.l(r) /= s;
    if (q.u(r) < kInf) q.u(r) /= s;
  }
  return q;
}

}  // namespace

QpMatrices TrajectoryQp::assembleCondensed(const TrajectoryQpProblem& pr) {
  Condensed c = condense(pr);
  QpMatrices m;
  m.H = c.H.sparseView();
  m.C = c.C.sparseView();
  m.A.resize(0, c.H.cols());
  m.b.resize(0);
  m.g = std::move(c.g);
  m.l = std::move(c.l);
  m.u = std::move(c.u);
  m.cost_constant = c.cost_constant;
  return m;
}

namespace {

namespace pq = proxsuite::proxqp;
using Status = TrajectoryQpSolution::Status;
using Clock = std::chrono::steady_clock;

Status statusOf(pq::QPSolverOutput s) {
  switch (s) {
    case pq::QPSolverOutput::PROXQP_SOLVED:
      return Status::kSolved;
    case pq::QPSolverOutput::PROXQP_PRIMAL_INFEASIBLE:
    case pq::QPSolverOutput::PROXQP_SOLVED_CLOSEST_PRIMAL_FEASIBLE:
      return Status::kInfeasible;
    case pq::QPSolverOutput::PROXQP_MAX_ITER_REACHED:
      return Status::kMaxIterations;
    default:
      return Status::kNumerical;
  }
}

/// ProxQP in rounds of at most limits.iterations_per_check outer iterations, each round
/// continuing from the previous one's iterate, proximal parameters and factorisation, until it
/// stops for another reason than the round's limit, limits.max_iterations outer iterations have
/// run, or `deadline` has passed (checked between rounds: the cooperative time bound).
template <class Qp>
void runSolver(Qp& qp, const Eigen::VectorXd* x0, const QpSolveLimits& limits, Clock::time_point deadline,
               QpMatricesSolution& out) {
  qp.settings.eps_abs = limits.eps_abs;
  qp.settings.eps_rel = 0.0;
  qp.settings.eps_primal_inf = limits.eps_primal_inf;
  qp.settings.verbose = false;
  qp.settings.compute_timings = false;
  int outer = 0;
  out.iterations = 0;
  for (int round = 0;; ++round) {
    qp.settings.max_iter = std::min(limits.iterations_per_check, limits.max_iterations - outer);
    if (round > 0) {
      qp.settings.initial_guess = pq::InitialGuessStatus::WARM_START_WITH_PREVIOUS_RESULT;
      qp.solve();
    } else if (x0 != nullptr) {
      qp.solve(*x0, proxsuite::nullopt, proxsuite::nullopt);
    } else {
      qp.solve();
    }
    outer += static_cast<int>(qp.settings.max_iter);
    out.iterations += static_cast<int>(qp.results.info.iter);
    out.status = statusOf(qp.results.info.status);
    out.rounds = round + 1;
    if (out.status != Status::kMaxIterations || outer >= limits.max_iterations) break;
    if (Clock::now() >= deadline) {
      out.status = Status::kTimeLimit;
      break;
    }
  }
  out.x = qp.results.x;
}

void solveSparse(const QpMatrices& m, const Eigen::VectorXd* x0, const QpSolveLimits& limits, Clock::time_point deadline,
                 QpMatricesSolution& out) {
  pq::sparse::QP<double, int> qp(static_cast<int>(m.H.rows()), static_cast<int>(m.A.rows()), static_cast<int>(m.C.rows()));
  qp.init(m.H, m.g, m.A, m.b, m.C, m.l, m.u);
  runSolver(qp, x0, limits, deadline, out);
}

void solveDense(const QpMatrices& m, const Eigen::VectorXd* x0, const QpSolveLimits& limits, Clock::time_point deadline,
                QpMatricesSolution& out) {
  out.dense_backend = true;
  pq::dense::QP<double> qp(m.H.rows(), m.A.rows(), m.C.rows());
  const Eigen::MatrixXd H(m.H), A(m.A), C(m.C);
  qp.init(H, m.g, A, m.b, C, m.l, m.u);
  runSolver(qp, x0, limits, deadline, out);
}

}  // namespace

std::string QpSolveLimits::validate() const {
  std::ostringstream e;
  if (!(eps_abs > 0.0) || !std::isfinite(eps_abs)) e << "eps_abs must be > 0, got " << eps_abs << "; ";
  if (!(eps_primal_inf > 0.0) || !std::isfinite(eps_primal_inf)) e << "eps_primal_inf must be > 0, got " << eps_primal_inf << "; ";
  if (max_iterations < 1) e << "max_iterations must be >= 1, got " << max_iterations << "; ";
  if (!(timeout_s > 0.0) || !std::isfinite(timeout_s)) e << "solve_timeout_s must be > 0, got " << timeout_s << "; ";
  if (iterations_per_check < 1) e << "iterations_per_check must be >= 1, got " << iterations_per_check << "; ";
  return e.str();
}

QpMatricesSolution TrajectoryQp::solveMatrices(const QpMatrices& m, const Eigen::VectorXd* x0,
                                               const QpSolveLimits& limits) {
  QpMatricesSolution out;
  const std::string bad = limits.validate();
  if (!bad.empty()) {
    out.status = Status::kBadInput;
    out.reason = "QP limits: " + bad.substr(0, bad.size() - 2);
    return out;
  }
  const auto timeout = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(limits.timeout_s));
  try {
    solveSparse(m, x0, limits, Clock::now() + timeout, out);
    return out;
  } catch (const detail::ProxqpInvariantError& e) {
    out = QpMatricesSolution{};  // the sparse solver's state is void: the same QP on the dense backend
    out.sparse_invariant_broken = true;
    out.reason = e.what();
  } catch (const std::exception& e) {  // ProxQP throws on inconsistent dimensions / allocation
    out = QpMatricesSolution{};
    out.reason = std::string("QP solver threw: ") + e.what();
    return out;
  }
  try {
    solveDense(m, x0, limits, Clock::now() + timeout, out);
  } catch (const std::exception& e) {
    out.x.resize(0);
    out.status = Status::kNumerical;
    out.reason += std::string("; dense backend threw: ") + e.what();
  }
  return out;
}

namespace {

/// ProxQP dense on the condensed form; x (size 3N) empty when the solver threw.
QpMatricesSolution solveCondensedDense(const Condensed& q, const Eigen::VectorXd* x0, const QpSolveLimits& limits) {
  QpMatricesSolution out;
  out.dense_backend = true;
  try {
    pq::dense::QP<double> qp(q.H.rows(), 0, q.C.rows(), false, pq::DenseBackend::PrimalDualLDLT);
    // No Ruiz equilibration: ProxQP's dense one costs ~4 ms on the ~900 × 120 rows here, 5× the
    // rest of the solve, and the condensed rows are already of order one (docs/planning.md §6.4).
    qp.init(q.H, q.g, proxsuite::nullopt, proxsuite::nullopt, q.C, q.l, q.u, /*compute_preconditioner=*/false);
    runSolver(qp, x0, limits, Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(limits.timeout_s)), out);
  } catch (const std::exception&) {
    out = QpMatricesSolution{};
  }
  return out;
}

/// p, v from a by the dynamics' recursion (exact to rounding).
void integrate(const TrajectoryQpProblem& pr, TrajectoryQpSolution& out) {
  const double dt = pr.dt_s;
  for (int k = 0; k < pr.intervals; ++k) {
    out.p[k + 1] = out.p[k] + out.v[k] * dt + out.a[k] * (dt * dt / 3.0) + out.a[k + 1] * (dt * dt / 6.0);
    out.v[k + 1] = out.v[k] + (out.a[k] + out.a[k + 1]) * (dt / 2.0);
  }
}

}  // namespace

Eigen::VectorXd TrajectoryQp::variables(int intervals, const std::vector<Eigen::Vector3d>& p,
                                        const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a) {
  const auto size = static_cast<std::size_t>(intervals) + 1;
  Eigen::VectorXd x;
  if (intervals < 1 || p.size() != size || v.size() != size || a.size() != size) return x;
  x.resize(9 * intervals);
  for (int k = 1; k <= intervals; ++k) {
    const auto i = static_cast<std::size_t>(k);
    x.segment<3>(var(k, 0, 0)) = p[i];
    x.segment<3>(var(k, 1, 0)) = v[i];
    x.segment<3>(var(k, 2, 0)) = a[i];
  }
  return x;
}

namespace {

QpSolveLimits limitsOf(const TrajectoryQpProblem& pr) {
  QpSolveLimits l;
  l.eps_abs = pr.eps_abs;
  l.eps_primal_inf = pr.eps_primal_inf;
  l.max_iterations = pr.max_iterations;
  l.timeout_s = pr.solve_timeout_s;
  return l;
}

}  // namespace

TrajectoryQpSolution TrajectoryQp::solve(const TrajectoryQpProblem& pr, const TrajectoryQpSolution* warm) const {
  TrajectoryQpSolution out;
  const std::string bad = checkProblem(pr);
  if (!bad.empty()) {
    out.status = TrajectoryQpSolution::Status::kBadInput;
    out.reason = "QP input: " + bad.substr(0, bad.size() - 2);
    return out;
  }
  const int N = pr.intervals;
  const bool have_warm = warm != nullptr && static_cast<int>(warm->p.size()) == N + 1 &&
                         static_cast<int>(warm->v.size()) == N + 1 && static_cast<int>(warm->a.size()) == N + 1;
  out.p.assign(N + 1, pr.p0);
  out.v.assign(N + 1, pr.v0);
  out.a.assign(N + 1, pr.a0);

  QpMatricesSolution r;
  if (pr.formulation == TrajectoryQpProblem::Formulation::kCondensed && !pr.terminal_rest) {
    const Condensed q = condense(pr);
    Eigen::VectorXd x0;
    if (have_warm) {
      x0.resize(3 * N);
      for (int k = 1; k <= N; ++k) {
        for (int i = 0; i < 3; ++i) x0(i * N + k - 1) = warm->a[static_cast<std::size_t>(k)](i);
      }
      if (!x0.allFinite()) x0.resize(0);
    }
    // A bounded attempt: solved replannings take ≤ 20 dense iterations (power-tower mission, max
    // seen 17); a QP that needs more is handed to the sparse form instead of running to
    // max_iterations here (each dense iteration costs ~1 ms on ~1400 rows).
    QpSolveLimits limits = limitsOf(pr);
    limits.max_iterations = std::min(pr.max_iterations, kCondensedMaxIterations);
    r = solveCondensedDense(q, x0.size() == 3 * N ? &x0 : nullptr, limits);
    if (r.x.size() == 3 * N && r.x.allFinite()) {
      out.condensed = true;
      out.warm_started = x0.size() == 3 * N;
      out.variables = 3 * N;
      out.equalities = 0;
      out.inequalities = static_cast<int>(q.C.rows());
      for (int k = 1; k <= N; ++k) {
        for (int i = 0; i < 3; ++i) out.a[static_cast<std::size_t>(k)](i) = r.x(i * N + k - 1);
      }
      integrate(pr, out);
      // Only a solution is taken from the condensed form; any other outcome (infeasible, iteration
      // limit, numerical) is decided by the sparse form, the reference formulation.
      if (r.status != Status::kSolved) {
        out.condensed = false;
        out.p.assign(N + 1, pr.p0);
        out.v.assign(N + 1, pr.v0);
        out.a.assign(N + 1, pr.a0);
      }
    }
  }

  if (!out.condensed) {  // the sparse form (asked for, or the condensed solve did not solve it)
    const int n = 9 * N;
    const QpMatrices m = assemble(pr);
    out.variables = n;
    out.equalities = static_cast<int>(m.b.size());
    out.inequalities = static_cast<int>(m.l.size());
    Eigen::VectorXd x0;
    if (have_warm) {
      x0 = variables(N, warm->p, warm->v, warm->a);
      if (!x0.allFinite()) x0.resize(0);
    }
    out.warm_started = x0.size() == n;
    r = solveMatrices(m, out.warm_started ? &x0 : nullptr, limitsOf(pr));
    if (r.x.size() != n) {
      out.status = TrajectoryQpSolution::Status::kNumerical;
      out.reason = r.reason.empty() ? "QP solver failed (threw)" : r.reason;
      out.sparse_invariant_broken = r.sparse_invariant_broken;
      out.dense_backend = r.dense_backend;
      return out;
    }
    if (!r.x.allFinite()) {
      out.status = TrajectoryQpSolution::Status::kNumerical;
      out.reason = "QP solution is not finite";
      return out;
    }
    for (int k = 1; k <= N; ++k) {
      out.p[k] = r.x.segment<3>(var(k, 0, 0));
      out.v[k] = r.x.segment<3>(var(k, 1, 0));
      out.a[k] = r.x.segment<3>(var(k, 2, 0));
    }
  }
  out.sparse_invariant_broken = r.sparse_invariant_broken;
  out.dense_backend = r.dense_backend;
  out.iterations = r.iterations;
  out.primal_residual = maxViolation(pr, out.p, out.v, out.a);
  out.objective = cost(pr, out.p, out.v, out.a);
  out.status = r.status;
  switch (r.status) {
    case Status::kSolved:
      break;
    case Status::kInfeasible:
      out.reason = "QP primal infeasible";
      break;
    case Status::kMaxIterations:
      out.reason = "QP reached " + std::to_string(pr.max_iterations) + " iterations";
      break;
    case Status::kTimeLimit: {
      std::ostringstream os;
      os << "QP stopped at its deadline (solve_timeout_s " << pr.solve_timeout_s << " s) after " << r.iterations
         << " iterations";
      out.reason = os.str();
      break;
    }
    default:
      out.reason = "QP solver failed";
      break;
  }
  if (out.sparse_invariant_broken && !out.reason.empty()) {
    out.reason += " (dense backend: the sparse solver broke an invariant)";
  }
  // ProxQP's criterion is on the equilibrated problem; insist on the original scale too.
  if (out.solved() && !(out.primal_residual <= 100.0 * pr.eps_abs + 1e-9)) {
    std::ostringstream os;
    os << "QP solution violates a constraint by " << out.primal_residual;
    out.status = TrajectoryQpSolution::Status::kNumerical;
    out.reason = os.str();
  }
  return out;
}

}  // namespace gesture_formation::planning
