// Corridors against their anchor (issue 38; docs/planning.md §3 "Speed"): our CorridorBuilder and
// DecompUtil's algorithm (bench/decomp_reference.hpp, the library's steps and point handling) fed
// the same pre-cropped obstacle points per segment, on classes of segments in the power-tower map.
// A program that prints figures, not a test:
//   gf_bench_corridors [--segments N] [--reps R] [--seed S] [--results FILE.md]
//   (GF_SOURCE_DIR or the source tree as working directory; --results: also a dated page with the
//   output, e.g. docs/results/corridors_anchor.md)
// Target: ours >= 2x faster than the anchor (median), on every class. Before any timing, every
// anchor corridor is checked: both segment ends inside, no fed point strictly inside.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench_machine.hpp"
#include "decomp_reference.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/scenario.hpp"

using namespace gesture_formation;
using namespace gesture_formation::planning;
namespace ref = gesture_formation::bench::decomp_reference;

namespace {
using gf_bench::loadAverage;
using gf_bench::cpuModel;

std::string source(const std::string& rel) {
  const char* src = std::getenv("GF_SOURCE_DIR");
  return std::string(src ? src : ".") + "/" + rel;
}

/// A class of segments: both ends in `region`, length in [len_min, len_max], |direction z| ≤ max_dir_z,
/// distance to the nearest voxel centre in [1 m (the planner's path clearance), max_clearance_m],
/// at least one obstacle point in our local box.
struct SegmentClass {
  const char* name;
  const char* what;
  Eigen::Vector3d region_min, region_max;
  double len_min_m, len_max_m, max_dir_z, max_clearance_m;
};

std::vector<SegmentClass> segmentClasses() {
  using V = Eigen::Vector3d;
  const double kAny = 1e9;
  return {
      {"high_free_air", "31-35 m up over the span, above the earth wires", V(8, -10, 31), V(42, 10, 35), 1.5, 4.0, 0.3, kAny},
      {"near_tower", "beside the west tower's lattice, 1-3 m from it", V(-8, -9, 2), V(8, 9, 28), 1.5, 4.0, 1.0, 3.0},
      {"low_ground", "1.2-3 m over the ground between the towers", V(8, -15, 1.2), V(42, 15, 3), 1.5, 4.0, 0.15, kAny},
      {"under_wires", "8-11.5 m up under the conductors", V(8, -8, 8), V(42, 8, 11.5), 1.5, 4.0, 0.3, kAny},
      {"short", "0.5-1.5 m long, anywhere near structure", V(-8, -10, 1.2), V(58, 10, 30), 0.5, 1.5, 1.0, 3.0},
      {"long", "6-10 m long, anywhere near structure", V(-8, -10, 1.2), V(58, 10, 30), 6.0, 10.0, 1.0, 3.0},
  };
}

/// The product's corridor settings (config/planner.yaml, as UavPlanner sets them).
struct BenchSetup {
  OccupancyMap map;
  CorridorConfig ours;
  Eigen::Vector3d anchor_bbox_m;
};

/// One segment with its pre-cropped points: the union of our query box and the anchor's box.
struct Segment {
  Eigen::Vector3d p0, p1;
  std::vector<Eigen::Vector3d> points;
};

/// Axis-aligned box holding our query box and the anchor's oriented local box.
Aabb cropBox(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const BenchSetup& S) {
  const double ours = S.ours.local_box_margin_m.maxCoeff() + S.ours.clearance_m + S.ours.min_exclusion_m + 1e-6;
  Aabb box{p0.cwiseMin(p1) - Eigen::Vector3d::Constant(ours), p0.cwiseMax(p1) + Eigen::Vector3d::Constant(ours)};
  const double r = S.anchor_bbox_m.norm();  // the oriented box lies within r of the segment
  box.min_world = box.min_world.cwiseMin(p0.cwiseMin(p1) - Eigen::Vector3d::Constant(r));
  box.max_world = box.max_world.cwiseMax(p0.cwiseMax(p1) + Eigen::Vector3d::Constant(r));
  return box;
}

double segmentClearance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const std::vector<Eigen::Vector3d>& points) {
  double d = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& o : points) d = std::min(d, (o - closestPointOnSegment(p0, p1, o)).norm());
  return d;
}

