#pragma once
/// \file
/// \brief Stage 3 trajectory optimisation as one sparse QP solved by ProxQP
/// (proxsuite::proxqp::sparse), docs/planning.md §6.
///
/// Model: per axis a triple integrator with constant jerk on each interval [t_k, t_{k+1}],
/// dt fixed. Variables: p_k, v_k, a_k ∈ R³ for k = 1..N (sample 0 is the fixed initial
/// state), ordered [p_1 v_1 a_1 p_2 …] (9N). Equalities (6N), with j_k = (a_{k+1} − a_k)/dt:
///   p_{k+1} = p_k + v_k dt + a_k dt²/3 + a_{k+1} dt²/6,   v_{k+1} = v_k + (a_k + a_{k+1}) dt/2.
/// Cost (×dt, so weights do not depend on the sampling):
///   Σ_k w_ref‖p_k − r_k‖² + w_acc‖a_k‖² + w_jerk‖(a_k − a_{k−1})/dt‖²  + w_term‖v_N‖².
/// Inequalities (all hard):
///   - position rows a·p_k ≤ b (corridor polytopes, inter-UAV and worker half-spaces);
///   - velocity in the inner polyhedron V (VelocityPolygon) at every sample *and* at the
///     middle Bézier control point v_k + a_k dt/2 of every interval — v(t) is a quadratic
///     Bézier on each interval, so it stays in V between samples too;
///   - acceleration in the inner polyhedron A at every sample (a(t) is linear in between).
///
/// Two formulations (`TrajectoryQpProblem::formulation`):
///   - kCondensed (experimental, not the default — docs/planning.md §6.3.1): the dynamics eliminated — per axis p_k = c_k + S_p a, v_k = c'_k + S_v a
///     with lower-triangular N×N S_p, S_v shared by the three axes — leaving the 3N accelerations,
///     no equalities and the same inequality rows (dense); solved by ProxQP's dense backend, which is
///     bounded by max_iter (no thread, no timeout needed). p and v are then recomputed from a by the
///     recursion above, so the dynamics hold to rounding. ~30 % cheaper per QP than the sparse form,
///     but the missions it flies meet more infeasible replannings (planning.md §6.3.1).
///   - kSparse (default): the 9N-variable form above, solved by ProxQP's sparse backend with the
///     time bound below; it also decides every QP the condensed form does not solve.
///
/// Time bound, without threads: ProxQP's sparse solver can loop forever (0.7.2–0.8.0: its LDLᵀ
/// row deletion breaks its own precondition and then walks a corrupted elimination tree, a loop
/// `max_iter` does not bound; docs/safety.md §4.5). ProxQP is compiled with its invariant checks on
/// (detail/proxqp_checked.hpp), so that QP stops with an exception the moment the invariant breaks
/// and is solved again by ProxQP's dense backend (no elimination tree; ~13× slower on the
/// mission's QPs). Every solve also runs in rounds of QpSolveLimits::iterations_per_check outer
/// iterations and checks its deadline (`solve_timeout_s`, per backend) between rounds: past it the
/// QP reports kTimeLimit and the planner falls back like on any failed QP. Replannings of the
/// power-tower mission need at most ~80 iterations, so a round is never cut in them.
/// Thread safety: solve() may be called from several threads (each call has its own solver).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace gesture_formation::planning {

/// \brief Inner polyhedral approximation of {‖x‖ ≤ max_norm, |x_z| ≤ max_vertical}: |x_z| ≤
/// max_vertical and (x, y) in the regular octagon inscribed in the disc of radius
/// r = sqrt(max_norm² − max_vertical²) (apothem r cos(π/8)). Every point of it satisfies
/// ‖x‖ ≤ max_norm; it contains the ball of radius min(r cos(π/8), max_vertical).
struct NormPolygon {
  double max_norm = 1.0;
  double max_vertical = 0.5;
  /// Rows d·x ∈ [−h, h]: directions (unit) and half-widths h.
  static constexpr int kRows = 5;
  Eigen::Matrix<double, kRows, 3> directions() const;
  Eigen::Matrix<double, kRows, 1> halfWidths() const;
  bool contains(const Eigen::Vector3d& x, double tolerance = 0.0) const;
};

/// \brief One linear constraint on the position of sample k (1 ≤ k ≤ N): a·p_k ≤ b.
struct PositionConstraint {
  int sample = 1;
  Eigen::Vector3d a = Eigen::Vector3d::UnitX();
  double b = 0.0;
  enum class Kind { kCorridor, kUav, kWorker } kind = Kind::kCorridor;
};

struct TrajectoryQpProblem {
  double dt_s = 0.2;
  int intervals = 0;  ///< N ≥ 1
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), v0 = Eigen::Vector3d::Zero(), a0 = Eigen::Vector3d::Zero();
  /// r_k for k = 0..N (index 0 unused), world frame [m].
  std::vector<Eigen::Vector3d> reference;
  std::vector<PositionConstraint> constraints;
  NormPolygon velocity;
  NormPolygon acceleration;
  double w_reference = 1.0, w_acceleration = 0.05, w_jerk = 0.01, w_terminal_velocity = 1.0;
  double eps_abs = 1e-6;
  /// ProxQP's primal infeasibility tolerance (its `eps_primal_inf`, ProxQP's default 1e-4): the
  /// relative tolerance of the Farkas certificate it builds from its Newton steps.
  double eps_primal_inf = 1e-4;
  int max_iterations = 4000;
  /// Cooperative wall-clock bound (s) of each backend's solve, > 0 (checked between rounds of
  /// QpSolveLimits::kIterationsPerCheck outer iterations; past it: kTimeLimit).
  double solve_timeout_s = 2.0;
  enum class Formulation { kCondensed, kSparse } formulation = Formulation::kSparse;
  /// The trajectory ends at rest: v_N = 0 and a_N = 0 as six more equality rows (solved in the
  /// sparse form whatever `formulation` says). Used by UavPlanner's truncated re-solve.
  bool terminal_rest = false;
};

