#pragma once
/// \file
/// \brief The assembled trajectory QP (QpMatrices, docs/planning.md §6) as JSON — the one format
/// that `gfctl plan --dump-qp` and `gf_bench_planner --qp-dump` write and that
/// tools/reference/qp_reference.py and tools/bench_qp_osqp.py read:
///
///   {"H": M, "g": V, "A": M, "b": V, "C": M, "l": V, "u": V, "cost_constant": x, <extra fields>}
///
/// for min ½xᵀHx + gᵀx s.t. Ax = b, l ≤ Cx ≤ u; M = {"rows": r, "cols": c, "entries": [[row, col,
/// value], …]} (column-major order, H with both triangles), V = [v, …]; ±1e20 means "no bound";
/// numbers with 17 significant digits (exact round trip), non-finite ones `null`.
/// Thread safety: free functions without state.

#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/trajectory_qp.hpp"

namespace gesture_formation::planning {

/// \brief A number as JSON: 17 significant digits, `null` when not finite.
std::string jsonNumber(double v);
/// \brief A vector as a JSON array (entries of magnitude ≥ 1e20 written as ±1e20: no bound).
std::string jsonVector(const Eigen::VectorXd& v);
/// \brief Writes the object above; `fields` (key, JSON text) follow `cost_constant` in order.
void writeQpJson(std::ostream& os, const QpMatrices& m, const std::vector<std::pair<std::string, std::string>>& fields);

}  // namespace gesture_formation::planning
