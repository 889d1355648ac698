#include "gesture_formation/planning/qp_json.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace gesture_formation::planning {

namespace {

void writeSparse(std::ostream& os, const Eigen::SparseMatrix<double>& m) {
  os << "{\"rows\": " << m.rows() << ", \"cols\": " << m.cols() << ", \"entries\": [";
  bool first = true;
  for (int k = 0; k < m.outerSize(); ++k) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(m, k); it; ++it) {
      os << (first ? "" : ", ") << "[" << it.row() << ", " << it.col() << ", " << jsonNumber(it.value()) << "]";
      first = false;
    }
  }
  os << "]}";
}

}  // namespace

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

std::string jsonVector(const Eigen::VectorXd& v) {
  std::ostringstream os;
  os << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    os << (i ? ", " : "") << (std::abs(v(i)) >= 1e20 ? (v(i) > 0 ? "1e20" : "-1e20") : jsonNumber(v(i)));
  }
  os << "]";
  return os.str();
}

void writeQpJson(std::ostream& os, const QpMatrices& m, const std::vector<std::pair<std::string, std::string>>& fields) {
  const char* separator = "{";
  for (const auto& [matrix, matrix_key, vector, vector_key] :
       {std::tuple{&m.H, "H", &m.g, "g"}, std::tuple{&m.A, "A", &m.b, "b"}, std::tuple{&m.C, "C", &m.l, "l"}}) {
    os << separator << "\"" << matrix_key << "\": ";
    writeSparse(os, *matrix);
    os << ", \"" << vector_key << "\": " << jsonVector(*vector);
    separator = ", ";
  }
  os << ", \"u\": " << jsonVector(m.u) << ", \"cost_constant\": " << jsonNumber(m.cost_constant);
  for (const auto& [key, json] : fields) os << ", \"" << key << "\": " << json;
  os << "}\n";
}

}  // namespace gesture_formation::planning
