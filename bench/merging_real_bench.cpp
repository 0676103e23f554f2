// Merging maps that robots built: fleetmap's `merge` beside the feature-based peer of the ROS
// `multirobot_map_merge` package, on the same pairs, as a program that prints markdown for
// bench/README.md (and, with --csv, one row per pair and method). Long on purpose: building the
// robot maps, cutting the pairs, the peer and the diagnosis belong to this one measurement.
//
// The maps: one simulated robot explores each of the floor plans of HouseExpo (Li et al. 2019,
// ../shared/datasets/houseexpo) with visible odometry noise, a noisy laser of 180 to 720 beams
// (ray fans at range) and `scan-matching` or `rbpf` localization, so its map has the thin broken
// walls, speckle and drift of a real one; the maps are cached in --cache. Plans too small to fill
// a 300-cell window at 0.05 m are explored at 0.025 m. With --furniture the plans are furnished
// first (Furnisher: boxes at walls, table and chair legs, discs), as real rooms are. The built-in
// `campus` (1200 x 1200 at 0.1 m) gives the 1000 x 1000 windows, and campus at 0.025 m the
// 4000 x 4000 ones.
//
// The pairs (the protocol of the ROS comparison): window `a` is axis-aligned; window `b`, of the
// same size, is turned by a uniform random angle and shifted until the stated share of the known
// cells of the smaller of the two lies in both (merging::OverlapMeasure::Known). Each window then
// gets its own clutter (specks and small blobs on free space: people, chairs moved between the
// two visits). Unrelated pairs: windows of two different plans. Success: merged, and b's known
// cells lie on average within 2 cells of where the truth puts them (the error reported). A wrong
// merge is any other merge.
//
// The peer, as `multirobot_map_merge` (Horner 2016) does it with OpenCV: the grid's raw
// occupancy values as an image (free 0, occupied 100, unknown 255), ORB (1500 features, scale
// 1.3, 5 levels: its OrbFeaturesFinder), nearest two descriptors with Lowe's ratio test both ways
// (match_conf 0.3: ratio 0.7; BestOf2NearestMatcher), cv::estimateAffinePartial2D with RANSAC
// (3 pixels), and the confidence inliers / (8 + 0.3 matches) of Brown & Lowe 2007, accepted at
// 1.0 (its `estimation_confidence` default). Its rule that zeroes a confidence above 3 (images
// too alike, from panorama stitching) is left out, in the peer's favour.
//
// --real-maps: windows of maps the user gives (real laser maps: map_server YAML, PGM, PNG), cut as
// above but without added clutter (set "real300", or "realN" with --real-window N), and unrelated
// pairs of windows of two of them (of two resolutions: aligned as `fleetmap merge` aligns them,
// merging::align_across_resolutions). They are loaded first, and the HouseExpo maps only when a set of
// house pairs is asked for. --real-coarsen F sees them through cells F times larger
// (mapping::coarsen), as a robot mapping at F times the cell size would: the check at another
// resolution. --real-mixed F makes each real pair one of two resolutions, as `fleetmap merge` gets from
// two robots mapping at different cell sizes: the second window is seen through cells F times
// larger, pooled on its own lattice (turned with the window and shifted by a random 0..F-1 cells),
// and the pair aligned as `fleetmap merge` aligns maps of two resolutions
// (merging::align_across_resolutions); errors are in the coarse cells. --two-robots-mixed F does
// the same to the second robot's window of each pair of two robots' maps.
//
// Times are the thread's CPU time per pair (alignment only; windows are cut outside the timing),
// with OpenCV held to one thread.
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "core/memory.h"
#include "core/random.h"
#include "mapping/occupancy_grid.h"
#include "maps/builtin_maps.h"
#include "io/map_io.h"
#include "merging/evaluation.h"
#include "merging/merge.h"
#include "merging/resolutions.h"
#include "sim/simulation.h"
#include "bench/merging_bench_support.h"

namespace {

using namespace fleetmap;
using bench::orb_peer;
using bench::PeerResult;
using bench::thread_seconds;
namespace fs = std::filesystem;

// --- options -------------------------------------------------------------------------------

struct Args {
  fs::path plans = fs::path(FLEETMAP_SOURCE_DIR) / ".." / "shared" / "datasets" / "houseexpo";
  fs::path cache = fs::path(FLEETMAP_BINARY_DIR) / "merging_real_cache";
  std::string csv;
  std::string diagnose;      // writes, per pair with a truth not merged right, where the right answer drops out and why (ambiguity_class)
  fs::path dump;             // writes each pair's maps here (a_<k>.png, b_<k>.png) when given
  std::vector<int> only;     // run only these pair numbers (as in the CSV)
  int pairs = 40;            // 300 x 300 pairs per overlap
  int campus_pairs = 10;     // 1000 x 1000 pairs per overlap
  int unrelated = 200;       // pairs of windows of different plans
  int large_pairs = 4;       // 4000 x 4000 pairs (time)
  int two_robots = 10;       // 300 x 300 pairs per overlap with a and b from two robots' maps of one plan
  int two_robots_mixed = 1;  // the second robot's window seen through cells this many times larger
  std::vector<std::string> real_maps;  // maps of the user's (real laser maps: PNG, PGM + YAML, or built-in names)
  int real_pairs = 10;       // pairs per real map and overlap
  int real_window = 300;     // their windows' side, cells
  int real_coarsen = 1;      // the real maps seen through cells this many times larger
  int real_mixed = 1;        // the second window of each real pair mapped at this many times the cell size
  int real_unrelated = 100;  // pairs of windows of two different real maps (with two or more)
  std::vector<double> overlaps = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9};
  std::string method = "auto";
  double min_confidence = merging::MergeOptions{}.min_confidence;
  int coarse_candidates = merging::MergeOptions{}.coarse_candidates;
  int fine_candidates = merging::MergeOptions{}.fine_candidates;
  bool peer = true;
  bool default_allocator = false;  // leave the C library's defaults instead of core::keep_freed_memory (as `fleetmap` sets)
  double clutter = 1.0;      // scales the clutter rates (0: none)
  double furniture = 0.0;    // one piece of furniture per this many m² of floor (0: the bare plans)
  std::uint64_t seed = 1;
  int build_part = -1, build_parts = 0;  // --build-maps K/N: only build the cached maps of plans K, K + N, ... and stop
};

constexpr const char* kUsage =
    "usage: fleetmap_bench_merging_real [--plans DIR] [--cache DIR] [--csv FILE] [--diagnose FILE] [--dump DIR] [--only K,...] [--pairs N]\n"
    "       [--campus-pairs N] [--unrelated N] [--large-pairs N] [--two-robots N] [--two-robots-mixed F] [--overlaps 0.1,0.5,...]\n"
    "       [--real-maps MAP,...] [--real-pairs N] [--real-window CELLS] [--real-coarsen F] [--real-mixed F]\n"
    "       [--real-unrelated N]\n"
    "       [--method auto] [--min-confidence C] [--coarse-candidates N] [--fine-candidates N] [--no-peer] [--clutter SCALE] [--furniture M2] [--seed S] [--build-maps K/N]\n"
    "       [--default-allocator]\n";