/// A random segment of the class, or none when this draw does not qualify.
std::optional<Segment> drawSegment(const SegmentClass& k, const BenchSetup& S, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const Eigen::Vector3d span = k.region_max - k.region_min;
  const Eigen::Vector3d p0 = k.region_min + Eigen::Vector3d(U(rng), U(rng), U(rng)).cwiseProduct(span);
  const double z = k.max_dir_z * (2.0 * U(rng) - 1.0), az = 2.0 * M_PI * U(rng), h = std::sqrt(1.0 - z * z);
  const Eigen::Vector3d dir(h * std::cos(az), h * std::sin(az), z);
  const Eigen::Vector3d p1 = p0 + (k.len_min_m + (k.len_max_m - k.len_min_m) * U(rng)) * dir;
  if ((p1.array() < k.region_min.array()).any() || (p1.array() > k.region_max.array()).any()) return std::nullopt;
  Segment s{p0, p1, {}};
  S.map.pointsInBox(cropBox(p0, p1, S), s.points);
  const double clearance = segmentClearance(p0, p1, s.points);
  const Aabb ours{p0.cwiseMin(p1) - S.ours.local_box_margin_m, p0.cwiseMax(p1) + S.ours.local_box_margin_m};
  const bool any_in_box = std::any_of(s.points.begin(), s.points.end(), [&](const Eigen::Vector3d& o) { return ours.contains(o); });
  if (clearance < 1.0 || clearance > k.max_clearance_m || !any_in_box) return std::nullopt;
  return s;
}

std::vector<Segment> drawSegments(const SegmentClass& k, const BenchSetup& S, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Segment> out;
  for (int tries = 0; static_cast<int>(out.size()) < n && tries < 200000; ++tries) {
    if (auto s = drawSegment(k, S, rng)) out.push_back(std::move(*s));
  }
  return out;
}

template <bool kInvertEachCall>
ref::LineSegmentDecomp<kInvertEachCall> runAnchor(const Segment& s, const Eigen::Vector3d& bbox) {
  ref::LineSegmentDecomp<kInvertEachCall> d(s.p0, s.p1, bbox);
  d.setObstacles(s.points);
  d.dilate();
  return d;
}

/// What the checks found over a class (before timing).
struct Checks {
  int anchor_invalid = 0, ours_invalid = 0, compared = 0, axes_agree = 0;
  double max_axes_diff_m = 0.0;
  std::string first_problem;
};

/// The anchor's corridor: both ends inside, no fed point strictly inside; ours: built, no fed point
/// inside. Ellipsoids compared where both saw the same points in the initial sphere (L/2 ≤ box).
void checkSegment(const Segment& s, const BenchSetup& S, const CorridorBuilder& ours, Checks& c) {
  const auto anchor = runAnchor<true>(s, S.anchor_bbox_m);
  const Polytope P = anchor.polytope();
  double deepest = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& o : s.points) deepest = std::min(deepest, P.violation(o));
  const bool anchor_ok = P.violation(s.p0) <= 1e-9 && P.violation(s.p1) <= 1e-9 && deepest >= -1e-9;
  const auto mine = ours.buildSegment(s.p0, s.p1, PointCloudObstacles(s.points));
  bool ours_ok = static_cast<bool>(mine);
  for (std::size_t i = 0; ours_ok && i < s.points.size(); ++i) ours_ok = mine->polytope.violation(s.points[i]) > 0.0;
  if (!anchor_ok) ++c.anchor_invalid;
  if (!ours_ok) ++c.ours_invalid;
  if ((!anchor_ok || !ours_ok) && c.first_problem.empty()) {
    c.first_problem = std::string(anchor_ok ? "ours" : "anchor") + " invalid on a segment of " +
                      std::to_string((s.p1 - s.p0).norm()) + " m (deepest fed point " + std::to_string(deepest) + " m)";
  }
  if (!ours_ok || 0.5 * (s.p1 - s.p0).norm() > S.anchor_bbox_m.minCoeff()) return;
  const double diff = (mine->ellipsoid.axes_m - anchor.axes()).cwiseAbs().maxCoeff();
  ++c.compared;
  if (diff < 1e-6) ++c.axes_agree;
  c.max_axes_diff_m = std::max(c.max_axes_diff_m, diff);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

/// The calling thread's CPU time (µs): a build takes tens of µs, far below a scheduler slice, so
/// on a shared machine its CPU time is what it costs, its wall time what the neighbours left.
double cpuUs() { return 1e3 * gf_bench::threadCpuMs(); }

/// Per segment: the median of `reps` builds of each, interleaved (ours, anchor, anchor with C⁻¹ kept).
struct Timings {
  std::vector<double> ours_us, anchor_us, cached_us, ours_planes, anchor_planes, points;
};

volatile std::size_t g_sink = 0;