struct TrajectoryQpSolution {
  enum class Status { kSolved, kInfeasible, kMaxIterations, kTimeLimit, kNumerical, kBadInput } status = Status::kBadInput;
  std::string reason;  ///< empty when solved
  /// p, v, a for k = 0..N (index 0 = the initial state).
  std::vector<Eigen::Vector3d> p, v, a;
  int variables = 0, equalities = 0, inequalities = 0, iterations = 0;
  double primal_residual = 0.0;  ///< max constraint violation of the returned x (ProxQP's scale)
  double objective = 0.0;
  bool warm_started = false;
  /// The sparse solver broke one of its invariants (the QP was then given to the dense backend)
  /// / the dense backend produced this solution (condensed form, or after a broken invariant).
  bool sparse_invariant_broken = false;
  bool dense_backend = false;
  /// Solved in the condensed form (accelerations only; `variables` = 3N, `equalities` = 0).
  bool condensed = false;
  bool solved() const { return status == Status::kSolved; }
};

/// \brief The assembled QP in ProxQP's form: min ½xᵀHx + gᵀx s.t. Ax = b, l ≤ Cx ≤ u
/// (±1e20 = no bound), x = [p_1 v_1 a_1 … p_N v_N a_N]. The constant of the cost is
/// `cost_constant` (so TrajectoryQp::cost = ½xᵀHx + gᵀx + cost_constant).
struct QpMatrices {
  Eigen::SparseMatrix<double> H, A, C;
  Eigen::VectorXd g, b, l, u;
  double cost_constant = 0.0;
};

/// \brief How long ProxQP may run on one QP (TrajectoryQp::solveMatrices).
struct QpSolveLimits {
  /// Outer iterations between two deadline checks; a round of them is bounded by ProxQP's
  /// own iteration limits, not by the clock.
  static constexpr int kIterationsPerCheck = 100;
  double eps_abs = 1e-6;                         ///< > 0
  double eps_primal_inf = 1e-4;                  ///< > 0, ProxQP's primal infeasibility tolerance
  int max_iterations = 4000;                     ///< outer iterations in all, ≥ 1
  double timeout_s = 2.0;                        ///< per backend, > 0
  int iterations_per_check = kIterationsPerCheck;  ///< ≥ 1
  /// Problems as "field must …, got …; " (empty: valid).
  std::string validate() const;
};

/// \brief What ProxQP returned for assembled matrices (TrajectoryQp::solveMatrices).
struct QpMatricesSolution {
  TrajectoryQpSolution::Status status = TrajectoryQpSolution::Status::kNumerical;
  Eigen::VectorXd x;  ///< the primal solution (size of H), empty if the solver threw
  int iterations = 0;  ///< ProxQP's (inner) iterations, all rounds
  int rounds = 0;      ///< rounds of QpSolveLimits::iterations_per_check run (by the backend that answered)
  bool sparse_invariant_broken = false;
  bool dense_backend = false;
  std::string reason;  ///< why there is no solution / why the dense backend answered
};

/// \brief Assembles and solves the QP. `warm` (optional): a guess of p, v, a for k = 0..N
/// (e.g. the previous plan re-timed), used as ProxQP's primal warm start.
class TrajectoryQp {
 public:
  TrajectoryQpSolution solve(const TrajectoryQpProblem& problem, const TrajectoryQpSolution* warm = nullptr) const;
  /// \brief The matrices solve() hands to ProxQP (problem must be valid: see solve()).
  static QpMatrices assemble(const TrajectoryQpProblem& problem);
  /// \brief The condensed form's matrices (dense; A, b empty; x = [a_x(1..N) a_y(1..N) a_z(1..N)])
  /// in the same form as QpMatrices, with H, C as sparse views for inspection and tests.
  static QpMatrices assembleCondensed(const TrajectoryQpProblem& problem);
  /// \brief ProxQP on assembled matrices with the bounds above: the sparse backend; if it breaks
  /// an invariant, the dense backend on the same QP. `x0` (optional, size of H): primal warm
  /// start. Invalid limits: kBadInput with the fields named in `reason`.
  static QpMatricesSolution solveMatrices(const QpMatrices& matrices, const Eigen::VectorXd* x0,
                                          const QpSolveLimits& limits);
  /// \brief x = [p_1 v_1 a_1 … p_N v_N a_N] of the sparse form (QpMatrices) from p, v, a for
  /// k = 0..N (sizes N + 1, e.g. a TrajectoryQpSolution or a warm start); empty when a size differs.
  static Eigen::VectorXd variables(int intervals, const std::vector<Eigen::Vector3d>& p,
                                   const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a);
  /// Dense iterations allowed to the condensed form before the sparse form takes the QP over.
  static constexpr int kCondensedMaxIterations = 100;

  /// \brief Worst violation of every constraint of `problem` (dynamics equalities, rows,
  /// velocity/acceleration polyhedra incl. the Bézier points) by p, v, a: ≤ 0 when all hold.
  static double maxViolation(const TrajectoryQpProblem& problem, const std::vector<Eigen::Vector3d>& p,
                             const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a);
  /// \brief The objective ½xᵀHx + gᵀx + const (the cost above) of p, v, a.
  static double cost(const TrajectoryQpProblem& problem, const std::vector<Eigen::Vector3d>& p,
                     const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3d>& a);
};

}  // namespace gesture_formation::planning