[[noreturn]] void usage(const std::string& problem) {
  std::cerr << "fleetmap_bench_merging_real: " << problem << "\n" << kUsage;
  std::exit(2);
}

Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--help" || k == "-h") {
      std::cout << "The merging benchmark of robot-built maps (bench/README.md, \"Merging robot-built maps\").\n" << kUsage;
      std::exit(0);
    }
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(k + " needs a value");
      return argv[++i];
    };
    // The comma-separated items of the value ("a,b,c").
    const auto list = [&]() -> std::vector<std::string> {
      try {
        return core::split_list(value(), k);
      } catch (const InputError& e) {
        usage(e.what());
      }
    };
    const auto number = [&](const std::string& v) {
      try {
        return std::stod(v);
      } catch (const std::exception&) {
        usage(k + ": '" + v + "' is not a number");
      }
    };
    // A whole number from `least` to `most` (a cell-size factor, a number of candidates).
    const auto whole = [&](int least, int most) {
      const std::string v = value();
      const double n = number(v);
      if (!(n >= least && n <= most && n == std::floor(n)))
        usage(k + ": '" + v + "' is not a whole number from " + std::to_string(least) + " to " + std::to_string(most));
      return int(n);
    };
    if (k == "--plans") a.plans = value();
    else if (k == "--cache") a.cache = value();
    else if (k == "--csv") a.csv = value();
    else if (k == "--dump") a.dump = value();
    else if (k == "--diagnose") a.diagnose = value();
    else if (k == "--only") {
      for (const auto& item : list()) a.only.push_back(int(number(item)));
    }
    else if (k == "--pairs") a.pairs = int(number(value()));
    else if (k == "--campus-pairs") a.campus_pairs = int(number(value()));
    else if (k == "--unrelated") a.unrelated = int(number(value()));
    else if (k == "--large-pairs") a.large_pairs = int(number(value()));
    else if (k == "--two-robots") a.two_robots = int(number(value()));
    else if (k == "--real-maps") a.real_maps = list();
    else if (k == "--real-pairs") a.real_pairs = int(number(value()));
    else if (k == "--real-window") {
      const std::string v = value();
      a.real_window = int(number(v));
      if (a.real_window < 50) usage("--real-window: '" + v + "' is under 50 cells");
    }
    else if (k == "--real-coarsen") a.real_coarsen = whole(1, 64);
    else if (k == "--real-mixed") a.real_mixed = whole(1, 16);
    else if (k == "--two-robots-mixed") a.two_robots_mixed = whole(1, 16);
    else if (k == "--real-unrelated") a.real_unrelated = int(number(value()));
    else if (k == "--method") a.method = value();
    else if (k == "--min-confidence") a.min_confidence = number(value());
    else if (k == "--coarse-candidates") a.coarse_candidates = whole(1, 1000);
    else if (k == "--fine-candidates") a.fine_candidates = whole(1, 1000);
    else if (k == "--no-peer") a.peer = false;
    else if (k == "--default-allocator") a.default_allocator = true;
    else if (k == "--clutter") a.clutter = number(value());
    else if (k == "--furniture") {
      const std::string v = value();
      a.furniture = number(v);
      if (a.furniture < 0.0) usage("--furniture: '" + v + "' is negative (0: bare plans)");
    }
    else if (k == "--seed") a.seed = std::uint64_t(number(value()));
    else if (k == "--build-maps") {
      const std::string v = value();
      const std::size_t slash = v.find('/');
      if (slash == std::string::npos) usage("--build-maps: '" + v + "' is not K/N");
      a.build_part = int(number(v.substr(0, slash)));
      a.build_parts = int(number(v.substr(slash + 1)));
      if (a.build_parts < 1 || a.build_part < 0 || a.build_part >= a.build_parts) usage("--build-maps: '" + v + "' needs 0 <= K < N");
    }
    else if (k == "--overlaps") {
      a.overlaps.clear();
      for (const auto& item : list()) a.overlaps.push_back(number(item));
    } else usage("unknown option " + k);
  }
  return a;
}


// --- robot-built maps ---------------------------------------------------------------------

// How one plan is explored: drawn from the plan's index, so the set is the same on every run.
struct MapRecipe {
  double resolution = 0.05;
  int beams = 360;
  double max_range = 8.0;
  double range_noise = 0.02;
  double motion_noise = 0.02;       // m per step
  double heading_noise_deg = 1.0;   // per step
  std::string localization = "scan-matching";
  std::string text() const {
    return fmt::format("{} m cells, {} beams to {} m (sigma {:.3f} m), odometry noise {:.3f} m / {:.2f} deg per step, {}",
                       resolution, beams, max_range, range_noise, motion_noise, heading_noise_deg, localization);
  }
};

MapRecipe recipe_for(int index, std::int64_t free_cells) {
  core::Random r(7000 + std::uint64_t(index));
  MapRecipe m;
  // A window of 300 cells at 0.05 m is 15 m: small flats are explored at 0.025 m so that windows
  // still show rooms, as a finer SLAM grid would.
  m.resolution = free_cells >= 40000 ? 0.05 : 0.025;
  const int beams[] = {180, 360, 720};
  m.beams = beams[r.uniform_int(0, 2)];
  m.max_range = r.bernoulli(0.5) ? 4.0 : 8.0;
  m.range_noise = r.uniform(0.01, 0.04);
  m.motion_noise = r.uniform(0.01, 0.03);
  m.heading_noise_deg = r.uniform(0.5, 1.5);
  m.localization = index % 5 == 4 ? "rbpf" : "scan-matching";
  return m;
}

// Every cell split into factor x factor cells.
mapping::OccupancyGrid refine_grid(const mapping::OccupancyGrid& g, int factor) {
  const auto& geo = g.geometry();
  mapping::OccupancyGrid out(core::GridGeometry(geo.resolution() / factor, geo.width() * factor, geo.height() * factor,
                                                geo.origin()),
                             g.options());
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) out.set_log_odds({x, y}, g.log_odds({x / factor, y / factor}));
  return out;
}

// --- furniture ------------------------------------------------------------------------------