void timeSegment(const Segment& s, const BenchSetup& S, const CorridorBuilder& ours, int reps, Timings& t) {
  const PointCloudObstacles cloud(s.points);
  std::vector<double> a, b, c;
  std::size_t planes_ours = 0, planes_anchor = 0;
  for (int r = 0; r < reps; ++r) {
    const double t0 = cpuUs();
    const auto mine = ours.buildSegment(s.p0, s.p1, cloud);
    const double t1 = cpuUs();
    const auto anchor = runAnchor<true>(s, S.anchor_bbox_m);
    const double t2 = cpuUs();
    const auto cached = runAnchor<false>(s, S.anchor_bbox_m);
    const double t3 = cpuUs();
    a.push_back(t1 - t0), b.push_back(t2 - t1), c.push_back(t3 - t2);
    planes_ours = static_cast<std::size_t>(mine->polytope.rows());
    planes_anchor = anchor.planes().size();
    g_sink = g_sink + cached.planes().size();  // keeps the third build
  }
  t.ours_us.push_back(median(a)), t.anchor_us.push_back(median(b)), t.cached_us.push_back(median(c));
  t.ours_planes.push_back(static_cast<double>(planes_ours)), t.anchor_planes.push_back(static_cast<double>(planes_anchor));
  t.points.push_back(static_cast<double>(s.points.size()));
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

struct ClassRow {
  const SegmentClass* k;
  std::size_t segments;
  Timings t;
  Checks checks;
};

void printHeader(std::FILE* out) {
  std::fprintf(out, "%-14s %4s %6s | %8s %8s | %8s %8s | %6s %6s | %8s %6s | %6s %6s | %s\n", "class", "segs", "points",
               "ours_med", "ours_p90", "anc_med", "anc_p90", "ratio", "r_p90", "ancC_med", "ratioC", "pl_our", "pl_anc",
               "target >= 2x");
}

void printRow(std::FILE* out, const ClassRow& r) {
  const double om = median(r.t.ours_us), am = median(r.t.anchor_us), cm = median(r.t.cached_us);
  const double op = quantile(r.t.ours_us, 0.9), ap = quantile(r.t.anchor_us, 0.9);
  std::fprintf(out, "%-14s %4zu %6.0f | %8.2f %8.2f | %8.2f %8.2f | %5.1fx %5.1fx | %8.2f %5.1fx | %6.1f %6.1f | %s\n",
               r.k->name, r.segments, mean(r.t.points), om, op, am, ap, am / om, ap / op, cm, cm / om, mean(r.t.ours_planes),
               mean(r.t.anchor_planes), am >= 2.0 * om ? "met" : "NOT met");
}

void printChecks(std::FILE* out, const std::vector<ClassRow>& rows) {
  std::fprintf(out, "\nchecks before timing (anchor: both ends inside, no fed point strictly inside; ours: no fed point inside;\n"
                    "ellipsoid semi-axes of ours vs the anchor where both saw the same points, L/2 <= box margin):\n");
  for (const ClassRow& r : rows) {
    std::fprintf(out, "  %-14s anchor invalid %d, ours invalid %d of %zu; ellipsoids equal (< 1e-6 m) %d of %d, max diff %.2e m%s%s\n",
                 r.k->name, r.checks.anchor_invalid, r.checks.ours_invalid, r.segments, r.checks.axes_agree, r.checks.compared,
                 r.checks.max_axes_diff_m, r.checks.first_problem.empty() ? "" : "; ", r.checks.first_problem.c_str());
  }
}

void printClasses(std::FILE* out, const std::vector<ClassRow>& rows) {
  std::fprintf(out, "classes:\n");
  for (const ClassRow& r : rows) std::fprintf(out, "  %-14s %s\n", r.k->name, r.k->what);
}

void printReport(std::FILE* out, const std::vector<ClassRow>& rows, const BenchSetup& S, int reps) {
  std::fprintf(out, "corridor of one segment, microseconds of CPU time (the thread's): median / p90 over the class's segments of\n"
                    "each segment's median of %d builds; ours: CorridorBuilder (clearance %.2f m, box margin %.1f m: config/planner.yaml); anchor: DecompUtil's\n"
                    "LineSegment::dilate(0) (local box %.1f m, planes through the points), ancC: the anchor keeping C^-1 instead of\n"
                    "inverting it per distance; ratio = anchor / ours; pl_*: mean rows (incl. the 6 box planes); points: fed per segment\n\n",
               reps, S.ours.clearance_m, S.ours.local_box_margin_m.x(), S.anchor_bbox_m.x());
  printHeader(out);
  for (const ClassRow& r : rows) printRow(out, r);
  printChecks(out, rows);
  printClasses(out, rows);
}


std::string utcNow() {
  const std::time_t now = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return buf;
}

bool writeResultsPage(const std::string& path, const std::vector<ClassRow>& rows, const BenchSetup& S, int reps,
                      const std::string& command, const std::string& load_before, const std::string& load_after) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) return false;
  std::fprintf(f, "# Results: corridors against the DecompUtil anchor (issue 38)\n\n"
                  "Written by `%s` on %s (%s, %u hardware threads; load average %s before, %s after; the times are the\n"
                  "thread's CPU time, which a loaded machine inflates much less than wall time, and the builds are\n"
                  "interleaved so that both see the same machine). Both are fed the\n"
                  "same pre-cropped voxel centres of config/scenarios/power_towers.yaml per segment. What is compared and\n"
                  "why: [planning.md](../planning.md) §3 \"Speed\"; the anchor: `bench/decomp_reference.hpp`.\n\n```\n",
               command.c_str(), utcNow().c_str(), cpuModel().c_str(), std::thread::hardware_concurrency(), load_before.c_str(),
               load_after.c_str());
  printReport(f, rows, S, reps);
  std::fprintf(f, "```\n");
  return std::fclose(f) == 0;
}

std::optional<BenchSetup> loadSetup() {
  auto scenario = loadScenario(source("config/scenarios/power_towers.yaml"));
  auto planner = loadPlannerConfig(source("config/planner.yaml"), common::ConfigReader::MissingKeys::kError);
  if (!scenario || !planner) {
    std::fprintf(stderr, "gf_bench_corridors: cannot load the configs (run from the source tree or set GF_SOURCE_DIR):\n%s%s\n",
                 scenario ? "" : scenario.reason().c_str(), planner ? "" : planner.reason().c_str());
    return std::nullopt;
  }
  auto map = OccupancyMap::fromScenario(*scenario);
  if (!map) return std::nullopt;
  CorridorConfig cc;  // as UavPlanner's constructor
  cc.clearance_m = planner->obstacle_clearance_m;
  cc.local_box_margin_m = Eigen::Vector3d::Constant(planner->corridor_box_margin_m);
  cc.seed_margin_m = planner->corridor_margin_m + 0.02;
  return BenchSetup{std::move(*map), cc, Eigen::Vector3d::Constant(planner->corridor_box_margin_m)};
}

int run(int n, int reps, std::uint64_t seed, const std::string& results, const std::string& command) {
  const std::string load_before = loadAverage();
  const auto setup = loadSetup();
  if (!setup) return 2;
  const CorridorBuilder ours(setup->ours);
  std::vector<ClassRow> rows;
  const auto classes = segmentClasses();
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const auto segments = drawSegments(classes[i], *setup, n, seed + i);
    ClassRow row{&classes[i], segments.size(), {}, {}};
    for (const Segment& s : segments) checkSegment(s, *setup, ours, row.checks);
    if (row.checks.anchor_invalid > 0 || row.checks.ours_invalid > 0) {
      std::fprintf(stderr, "gf_bench_corridors: class %s: %s; not timed\n", classes[i].name, row.checks.first_problem.c_str());
      return 1;
    }
    for (const Segment& s : segments) timeSegment(s, *setup, ours, reps, row.t);
    rows.push_back(std::move(row));
  }
  const std::string load_after = loadAverage();
  printReport(stdout, rows, *setup, reps);
  std::printf("load average %s before, %s after\n", load_before.c_str(), load_after.c_str());
  if (!results.empty() && !writeResultsPage(results, rows, *setup, reps, command, load_before, load_after)) {
    std::fprintf(stderr, "gf_bench_corridors: cannot write %s\n", results.c_str());
    return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int n = 60, reps = 15;
  std::uint64_t seed = 38;
  std::string results, command = "gf_bench_corridors";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (std::strcmp(argv[i], "--segments") == 0 && has_value) {
      n = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--reps") == 0 && has_value) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--seed") == 0 && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (std::strcmp(argv[i], "--results") == 0 && has_value) {
      results = argv[++i];
    } else {
      std::fprintf(stderr, "gf_bench_corridors: unknown or incomplete option '%s' "
                           "([--segments N] [--reps R] [--seed S] [--results FILE.md])\n", argv[i]);
      return 2;
    }
  }
  return run(n, reps, seed, results, command);
}