// 255 where the grid is free, 0 elsewhere (rows as the grid's rows).
cv::Mat free_mask(const mapping::OccupancyGrid& g) {
  cv::Mat free(g.height(), g.width(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x)
      if (g.state({x, y}) == mapping::CellState::Free) free.at<std::uint8_t>(y, x) = 255;
  return free;
}

// Furniture as a laser 20-30 cm above the floor sees it, so that both robots' maps of a plan show
// what real laser maps of rooms show beyond the walls (HouseExpo's plans are bare walls): cabinets,
// shelves, beds, sofas, counters as solid boxes, mostly with their back to a wall; tables and chairs
// as their four legs; bins, pots and round tables' bases as discs. About one piece per
// `m2_per_piece` square metres of free floor, drawn from the plan's index (the same in both robots'
// maps). A piece is kept only if the floor where a robot of radius 0.25 m fits falls into no more
// regions than before and loses no more than the piece's own surroundings: no doorway or corridor
// is closed or narrowed below 0.5 m.
class Furnisher {
 public:
  Furnisher(mapping::OccupancyGrid& truth, std::uint64_t seed)
      : g_(truth), random_(seed), res_(truth.resolution()), occupied_(free_mask(truth) == 0), reach_(reach(occupied_)) {}

  // Places the pieces; returns how many were kept.
  int furnish(double m2_per_piece) {
    const double free_m2 = double(cv::countNonZero(occupied_ == 0)) * res_ * res_;
    const int wanted = int(std::lround(free_m2 / m2_per_piece));
    int kept = 0;
    for (int attempt = 0; attempt < 30 * wanted && kept < wanted; ++attempt) {
      const cv::Point2d c = random_free_point();
      cv::Mat piece(occupied_.size(), CV_8U, cv::Scalar(0));
      double reach_m = 0.0;  // the piece's extent, for what a robot may lose around it
      const double kind = random_.uniform();
      if (kind < 0.45) {
        if (!box_at_wall(piece, c, reach_m)) continue;
      } else if (kind < 0.55) {
        reach_m = box(piece, c, random_.uniform(0.5, 2.0), random_.uniform(0.4, 1.0), axis_or_any_angle(0.8));
      } else if (kind < 0.72) {
        reach_m = table_with_chairs(piece, c);
      } else if (kind < 0.85) {
        reach_m = legs(piece, c, 0.42, 0.42, random_.uniform(0.0, std::numbers::pi));
      } else {
        const double r = random_.uniform(0.08, 0.25);
        cv::circle(piece, cv::Point(int(std::lround(c.x)), int(std::lround(c.y))), std::max(0, int(std::lround(r / res_))), 255, cv::FILLED);
        reach_m = 2.0 * r;
      }
      if (!try_place(piece, reach_m)) continue;
      ++kept;
    }
    for (int y = 0; y < g_.height(); ++y)
      for (int x = 0; x < g_.width(); ++x)
        if (occupied_.at<std::uint8_t>(y, x) && g_.state({x, y}) == mapping::CellState::Free) g_.set_state({x, y}, mapping::CellState::Occupied);
    return kept;
  }

 private:
  static constexpr double kRobotRadius = 0.25;

  // Where a robot of kRobotRadius fits: its area in cells, and its regions of 0.25 m² or more.
  struct Reach {
    int area = 0;
    int regions = 0;
  };
  Reach reach(const cv::Mat& occupied) const {
    cv::Mat clearance, fits, labels, stats, centroids;
    cv::distanceTransform(occupied == 0, clearance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    fits = clearance > kRobotRadius / res_;
    const int n = cv::connectedComponentsWithStats(fits, labels, stats, centroids, 8, CV_32S);
    Reach r;
    for (int i = 1; i < n; ++i) {
      const int area = stats.at<int>(i, cv::CC_STAT_AREA);
      r.area += area;
      r.regions += double(area) * res_ * res_ >= 0.25;
    }
    return r;
  }

  cv::Point2d random_free_point() {
    for (;;) {
      const int x = random_.uniform_int(0, g_.width() - 1), y = random_.uniform_int(0, g_.height() - 1);
      if (!occupied_.at<std::uint8_t>(y, x)) return {x + random_.uniform(-0.5, 0.5), y + random_.uniform(-0.5, 0.5)};
    }
  }

  // Rooms are mostly square to the plan: a piece is turned by a multiple of 90 degrees with
  // probability `p_axis`, otherwise by any angle.
  double axis_or_any_angle(double p_axis) {
    return random_.bernoulli(p_axis) ? 0.5 * std::numbers::pi * random_.uniform_int(0, 3) : random_.uniform(0.0, std::numbers::pi);
  }

  // A solid box of w x d metres centred at c (cells), turned by `angle`; returns its extent (m).
  double box(cv::Mat& piece, const cv::Point2d& c, double w, double d, double angle) const {
    const cv::RotatedRect r(cv::Point2f(float(c.x), float(c.y)), cv::Size2f(float(w / res_), float(d / res_)), float(core::rad2deg(angle)));
    cv::Point2f p[4];
    r.points(p);
    std::vector<cv::Point> poly;
    for (const auto& q : p) poly.emplace_back(int(std::lround(q.x)), int(std::lround(q.y)));
    cv::fillConvexPoly(piece, poly, 255);
    return std::max(w, d);
  }

  // A box with its back to the nearest wall along one of the four axis directions within 1 m of c.
  bool box_at_wall(cv::Mat& piece, const cv::Point2d& c, double& reach_m) {
    const int dx[] = {1, -1, 0, 0}, dy[] = {0, 0, 1, -1};
    int best_dir = -1, best_steps = int(1.0 / res_) + 1;
    for (int k = 0; k < 4; ++k) {
      for (int s = 1; s < best_steps; ++s) {
        const int x = int(std::lround(c.x)) + s * dx[k], y = int(std::lround(c.y)) + s * dy[k];
        if (x < 0 || y < 0 || x >= occupied_.cols || y >= occupied_.rows) break;
        if (occupied_.at<std::uint8_t>(y, x)) {
          best_dir = k, best_steps = s;
          break;
        }
      }
    }
    if (best_dir < 0) return false;
    const double w = random_.uniform(0.4, 2.0), d = random_.uniform(0.3, 0.9);
    // The box's centre: half its depth out from the wall face, along the way back to c.
    const double face = best_steps - 1.0;  // the back's cells end next to the wall's
    const cv::Point2d from(std::lround(c.x), std::lround(c.y));
    const cv::Point2d centre(from.x + dx[best_dir] * (face - 0.5 * d / res_), from.y + dy[best_dir] * (face - 0.5 * d / res_));
    const double angle = dx[best_dir] != 0 ? 0.5 * std::numbers::pi : 0.0;  // width along the wall
    reach_m = box(piece, centre, w, d, angle);
    return true;
  }

  // Four legs (0.05 m) at the corners of a w x d rectangle centred at c; returns its extent (m).
  double legs(cv::Mat& piece, const cv::Point2d& c, double w, double d, double angle) const {
    const int side = std::max(1, int(std::lround(0.05 / res_)));
    const double ca = std::cos(angle), sa = std::sin(angle);
    for (const double u : {-0.5, 0.5})
      for (const double v : {-0.5, 0.5}) {
        const double px = c.x + (u * w * ca - v * d * sa) / res_, py = c.y + (u * w * sa + v * d * ca) / res_;
        const int x0 = int(std::lround(px - 0.5 * (side - 1))), y0 = int(std::lround(py - 0.5 * (side - 1)));
        cv::rectangle(piece, cv::Rect(x0, y0, side, side), 255, cv::FILLED);
      }
    return std::hypot(w, d);
  }

  // A table's legs and up to four chairs' legs around it.
  double table_with_chairs(cv::Mat& piece, const cv::Point2d& c) {
    const double w = random_.uniform(0.6, 1.8), d = random_.uniform(0.6, 1.0), angle = axis_or_any_angle(0.8);
    legs(piece, c, w, d, angle);
    const double ca = std::cos(angle), sa = std::sin(angle);
    const int chairs = random_.uniform_int(0, 4);
    for (int k = 0; k < chairs; ++k) {
      // Beside one of the four sides, 0.35 m out, turned a little.
      const int side = random_.uniform_int(0, 3);
      const double u = side < 2 ? (side == 0 ? -1.0 : 1.0) * (0.5 * w + 0.35) : random_.uniform(-0.3, 0.3) * w;
      const double v = side >= 2 ? (side == 2 ? -1.0 : 1.0) * (0.5 * d + 0.35) : random_.uniform(-0.3, 0.3) * d;
      const cv::Point2d chair(c.x + (u * ca - v * sa) / res_, c.y + (u * sa + v * ca) / res_);
      legs(piece, chair, 0.42, 0.42, angle + random_.uniform(-0.3, 0.3));
    }
    return std::hypot(w, d) + 1.2;
  }

  // Keeps the piece if it lies on free floor (inside the plan) and closes no way: the floor where a
  // robot fits is in no more regions than before and smaller by at most the piece's surroundings.
  bool try_place(const cv::Mat& piece, double reach_m) {
    if (cv::countNonZero(piece) == 0 || cv::countNonZero(piece & occupied_) > 0) return false;
    // Nor touch the map's border (walls and unknown space are in occupied_).
    if (cv::countNonZero(piece.row(0)) || cv::countNonZero(piece.row(piece.rows - 1)) || cv::countNonZero(piece.col(0)) ||
        cv::countNonZero(piece.col(piece.cols - 1)))
      return false;
    cv::Mat after = occupied_ | piece;
    const Reach r = reach(after);
    const double around = (reach_m + 2.0 * kRobotRadius) / res_;
    if (r.regions > reach_.regions || double(reach_.area - r.area) > 1.3 * around * around) return false;
    occupied_ = after;
    reach_ = r;
    return true;
  }

  mapping::OccupancyGrid& g_;
  core::Random random_;
  double res_;
  cv::Mat occupied_;  // 255: wall, unknown, or furniture placed so far
  Reach reach_;
};

// A start in the largest free region of the plan, at least 0.4 m from walls (a random start may
// fall in a closet-sized pocket between walls), drawn with `random`.
core::Pose2 start_in_largest_room(const mapping::OccupancyGrid& truth, core::Random& random) {
  const cv::Mat free = free_mask(truth);
  cv::Mat labels, stats, centroids, clearance;
  const int n = cv::connectedComponentsWithStats(free, labels, stats, centroids, 4, CV_32S);
  int best = 1;
  for (int i = 2; i < n; ++i)
    if (stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
  cv::distanceTransform(free, clearance, cv::DIST_L2, 3);
  std::vector<core::Cell> cells;
  const double min_clearance = 0.4 / truth.resolution();
  for (int y = 0; y < truth.height(); ++y)
    for (int x = 0; x < truth.width(); ++x)
      if (labels.at<int>(y, x) == best && clearance.at<float>(y, x) >= min_clearance) cells.push_back({x, y});
  if (cells.empty()) throw Error("no free place 0.4 m from walls for a robot to start");
  const core::Cell c = cells[std::size_t(random.uniform_int(0, int(cells.size()) - 1))];
  const Eigen::Vector2d p = truth.geometry().cell_center(c);
  return {p.x(), p.y(), random.uniform(-std::numbers::pi, std::numbers::pi)};
}

struct PlanMap {
  std::string id;
  MapRecipe recipe;
  mapping::OccupancyGrid map;
  double position_rmse_m = 0.0;
  double coverage = 0.0;
};

constexpr const char* kCacheVersion = "v2";

// The plan as the robots explore it: on cells of the recipe's size, furnished when `m2_per_piece` > 0
// (the same furniture for every robot).
mapping::OccupancyGrid simulated_plan(const fs::path& plan_yaml, int index, double m2_per_piece) {
  mapping::OccupancyGrid truth = io::load_map(plan_yaml);
  const MapRecipe recipe = recipe_for(index, truth.count(mapping::CellState::Free));
  if (recipe.resolution < truth.resolution() - 1e-9) truth = refine_grid(truth, int(std::lround(truth.resolution() / recipe.resolution)));
  if (m2_per_piece > 0.0) Furnisher(truth, 11000 + std::uint64_t(index)).furnish(m2_per_piece);
  return truth;
}

// `robot` 0 and 1: two robots exploring the same plan alone, from different starts with different
// noise (the second map of a plan, for pairs of two robots' maps).
// `m2_per_piece` > 0: the plan furnished first (Furnisher), the same furniture for both robots.
PlanMap build_plan_map(const fs::path& plan_yaml, int index, int robot, const fs::path& cache, double m2_per_piece) {
  PlanMap p{plan_yaml.stem().string(), {}, mapping::OccupancyGrid(core::GridGeometry(0.05, 1, 1)), 0.0, 0.0};
  const std::string furnished = m2_per_piece > 0.0 ? fmt::format("-f{:g}", m2_per_piece) : "";
  const fs::path stem = cache / fmt::format("{}-{}{}{}", p.id, kCacheVersion, furnished, robot == 0 ? "" : "-r2");
  p.recipe = recipe_for(index, io::load_map(plan_yaml).count(mapping::CellState::Free));
  if (fs::exists(stem.string() + ".yaml") && fs::exists(stem.string() + ".txt")) {
    p.map = io::load_map(stem.string() + ".yaml");
    std::ifstream in(stem.string() + ".txt");
    in >> p.position_rmse_m >> p.coverage >> p.recipe.beams;
    return p;
  }
  const mapping::OccupancyGrid truth = simulated_plan(plan_yaml, index, m2_per_piece);
  // The explorer stops at once when sparse far beams leave no frontier it can use (seen with
  // 180 beams on 0.025 m cells): such a plan is explored again with twice the beams.
  core::Random start_random(9000 + std::uint64_t(index) + 1000 * std::uint64_t(robot));
  const core::Pose2 start = start_in_largest_room(truth, start_random);
  for (;;) {
    sim::Scenario s;
    s.map = plan_yaml.string();
    s.seed = std::uint64_t(index) + 1 + 1000 * std::uint64_t(robot);
    s.robot_count = 1;
    s.placement = sim::Placement::List;
    s.starts = {start};
    s.noise.position_m = p.recipe.motion_noise;
    s.noise.heading_rad = core::deg2rad(p.recipe.heading_noise_deg);
    s.range.beams = p.recipe.beams;
    s.range.max_range_m = p.recipe.max_range;
    s.range.noise_m = p.recipe.range_noise;
    s.localization = p.recipe.localization;
    s.localization_settings = localization::localizer_registry().declared(s.localization, {{"particles", "15"}});
    s.steps = 1500;
    sim::Simulation simulation(s, truth);
    const sim::RunResult r = simulation.run();
    p.map = r.robot_maps.front();
    const auto& t = r.robots.front();
    double se = 0.0;
    for (std::size_t k = 0; k < t.truth.size(); ++k) se += (t.truth[k].position() - t.estimate[k].position()).squaredNorm();
    p.position_rmse_m = t.truth.empty() ? 0.0 : std::sqrt(se / double(t.truth.size()));
    p.coverage = r.coverage.empty() ? 0.0 : r.coverage.back();
    if (p.coverage >= 0.8 || p.recipe.beams >= 1440) break;
    p.recipe.beams *= 2;
  }
  fs::create_directories(cache);
  io::save_map_yaml(p.map, stem.string() + ".yaml");
  std::ofstream(stem.string() + ".txt") << p.position_rmse_m << " " << p.coverage << " " << p.recipe.beams << "\n";
  return p;
}

// --- clutter --------------------------------------------------------------------------------

// What changes between two visits and what a laser sees wrongly: occupied specks on free space
// (rate per free cell) and small blobs (a person's legs, a chair: 2-9 cells) on free space.
void add_clutter(mapping::OccupancyGrid& g, double speck_rate, double blobs_per_1000_free, core::Random& random) {
  std::vector<core::Cell> free;
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x)
      if (g.state({x, y}) == mapping::CellState::Free) free.push_back({x, y});
  if (free.empty()) return;
  for (const auto& c : free)
    if (random.bernoulli(speck_rate)) g.set_state(c, mapping::CellState::Occupied);
  const int blobs = int(std::lround(blobs_per_1000_free * double(free.size()) / 1000.0));
  for (int i = 0; i < blobs; ++i) {
    const core::Cell c = free[std::size_t(random.uniform_int(0, int(free.size()) - 1))];
    if (random.bernoulli(0.5)) {  // a disc
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (std::abs(dx) + std::abs(dy) <= 1 && g.contains({c.x + dx, c.y + dy})) g.set_state({c.x + dx, c.y + dy}, mapping::CellState::Occupied);
    } else {  // a short bar
      const double a = random.uniform(0.0, std::numbers::pi);
      const int len = random.uniform_int(2, 8);
      for (int k = 0; k < len; ++k) {
        const core::Cell q{int(std::lround(c.x + k * std::cos(a))), int(std::lround(c.y + k * std::sin(a)))};
        if (g.contains(q)) g.set_state(q, mapping::CellState::Occupied);
      }
    }
  }
}

double clutter_scale = 1.0;

void clutter_pair(mapping::OccupancyGrid& a, mapping::OccupancyGrid& b, core::Random& random) {
  for (auto* g : {&a, &b})
    add_clutter(*g, clutter_scale * random.uniform(0.0, 0.0005), clutter_scale * random.uniform(0.0, 0.2), random);
}

// --- pairs and records --------------------------------------------------------------------

struct Pair {
  std::string set;       // "house300", "house300x2", "real300" (real_set), "campus1000", "campus4000", "unrelated"
  std::string source;    // plan id(s)
  double overlap = 0.0;  // 0 for unrelated
  mapping::OccupancyGrid a, b;
  std::optional<core::Transform2> truth;
  // Where a success must land (mean displacement under 2 cells): the truth, or for two robots'
  // maps the best fit of the two maps next to the truth corrected by each map's drift (each map is
  // off the world by its own drift, up to a metre; drift_on_plan).
  std::optional<core::Transform2> reference;
  // Unrelated pairs: where each window lies on its own map (a's and b's cells into their maps'), so
  // that a merge says where it puts b's map on a's: the same place for several windows is a part
  // the two maps share, not a chance fit.
  std::optional<std::pair<core::Transform2, core::Transform2>> windows_on_maps;
};

// The fits of b to a next to each of `starts`: fleetmap's refinement from there, coarse to fine from
// cells of 4 x 4 fine cells, and their scores (matched walls less ten times the walls on free
// space). The two maps are prepared once for all the starts.
std::vector<std::pair<core::Transform2, double>> fits_near(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                                                           const std::vector<core::Transform2>& starts) {
  const merging::KnownPart ka(a), kb(b);
  const merging::PrepareOptions prepare = merging::prepare_options(merging::MergeOptions{});
  const merging::PreparedGrid pa(ka.grid(), prepare), pb(kb.grid(), prepare);
  const Eigen::Vector2d oa = ka.origin().cast<double>(), ob = kb.origin().cast<double>();
  std::vector<std::pair<core::Transform2, double>> out;
  for (const core::Transform2& start : starts) {
    // In the cuts' cells: cut_a = T (cut_b + ob) + t - oa.
    const core::Transform2 cut(start.translation() + start.rotation_matrix() * ob - oa, start.rotation());
    merging::MergeResult r;
    r.transform = merging::refine_alignment(pa, pb, cut, 2).b_to_a;
    const double score = merging::evaluate_alignment(pa, pb, r.transform).score;
    out.emplace_back(merging::uncut(r, ka, kb).transform, score);
  }
  return out;
}

// Where a robot's window of a plan lies on the same window of the plan itself (both in the window's
// cells): the drift of the robot's map there. fleetmap's refinement, coarse to fine from cells of
// 4 x 4 fine cells, started at the identity and at every translation on a grid of `step` cells
// within `radius` cells of it, turned by -1, 0 and 1 degrees; the fit with the highest score
// (matched walls less ten times the walls on free space) wins. The whole window against the plan
// pins its drift down however little it has in common with another robot's window; two robots'
// windows fitted to each other near the truth can land where one wall fits (seen at 90% overlap:
// 480 walls matched and 318 on free space, 13 cells from the fit with 739 and 55).
core::Transform2 drift_on_plan(const mapping::OccupancyGrid& window, const mapping::OccupancyGrid& plan_window,
                               double radius, double step) {
  const merging::PrepareOptions prepare = merging::prepare_options(merging::MergeOptions{});
  const merging::PreparedGrid plan(plan_window, prepare), robot(window, prepare);
  std::optional<core::Transform2> best;
  double best_score = 0.0;
  const int steps = int(std::floor(radius / step));
  for (int i = -steps; i <= steps; ++i) {
    for (int j = -steps; j <= steps; ++j) {
      for (const double turn : {-1.0, 0.0, 1.0}) {
        const core::Transform2 start(step * i, step * j, core::deg2rad(turn));
        const core::Transform2 fit = merging::refine_alignment(plan, robot, start, 2).b_to_a;
        const double score = merging::evaluate_alignment(plan, robot, fit).score;
        if (!best || score > best_score) best = fit, best_score = score;
      }
    }
  }
  return *best;
}

struct Outcome {
  bool merged = false;
  bool found = false;          // the answer (merged or not) is within 2 cells
  double error = -1.0;         // mean displacement of b's known cells, cells (-1: no answer or no truth)
  double confidence = 0.0;
  double cpu_s = 0.0, wall_s = 0.0;
  std::string detail;          // for the CSV
};

struct Record {
  const Pair* pair = nullptr;
  Outcome fleetmap, peer;
  std::string loss_class, alone_class;  // with --diagnose, for pairs not merged right
};

constexpr double kSuccessCells = 2.0;

Outcome run_fleetmap(const Pair& p, const merging::MergeOptions& options) {
  Outcome o;
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = thread_seconds();
  // Maps of two resolutions (--real-mixed, unrelated real maps) as `fleetmap merge` aligns them: the
  // result is between the two seen through the coarser cells.
  const bool mixed = p.a.resolution() != p.b.resolution();
  const merging::MergeResult r =
      mixed ? merging::align_across_resolutions(p.a, p.b, options) : merging::align_maps(p.a, p.b, options);
  o.cpu_s = thread_seconds() - c0;
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  o.merged = r.merged;
  o.confidence = r.confidence;
  if (p.truth && r.candidates > 0) {
    o.error = merging::mean_displacement(r.transform, p.reference.value_or(*p.truth), p.b);
    o.found = o.error < kSuccessCells;
  }
  const double coarser = std::max(p.a.resolution(), p.b.resolution());
  const merging::Acceptance acc =
      mixed ? merging::acceptance_index(mapping::resample(p.a, coarser), mapping::resample(p.b, coarser), r.transform)
            : merging::acceptance_index(p.a, p.b, r.transform);
  if (r.alternative) {
    const double dth = core::rad2deg(core::normalize_angle(r.alternative->rotation() - r.transform.rotation()));
    const double dd = merging::mean_displacement(*r.alternative, r.transform, p.b);
    o.detail = fmt::format("alternative: {:.1f} deg, {:.1f} cells;", dth, dd);
  }
  if (r.merged && p.windows_on_maps && !mixed) {
    // b's map into a's map: a's window onto its map, the answer, b's window from its map.
    const auto& [a_on_map, b_on_map] = *p.windows_on_maps;
    const core::Transform2 maps = a_on_map * r.transform * b_on_map.inverse();
    o.detail += fmt::format("maps: {:.1f} {:.1f} {:.1f} deg;", maps.translation().x(), maps.translation().y(),
                            core::rad2deg(maps.rotation()));
  }
  o.detail += fmt::format("{};agree={:.3f};accept={:.3f};constraint={:.1f};distinct={:.3f};matched={};contra={};tested={};radius={:.1f};common={};dis={};sigma={:.3f};corner={};ends={};arms={};room={};parallel={};off={};openings={};hallend={};open={};outside={:.3f};details={};{}",
                         r.method, r.quality.agreement, r.acceptance, r.quality.constraint, r.distinctiveness,
                         r.quality.matched, r.quality.contradicted, r.quality.tested, r.quality.overlap_radius,
                         acc.common(), acc.disagree, r.quality.residual_rms, r.quality.beyond_corner, r.quality.wall_ends, r.quality.junction_arms,
                         r.quality.beyond_room, r.quality.parallel_lines, r.quality.off_room_sides, r.quality.common_openings, r.quality.beyond_end, r.quality.open_space_walls, r.quality.outside_room, r.quality.room_details, r.reason);
  return o;
}

Outcome run_peer(const Pair& p) {
  Outcome o;
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = thread_seconds();
  const PeerResult r = orb_peer(p.a, p.b);
  o.cpu_s = thread_seconds() - c0;
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  o.merged = r.merged;
  o.confidence = r.confidence;
  if (p.truth && r.b_to_a) {
    o.error = merging::mean_displacement(*r.b_to_a, p.reference.value_or(*p.truth), p.b);
    o.found = o.error < kSuccessCells;
  }
  o.detail = fmt::format("matches={};inliers={}", r.matches, r.inliers);
  return o;
}

// Why a pair the run did not merge right is lost, from the oracle's decision (the truth handed in
// as a candidate beside all of the search's):
// - "determinable": the oracle merges the truth: the search missed it (or refined it elsewhere);
// - "rival-scores-higher": a wrong placement fits the walls better than the truth (the oracle's
//   answer is wrong): ambiguous on these maps by the wall score;
// - "rival-fits-as-well", "one-corner", "one-room": the truth is the answer but another placement
//   fits nearly as well without contradiction, or the common walls are one corner or the sides of
//   one room: ambiguous;
// - "little-evidence": the truth is the answer and unrivalled, but too few of its walls pin it
//   (a corridor, one wall, a bare room): weak rather than ambiguous;
// - "disagreement": the truth's own cells disagree (walls on free space, drift).
std::string ambiguity_class(bool merged, bool found, merging::Refusal refusal) {
  using merging::Refusal;
  if (merged && found) return "determinable";
  if (!found) return "rival-scores-higher";
  switch (refusal) {
    case Refusal::AnotherPlacement: return "rival-fits-as-well";
    case Refusal::OneCorner: return "one-corner";
    case Refusal::OneRoom:
    case Refusal::HallEnd: return "one-room";
    case Refusal::FreeToSlide:
    case Refusal::LittleFit: return "little-evidence";
    default: return "disagreement";
  }
}

// Where the right answer drops out: the spectral rotations' error, the rank of the first right
// candidate (within 3 degrees, and 3 cells of the search level at b's known cells) among the
// overlap search's candidates, among the sweep's, and whether refining any candidate reaches the
// truth (within 2 cells).
struct Diagnosis {
  std::string csv;         // the CSV columns after the pair's own
  std::string loss_class;  // ambiguity_class of the oracle's decision
  std::string alone_class; // ... of the truth alone
};

Diagnosis diagnose(const Pair& p, const merging::MergeOptions& options) {
  const merging::KnownPart ka(p.a), kb(p.b);
  const merging::PrepareOptions prepare = merging::prepare_options(options);
  const merging::PreparedGrid pa(ka.grid(), prepare), pb(kb.grid(), prepare);
  const core::Transform2 truth = p.reference.value_or(*p.truth);
  const Eigen::Vector2d oa = ka.origin().cast<double>(), ob = kb.origin().cast<double>();
  const core::Transform2 cut(truth.translation() + truth.rotation_matrix() * ob - oa, truth.rotation());
  double rot_err = 180.0;
  for (double r : merging::spectral_rotation_candidates(pa, pb, options.overlap))
    rot_err = std::min(rot_err, std::abs(core::rad2deg(core::normalize_angle(r - cut.rotation()))));
  const auto first_right = [&](const std::vector<merging::Hypothesis>& hs, int& refined_rank) {
    int rank = -1;
    refined_rank = -1;
    for (std::size_t i = 0; i < hs.size(); ++i) {
      const auto& h = hs[i];
      const int factor = 1 << h.level;
      const double d = merging::mean_displacement(h.b_to_a, cut, kb.grid());
      const double dth = std::abs(core::rad2deg(core::normalize_angle(h.b_to_a.rotation() - cut.rotation())));
      if (rank < 0 && dth < 3.0 && d < 3.0 * factor) rank = int(i);
      if (refined_rank < 0 && dth < 6.0 && d < 8.0 * factor) {
        const auto f = merging::refine_alignment(pa, pb, h.b_to_a, h.level, options.refinement);
        if (merging::mean_displacement(f.b_to_a, cut, kb.grid()) < kSuccessCells) refined_rank = int(i);
      }
    }
    return rank;
  };
  int ref_spec = -1, ref_sweep = -1;
  const auto spec = merging::overlap_hypotheses(pa, pb, options.overlap);
  const int r_spec = first_right(spec, ref_spec);
  merging::OverlapSearchOptions sw = options.overlap;
  sw.sweep_step_deg = options.sweep_step_deg;
  sw.search_cells = options.sweep_search_cells;
  const auto sweep = merging::overlap_hypotheses(pa, pb, sw);
  const int r_sweep = first_right(sweep, ref_sweep);
  // The right answer's own quality, refined from the truth.
  const auto f = merging::refine_alignment(pa, pb, cut, 2, options.refinement);
  const auto q = merging::evaluate_alignment(pa, pb, f.b_to_a, options.quality);
  // The oracle: the same decision with the truth handed in as one more candidate (all of auto's
  // candidates: spectral, features, sweep). What it does with the truth says whether these maps
  // determine the answer by fleetmap's own measures (ambiguity_class).
  std::vector<merging::Hypothesis> all = spec;
  core::Random random(options.seed);
  for (auto& h : merging::feature_hypotheses(pa, pb, options.features, random)) all.push_back(h);
  all.insert(all.end(), sweep.begin(), sweep.end());
  all.push_back({cut, 1e9, 0, "truth"});
  const merging::MergeResult o = merging::decide(pa, pb, all, options);
  const bool o_found = merging::mean_displacement(o.transform, cut, kb.grid()) < kSuccessCells;
  // The truth alone (its only rivals those the symmetry probes find): would it be merged if the
  // search had not proposed anything that outscores it?
  const merging::MergeResult alone = merging::decide(pa, pb, {{cut, 1e9, 0, "truth"}}, options);
  Diagnosis out{"", ambiguity_class(o.merged, o_found, o.refusal), ambiguity_class(alone.merged, true, alone.refusal)};
  out.csv = fmt::format("{:.2f},{},{},{},{},{},{},{:.1f},{},{},{:.2f},{},{},{:.3f},{:.3f},{:.1f},{},\"{}\",{},{:.3f},{}", rot_err, spec.size(), r_spec,
                     ref_spec, sweep.size(), r_sweep, ref_sweep, q.score, q.matched, q.contradicted, q.residual_rms,
                     int(o.merged), int(o_found), o.confidence, o.distinctiveness, o.evidence,
                     out.loss_class, o.reason, int(alone.merged), alone.confidence,
                     out.alone_class);
  return out;
}

bool success(const Outcome& o) { return o.merged && o.found; }
bool wrong(const Outcome& o) { return o.merged && !o.found; }

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string ms(double s) { return std::isnan(s) ? "-" : s < 0.01 ? fmt::format("{:.1f} ms", 1e3 * s) : fmt::format("{:.0f} ms", 1e3 * s); }
std::string cells(double c) { return std::isnan(c) ? "-" : fmt::format("{:.2f}", c); }

// One row: success n/N (%), wrong, median error of successes, median CPU time.
std::string summary(const std::vector<const Outcome*>& os) {
  int n = 0, ok = 0, bad = 0;
  std::vector<double> err, t;
  for (const auto* o : os) {
    ++n;
    ok += success(*o);
    bad += wrong(*o);
    if (success(*o)) err.push_back(o->error);
    t.push_back(o->cpu_s);
  }
  return fmt::format("{:.0f}% ({}/{}), {} wrong, {} c, {}", n ? 100.0 * ok / n : 0.0, ok, n, bad, cells(median(err)),
                     ms(median(t)));
}

// --- main ------------------------------------------------------------------------------------

int overlap_percent(double f) { return int(std::lround(100.0 * f)); }

// The set of the windows of --real-maps: "real300" for 300 x 300 windows.
std::string real_set(int window) { return "real" + std::to_string(window); }

// --real-mixed: b seen through cells `f` times larger on its own lattice (shifted by a random
// 0..f-1 cells); the truth between b and a seen through such cells on a's lattice (the cells of
// align_across_resolutions's result). A coarse cell X
// of b has its centre at b's fine cell f X + c + d (c = (f - 1) / 2, d the shift), and a's fine
// cell p is a's coarse cell (p - c) / f: the truth R p + t becomes R X + (R (c + d) + t - c) / f.
void mix_resolutions(mapping::OccupancyGrid& b, std::initializer_list<core::Transform2*> b_to_a, int f,
                     core::Random& random) {
  const int dx = random.uniform_int(0, f - 1), dy = random.uniform_int(0, f - 1);
  b = mapping::coarsen(merging::crop_grid(b, dx, dy, b.width() - dx, b.height() - dy), f);
  const Eigen::Vector2d c = Eigen::Vector2d::Constant((f - 1) / 2.0), d(dx, dy);
  for (core::Transform2* t : b_to_a) {
    const Eigen::Matrix2d r = t->rotation_matrix();
    *t = core::Transform2((r * (c + d) + t->translation() - c) / f, t->rotation());
  }
}

void mix_resolutions(merging::CropPair& pair, int f, core::Random& random) {
  mix_resolutions(pair.b, {&pair.b_to_a}, f, random);
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  clutter_scale = args.clutter;
  cv::setNumThreads(1);
  // Merged as the `fleetmap` program and the Python module merge: freed images kept for reuse.
  if (!args.default_allocator) core::keep_freed_memory();
  try {
    merging::MergeOptions options;
    options.method = args.method;
    options.min_confidence = args.min_confidence;
    options.coarse_candidates = args.coarse_candidates;
    options.fine_candidates = args.fine_candidates;
    merging::check_merge_method(options.method);

    // The user's maps first: a wrong path is told before the long part.
    std::vector<std::pair<std::string, mapping::OccupancyGrid>> real;
    for (const auto& name : args.real_maps)
      real.emplace_back(fs::path(name).stem().string(), mapping::coarsen(maps::load_map_source(name), args.real_coarsen));

    // The robot-built maps (only when a set of pairs needs them).
    const bool houses = args.pairs > 0 || args.two_robots > 0 || args.unrelated > 0;
    std::vector<fs::path> plans;
    if (houses || args.build_parts > 0) {
      if (!fs::is_directory(args.plans)) usage("--plans: " + args.plans.string() + " is not a folder");
      for (const auto& e : fs::directory_iterator(args.plans))
        if (e.path().extension() == ".yaml") plans.push_back(e.path());
      std::sort(plans.begin(), plans.end());
      if (plans.size() < 2) usage("--plans: " + args.plans.string() + " holds fewer than two map_server YAML plans");
    }
    std::vector<PlanMap> maps, second;
    if (args.build_parts > 0) {
      // Only fill the cache (run N of these at once, K = 0 .. N-1, to use N cores).
      for (std::size_t i = std::size_t(args.build_part); i < plans.size(); i += std::size_t(args.build_parts)) {
        std::cerr << fmt::format("maps: {}/{} {}\n", i + 1, plans.size(), plans[i].stem().string());
        build_plan_map(plans[i], int(i), 0, args.cache, args.furniture);
        if (args.two_robots > 0) build_plan_map(plans[i], int(i), 1, args.cache, args.furniture);
      }
      return 0;
    }
    for (std::size_t i = 0; houses && i < plans.size(); ++i) {
      std::cerr << fmt::format("\rmaps: {}/{} {}      ", i + 1, plans.size(), plans[i].stem().string()) << std::flush;
      maps.push_back(build_plan_map(plans[i], int(i), 0, args.cache, args.furniture));
      if (args.two_robots > 0) second.push_back(build_plan_map(plans[i], int(i), 1, args.cache, args.furniture));
    }
    std::cerr << "\n";

    std::vector<std::unique_ptr<Pair>> pairs;
    core::Random random(args.seed);
    // 300 x 300 windows of the robot maps.
    merging::CropPairOptions crop;
    crop.width = crop.height = 300;
    crop.measure = merging::OverlapMeasure::Known;
    crop.min_known = 0.25;
    crop.max_tries = 60;
    std::size_t next_plan = 0;
    for (const double f : args.overlaps) {
      crop.overlap = f;
      for (int k = 0; k < args.pairs; ++k) {
        for (std::size_t tries = 0; tries < maps.size(); ++tries) {
          const PlanMap& m = maps[next_plan++ % maps.size()];
          try {
            merging::CropPair c = merging::make_crop_pair(m.map, crop, random);
            clutter_pair(c.a, c.b, random);
            pairs.push_back(std::make_unique<Pair>(Pair{"house300", m.id, f, std::move(c.a), std::move(c.b), c.b_to_a, {}, {}}));
            break;
          } catch (const Error&) {
            // This plan has no such windows (too small for this overlap): the next one.
          }
        }
      }
    }
    // The same windows, a from one robot's map and b from another robot's map of the plan: both
    // maps are in the plan's frame, so the truth is the windows' transform (up to each map's drift).
    // Each set of pairs draws from its own stream, so that a set's pairs do not depend on the sets
    // before it (the two-robot set skips windows by a fit that runs fleetmap's refinement: with one
    // stream, a change to the refinement would change every later pair).
    random = core::Random(args.seed + 1);
    std::size_t next_two = 0;
    std::vector<std::optional<mapping::OccupancyGrid>> plan_grids(maps.size());
    for (const double f : args.overlaps) {
      crop.overlap = f;
      for (int k = 0; k < args.two_robots; ++k) {
        for (std::size_t tries = 0; tries < maps.size(); ++tries) {
          const std::size_t i = next_two++ % maps.size();
          try {
            merging::CropPair c = merging::make_crop_pair(maps[i].map, crop, random);
            mapping::OccupancyGrid b = merging::resample_grid(second[i].map, c.b_to_source, crop.width, crop.height);
            clutter_pair(c.a, b, random);
            if (!plan_grids[i]) plan_grids[i] = simulated_plan(plans[i], int(i), args.furniture);
            const double metre = 1.0 / b.resolution();
            const core::Transform2 drift_a = drift_on_plan(c.a, merging::resample_grid(*plan_grids[i], c.a_to_source, crop.width, crop.height), metre, 8.0);
            const core::Transform2 drift_b = drift_on_plan(b, merging::resample_grid(*plan_grids[i], c.b_to_source, crop.width, crop.height), metre, 8.0);
            // A map off its plan by more than 1.5 m here (a fit that did not place the window, or a
            // map bent beyond use): no reference for this window.
            if (merging::mean_displacement(drift_a, core::Transform2::identity(), c.a) > 1.5 * metre ||
                merging::mean_displacement(drift_b, core::Transform2::identity(), b) > 1.5 * metre)
              continue;
            // b's cells -> the plan's b window -> the plan's a window -> a's cells: the truth corrected
            // by both maps' drift. A map bent by its drift lies on the other a few cells off its
            // window's mean drift: the reference is the better (higher score) of the refinements of
            // the two windows on each other started there and at the truth, of those within a metre
            // of the corrected truth; none: the fit found another place, no reference for this window.
            const core::Transform2 anchored = drift_a.inverse() * c.b_to_a * drift_b;
            std::optional<core::Transform2> found;
            double found_score = 0.0;
            for (const auto& [fit, score] : fits_near(c.a, b, {anchored, c.b_to_a})) {
              if (merging::mean_displacement(fit, anchored, b) > metre) continue;
              if (!found || score > found_score) found = fit, found_score = score;
            }
            if (!found) continue;
            core::Transform2 reference = *found;
            core::Transform2 truth = c.b_to_a;
            if (args.two_robots_mixed > 1) mix_resolutions(b, {&truth, &reference}, args.two_robots_mixed, random);
            pairs.push_back(std::make_unique<Pair>(
                Pair{"house300x2", maps[i].id, f, std::move(c.a), std::move(b), truth, reference, {}}));
            break;
          } catch (const Error&) {
          }
        }
      }
    }
    // Windows of two different plans.
    merging::CropPairOptions single = crop;
    single.overlap = 0.9;
    random = core::Random(args.seed + 2);
    for (int k = 0; k < args.unrelated; ++k) {
      for (int tries = 0; tries < 100; ++tries) {
        const std::size_t i = std::size_t(random.uniform_int(0, int(maps.size()) - 1));
        const std::size_t j = std::size_t(random.uniform_int(0, int(maps.size()) - 1));
        if (i == j) continue;
        try {
          merging::CropPair ci = merging::make_crop_pair(maps[i].map, single, random);
          merging::CropPair cj = merging::make_crop_pair(maps[j].map, single, random);
          clutter_pair(ci.a, cj.b, random);
          pairs.push_back(std::make_unique<Pair>(
              Pair{"unrelated", maps[i].id + "/" + maps[j].id, 0.0, std::move(ci.a), std::move(cj.b), std::nullopt, {}, {}}));
          break;
        } catch (const Error&) {
        }
      }
    }
    // Windows of the user's maps (--real-maps), as the house windows but without added clutter:
    // real maps bring their own. Unrelated pairs: windows of two different ones.
    {
      random = core::Random(args.seed + 5);
      merging::CropPairOptions window = crop;
      window.width = window.height = args.real_window;
      const std::string set = real_set(args.real_window);
      for (const auto& [name, map] : real) {
        std::string missing;  // the overlaps this map has no windows for
        for (const double f : args.overlaps) {
          window.overlap = f;
          for (int k = 0; k < args.real_pairs; ++k) {
            try {
              merging::CropPair c = merging::make_crop_pair(map, window, random);
              if (args.real_mixed > 1) mix_resolutions(c, args.real_mixed, random);
              pairs.push_back(std::make_unique<Pair>(Pair{set, name, f, std::move(c.a), std::move(c.b), c.b_to_a, {}, {}}));
            } catch (const Error&) {
              missing += fmt::format("{}{}%", missing.empty() ? "" : ", ", overlap_percent(f));
              break;
            }
          }
        }
        if (!missing.empty())
          std::cerr << fmt::format("--real-maps: {}: no {} x {} windows found at {} overlap (fewer pairs there)\n", name,
                                   args.real_window, args.real_window, missing);
      }
      merging::CropPairOptions one = window;
      one.overlap = 0.9;
      for (int k = 0; real.size() >= 2 && k < args.real_unrelated; ++k) {
        const std::size_t i = std::size_t(random.uniform_int(0, int(real.size()) - 1));
        const std::size_t j = (i + std::size_t(random.uniform_int(1, int(real.size()) - 1))) % real.size();
        try {
          merging::CropPair ci = merging::make_crop_pair(real[i].second, one, random);
          merging::CropPair cj = merging::make_crop_pair(real[j].second, one, random);
          if (args.real_mixed > 1) {
            mix_resolutions(ci, args.real_mixed, random);
            mix_resolutions(cj, args.real_mixed, random);
          }
          pairs.push_back(std::make_unique<Pair>(Pair{"unrelated", real[i].first + "/" + real[j].first, 0.0, std::move(ci.a),
                                                      std::move(cj.b), std::nullopt, {},
                                                      std::pair(ci.a_to_source, cj.b_to_source)}));
        } catch (const Error&) {
        }
      }
    }
    // Campus windows.
    const mapping::OccupancyGrid campus = maps::load_map_source("campus");
    merging::CropPairOptions campus_crop = crop;
    campus_crop.width = campus_crop.height = 1000;
    campus_crop.min_known = 0.3;
    random = core::Random(args.seed + 3);
    for (const double f : args.overlaps) {
      campus_crop.overlap = f;
      for (int k = 0; k < args.campus_pairs; ++k) {
        merging::CropPair c = merging::make_crop_pair(campus, campus_crop, random);
        clutter_pair(c.a, c.b, random);
        pairs.push_back(std::make_unique<Pair>(Pair{"campus1000", "campus", f, std::move(c.a), std::move(c.b), c.b_to_a, {}, {}}));
      }
    }
    if (args.large_pairs > 0) {
      const mapping::OccupancyGrid fine = refine_grid(campus, 4);
      merging::CropPairOptions big = crop;
      big.width = big.height = 4000;
      big.min_known = 0.3;
      random = core::Random(args.seed + 4);
      for (int k = 0; k < args.large_pairs; ++k) {
        big.overlap = k % 2 ? 0.2 : 0.5;
        merging::CropPair c = merging::make_crop_pair(fine, big, random);
        pairs.push_back(std::make_unique<Pair>(Pair{"campus4000", "campus", big.overlap, std::move(c.a), std::move(c.b), c.b_to_a, {}, {}}));
      }
    }

    std::vector<Record> records;
    std::ofstream diag;
    if (!args.diagnose.empty()) {
      diag.open(args.diagnose);
      diag << "pair,set,overlap,merged,found,confidence,rot_err_deg,spectral_candidates,first_right,first_refines_right,"
              "sweep_candidates,sweep_first_right,sweep_first_refines_right,truth_score,truth_matched,truth_contra,truth_rms,"
              "oracle_merged,oracle_found,oracle_confidence,oracle_distinct,oracle_evidence,class,oracle_reason,"
              "alone_merged,alone_confidence,alone_class\n";
    }
    std::ofstream csv;
    if (!args.csv.empty()) {
      csv.open(args.csv);
      csv << "pair,set,source,overlap,truth_x,truth_y,truth_deg,method,merged,found,error_cells,confidence,cpu_ms,wall_ms,detail\n";
    }
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      const Pair& p = *pairs[i];
      if (!args.only.empty() && std::find(args.only.begin(), args.only.end(), int(i)) == args.only.end()) continue;
      std::cerr << fmt::format("\rpairs: {}/{} {} {}%      ", i + 1, pairs.size(), p.set, overlap_percent(p.overlap))
                << std::flush;
      if (!args.dump.empty()) {
        fs::create_directories(args.dump);
        io::save_map_image(p.a, args.dump / fmt::format("a_{}.png", i));
        io::save_map_image(p.b, args.dump / fmt::format("b_{}.png", i));
      }
      Record r;
      r.pair = &p;
      r.fleetmap = run_fleetmap(p, options);
      if (args.peer) r.peer = run_peer(p);
      records.push_back(r);
      if (diag.is_open() && p.truth && !success(r.fleetmap)) {
        const Diagnosis d = diagnose(p, options);
        records.back().loss_class = d.loss_class, records.back().alone_class = d.alone_class;
        diag << fmt::format("{},{},{:.2f},{},{},{:.3f},{}\n", i, p.set, p.overlap, int(r.fleetmap.merged),
                            int(r.fleetmap.found), r.fleetmap.confidence, d.csv) << std::flush;
      }
      if (csv) {
        for (const auto& [name, o] : {std::pair<std::string, const Outcome*>{"fleetmap", &r.fleetmap}, {"peer", &r.peer}}) {
          if (name == "peer" && !args.peer) continue;
          const core::Transform2 t = p.truth.value_or(core::Transform2::identity());
          csv << fmt::format("{},{},{},{:.2f},{:.3f},{:.3f},{:.3f},{},{},{},{:.4f},{:.4f},{:.2f},{:.2f},\"{}\"\n", i, p.set,
                             p.source, p.overlap, t.translation().x(), t.translation().y(), core::rad2deg(t.rotation()),
                             name, int(o->merged), int(o->found), o->error, o->confidence, 1e3 * o->cpu_s,
                             1e3 * o->wall_s, o->detail);
        }
        csv.flush();
      }
    }
    std::cerr << "\n";

    // Tables.
    if (!maps.empty())
      std::cout << "Maps: " << maps.size() << " robot-built HouseExpo maps"
                << (args.furniture > 0.0 ? fmt::format(", furnished (a piece per {:g} m² of floor)", args.furniture) : std::string(", bare plans"))
                << " (cache " << args.cache.string() << ")\n\n";
    if (!real.empty()) {
      std::cout << "Maps of --real-maps (" << args.real_window << " x " << args.real_window << " windows):";
      for (std::size_t i = 0; i < real.size(); ++i) std::cout << (i ? ", " : " ") << real[i].first;
      std::cout << "\n\n";
    }
    const auto select = [&](const std::string& set, std::optional<double> f, bool peer) {
      std::vector<const Outcome*> out;
      for (const auto& r : records) {
        if (r.pair->set != set || (f && std::abs(r.pair->overlap - *f) > 1e-9)) continue;
        out.push_back(peer ? &r.peer : &r.fleetmap);
      }
      return out;
    };
    for (const std::string& set : std::vector<std::string>{"house300", "house300x2", real_set(args.real_window), "campus1000", "campus4000"}) {
      std::vector<double> fs_;
      for (const auto& r : records)
        if (r.pair->set == set && std::find(fs_.begin(), fs_.end(), r.pair->overlap) == fs_.end()) fs_.push_back(r.pair->overlap);
      if (fs_.empty()) continue;
      std::sort(fs_.begin(), fs_.end());
      std::cout << "### " << set << "\n\n| overlap | peer (ORB): success, wrong, median error, median CPU | peer's answer right, "
                   "whatever its confidence | fleetmap `" << args.method
                << "`: success, wrong, median error, median CPU | fleetmap's answer right but refused |\n|---|---|---|---|---|\n";
      const auto found = [](const std::vector<const Outcome*>& os, bool refused_only) {
        int n = 0;
        for (const auto* o : os) n += o->found && (!refused_only || !o->merged);
        return n;
      };
      for (const double f : fs_) {
        const auto fl = select(set, f, false), pe = select(set, f, true);
        std::cout << fmt::format("| {}% | {} | {} | {} | {} |\n", overlap_percent(f), args.peer ? summary(pe) : "-",
                                 args.peer ? std::to_string(found(pe, false)) : "-", summary(fl), found(fl, true));
      }
      const auto fl = select(set, std::nullopt, false), pe = select(set, std::nullopt, true);
      std::cout << fmt::format("| all | {} | {} | {} | {} |\n\n", args.peer ? summary(pe) : "-",
                               args.peer ? std::to_string(found(pe, false)) : "-", summary(fl), found(fl, true));
      // Real maps differ more from one another than from one overlap to the next: the same pairs
      // by map (merged right of the pairs, per overlap), so that a hard building shows.
      if (set != real_set(args.real_window)) continue;
      std::vector<std::string> sources;
      for (const auto& r : records)
        if (r.pair->set == set && std::find(sources.begin(), sources.end(), r.pair->source) == sources.end())
          sources.push_back(r.pair->source);
      std::cout << "### " << set << " by map (fleetmap merged right / pairs)\n\n| map |";
      for (const double f : fs_) std::cout << " " << overlap_percent(f) << "% |";
      std::cout << " all | wrong |" << (args.peer ? " peer (ORB): all, wrong |" : "") << "\n|---|";
      for (std::size_t k = 0; k < fs_.size() + 2 + (args.peer ? 1 : 0); ++k) std::cout << "---|";
      std::cout << "\n";
      for (const auto& source : sources) {
        const auto count = [&](std::optional<double> f, bool peer, bool wrong_only) {
          int n = 0, hits = 0;
          for (const auto& r : records) {
            if (r.pair->set != set || r.pair->source != source || (f && std::abs(r.pair->overlap - *f) > 1e-9)) continue;
            const Outcome& o = peer ? r.peer : r.fleetmap;
            ++n;
            hits += wrong_only ? wrong(o) : success(o);
          }
          return std::pair(hits, n);
        };
        std::cout << "| " << source << " |";
        for (const double f : fs_) {
          const auto [k, n] = count(f, false, false);
          std::cout << " " << (n ? fmt::format("{}/{}", k, n) : "-") << " |";
        }
        const auto [k, n] = count(std::nullopt, false, false);
        std::cout << fmt::format(" {}/{} | {} |", k, n, count(std::nullopt, false, true).first);
        if (args.peer)
          std::cout << fmt::format(" {}/{}, {} |", count(std::nullopt, true, false).first, n, count(std::nullopt, true, true).first);
        std::cout << "\n";
      }
      std::cout << "\n";
    }
    {
      const auto fl = select("unrelated", std::nullopt, false);
      const auto pe = select("unrelated", std::nullopt, true);
      int ff = 0, pf = 0;
      std::vector<double> tf, tp;
      for (const auto* o : fl) ff += o->merged, tf.push_back(o->cpu_s);
      for (const auto* o : pe) pf += o->merged, tp.push_back(o->cpu_s);
      std::cout << fmt::format("### unrelated (windows of two different plans or maps)\n\n| | pairs | false merges | median CPU |\n|---|---|---|---|\n"
                               "| peer (ORB) | {} | {} | {} |\n| fleetmap | {} | {} | {} |\n\n",
                               args.peer ? int(pe.size()) : 0, args.peer ? std::to_string(pf) : "-", ms(median(tp)),
                               fl.size(), ff, ms(median(tf)));
    }
    // Why the pairs not merged right were lost (--diagnose): the oracle's decision with the truth
    // handed in as a candidate (ambiguity_class), and the truth alone.
    if (diag.is_open()) {
      const std::vector<std::string> classes = {"determinable", "rival-scores-higher", "rival-fits-as-well", "one-corner",
                                                "one-room", "little-evidence", "disagreement"};
      for (const std::string& set : std::vector<std::string>{"house300", "house300x2", real_set(args.real_window), "campus1000"}) {
        std::vector<double> fs_;
        for (const auto& r : records)
          if (r.pair->set == set && std::find(fs_.begin(), fs_.end(), r.pair->overlap) == fs_.end()) fs_.push_back(r.pair->overlap);
        if (fs_.empty()) continue;
        std::sort(fs_.begin(), fs_.end());
        std::cout << "### Losses of " << set << " (oracle: the truth handed in beside the search's candidates)\n\n| overlap | lost |";
        for (const auto& c : classes) std::cout << " " << c << " |";
        std::cout << " truth alone: refused as one corner / little evidence / other |\n|---|---|";
        for (std::size_t k = 0; k < classes.size() + 1; ++k) std::cout << "---|";
        std::cout << "\n";
        for (const double f : fs_) {
          std::map<std::string, int> n;
          int lost = 0;
          for (const auto& r : records) {
            if (r.pair->set != set || std::abs(r.pair->overlap - f) > 1e-9 || r.loss_class.empty()) continue;
            ++lost, ++n[r.loss_class];
            ++n[r.alone_class == "one-corner" ? "alone corner" : r.alone_class == "little-evidence" ? "alone evidence" : "alone other"];
          }
          std::cout << fmt::format("| {}% | {} |", overlap_percent(f), lost);
          for (const auto& c : classes) std::cout << " " << n[c] << " |";
          std::cout << fmt::format(" {} / {} / {} |\n", n["alone corner"], n["alone evidence"], n["alone other"]);
        }
        std::cout << "\n";
      }
    }
    // Reliability: of the answers with confidence in a bin, the share that is right; and at each
    // threshold, what a user gets.
    {
      std::cout << "### fleetmap's confidence (every pair above but campus4000)\n\n"
                << "| confidence | answers | right | share right | accepted at >= c: answers, share right, share of all right answers |\n|---|---|---|---|---|\n";
      int total_right = 0;
      for (const auto& r : records) total_right += r.pair->set != "campus4000" && r.fleetmap.found;
      for (int k = 0; k < 10; ++k) {
        const double lo = 0.1 * k, hi = k == 9 ? 1.01 : 0.1 * (k + 1);
        int n = 0, right = 0, acc = 0, acc_right = 0;
        for (const auto& r : records) {
          if (r.pair->set == "campus4000") continue;
          const double c = r.fleetmap.confidence;
          if (c >= lo && c < hi) ++n, right += r.fleetmap.found;
          if (c >= lo) ++acc, acc_right += r.fleetmap.found;
        }
        std::cout << fmt::format("| {:.1f}-{:.1f} | {} | {} | {} | {}, {}, {} |\n", lo, std::min(hi, 1.0), n, right,
                                 n ? fmt::format("{:.0f}%", 100.0 * right / n) : "-", acc,
                                 acc ? fmt::format("{:.1f}%", 100.0 * acc_right / acc) : "-",
                                 total_right ? fmt::format("{:.1f}%", 100.0 * acc_right / total_right) : "-");
      }
      std::cout << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "fleetmap_bench_merging_real: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
