// Could any method tell a pair's true placement from every other? An exhaustive judge, independent
// of fleetmap's merging, for the pairs of fleetmap_bench_merging_real (its --csv and --dump files).
//
// Every rotation of b (1 degree steps) at every translation over a, by FFT correlation, is scored by
// the weakest direction's matched walls, less the walls on the other map's free space:
//   - a match: a cell beside one of b's walls, on the side b saw it from (its first free layer,
//     a "face"), within 1.5 cells of a face of a's walls, counted by the direction of a's wall
//     (four bins of the normal, 45 degrees apart); the score is the smallest eigenvalue of
//     sum_k M_k n_k n_k^T, the matched faces pinning the placement's weakest direction, so one long
//     wall laid on another pins nothing, and a wall seen from opposite sides matches nothing;
//   - a contradiction: a wall of one map on the other's free space, 3 cells or more from its walls
//     (weight 10); wall pieces under 40 cells (dilated) are clutter, neither wall nor free.
// The truth's score is the best within 5 cells (at the common part's centre) and 5 degrees of it;
// the rival's, the best elsewhere. A pair is determinable when the truth scores at least 20 and the
// rival at most 0.7 of the truth: otherwise another placement fits the two maps nearly as well, or
// nothing pins the truth, whatever a method makes of them.
#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct JudgeOptions {
  double face = 1.5;                  // cells: a face is a free cell this close to a wall
  double match = 1.5;                 // cells: a face of b this close to a face of a matches
  double far_free = 3.0;              // cells: a wall on free space this far from walls contradicts
  double contradiction_weight = 10.0;
  int clutter_cells = 40;             // wall pieces (dilated by a cell) smaller than this are clutter
  double same_distance = 5.0;         // cells, at the common part's centre: the truth's own placements
  double same_rotation_deg = 5.0;
  double min_truth = 20.0;            // the weakest direction's matched faces that pin a placement
  double max_rival_share = 0.7;       // a rival scoring more than this share of the truth: ambiguous
};

// A placement of b's cells in a's: q = R(deg) p + (x, y), cells with y upwards (the CSV's truth).
struct Placement {
  double x = 0.0, y = 0.0, deg = 0.0;
};

struct Verdict {
  double truth = 0.0, rival = 0.0;  // scores
  Placement rival_placement;
  double rival_distance = 0.0;      // cells, at the common part's centre
  bool common = false;              // whether the truth lays any of b's known cells on a's
};

constexpr std::uint8_t kUnknownGray = 205;

struct Masks {
  cv::Mat walls, far_free;          // CV_32F 0/1
  cv::Mat faces;                    // b: all faces
  std::vector<cv::Mat> face_bins;   // a: cells within `match` of the faces of walls of each normal bin
};

Masks masks_of(const cv::Mat& m, bool binned, const JudgeOptions& o) {
  cv::Mat walls = m < 100, free = m > 230;
  {
    cv::Mat grown, labels, stats, centroids;
    cv::dilate(walls, grown, cv::Mat::ones(3, 3, CV_8U));
    cv::connectedComponentsWithStats(grown, labels, stats, centroids, 8);
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < m.cols; ++x) {
        const int l = labels.at<int>(y, x);
        if (l > 0 && stats.at<int>(l, cv::CC_STAT_AREA) < o.clutter_cells) walls.at<std::uint8_t>(y, x) = 0, free.at<std::uint8_t>(y, x) = 0;
      }
  }
  cv::Mat distance;
  cv::distanceTransform(~walls, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  Masks out;
  walls.convertTo(out.walls, CV_32F, 1.0 / 255);
  cv::Mat(free & (distance >= o.far_free)).convertTo(out.far_free, CV_32F, 1.0 / 255);
  if (!binned) {
    cv::Mat(free & (distance <= o.face)).convertTo(out.faces, CV_32F, 1.0 / 255);
    return out;
  }
  // The normal's direction of each wall cell: the structure tensor of the wall mask.
  cv::Mat smooth, gx, gy, jxx, jyy, jxy;
  cv::GaussianBlur(out.walls, smooth, cv::Size(0, 0), 1.0);
  cv::Sobel(smooth, gx, CV_32F, 1, 0), cv::Sobel(smooth, gy, CV_32F, 0, 1);
  cv::GaussianBlur(gx.mul(gx), jxx, cv::Size(0, 0), 2.0);
  cv::GaussianBlur(gy.mul(gy), jyy, cv::Size(0, 0), 2.0);
  cv::GaussianBlur(gx.mul(gy), jxy, cv::Size(0, 0), 2.0);
  std::vector<cv::Mat> not_bin(4);  // 0 on the walls of the bin
  for (auto& b : not_bin) b = cv::Mat(m.size(), CV_8U, cv::Scalar(255));
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) {
      if (!walls.at<std::uint8_t>(y, x)) continue;
      const double xx = jxx.at<float>(y, x), yy = jyy.at<float>(y, x), xy = jxy.at<float>(y, x), trace = xx + yy;
      if (trace <= 1e-9 || std::hypot(xx - yy, 2.0 * xy) < 0.5 * trace) continue;  // a corner or a speck
      double deg = 0.5 * std::atan2(2.0 * xy, xx - yy) * 180.0 / CV_PI;
      if (deg < 0.0) deg += 180.0;
      not_bin[std::size_t(std::lround(deg / 45.0) % 4)].at<std::uint8_t>(y, x) = 0;
    }
  for (const auto& nb : not_bin) {
    cv::Mat to_wall, to_face;
    cv::distanceTransform(nb, to_wall, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::distanceTransform(~(free & (to_wall <= o.face)), to_face, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::Mat near;
    cv::Mat(to_face <= o.match).convertTo(near, CV_32F, 1.0 / 255);
    out.face_bins.push_back(near);
  }
  return out;
}

// Crops a map image to its known cells and a margin; returns the crop's corner.
cv::Point crop_known(cv::Mat& m) {
  cv::Rect box = cv::boundingRect(m != kUnknownGray);
  box = cv::Rect(box.x - 4, box.y - 4, box.width + 8, box.height + 8) & cv::Rect(0, 0, m.cols, m.rows);
  m = m(box).clone();
  return box.tl();
}

// Moves the rows-past-the-end half of a cyclic correlation before the rest: out(y + s, x + s) is
// the value at shift (x, y), for shifts in [-s, n - s).
cv::Mat unwrap(const cv::Mat& c, int s) {
  const int n = c.rows;
  cv::Mat cols(n, n, CV_32F), out(n, n, CV_32F);
  c(cv::Rect(n - s, 0, s, n)).copyTo(cols(cv::Rect(0, 0, s, n)));
  c(cv::Rect(0, 0, n - s, n)).copyTo(cols(cv::Rect(s, 0, n - s, n)));
  cols(cv::Rect(0, n - s, n, s)).copyTo(out(cv::Rect(0, 0, n, s)));
  cols(cv::Rect(0, 0, n, n - s)).copyTo(out(cv::Rect(0, s, n, n - s)));
  return out;
}

// a, b: map images as saved (row 0 at the top); truth: b's cells into a's.
Verdict judge(cv::Mat a, cv::Mat b, Placement truth, const JudgeOptions& o) {
  cv::flip(a, a, 0), cv::flip(b, b, 0);  // rows are y, upwards
  const cv::Point oa = crop_known(a), ob = crop_known(b);
  const double t0 = truth.deg * CV_PI / 180.0, c0 = std::cos(t0), s0 = std::sin(t0);
  truth.x += c0 * ob.x - s0 * ob.y - oa.x;
  truth.y += s0 * ob.x + c0 * ob.y - oa.y;
  Verdict v;
  // The common part's centre, in b's cells.
  double cx = 0.0, cy = 0.0, cn = 0.0;
  for (int y = 0; y < b.rows; ++y)
    for (int x = 0; x < b.cols; ++x) {
      if (b.at<std::uint8_t>(y, x) == kUnknownGray) continue;
      const long u = std::lround(c0 * x - s0 * y + truth.x), w = std::lround(s0 * x + c0 * y + truth.y);
      if (u < 0 || w < 0 || u >= a.cols || w >= a.rows || a.at<std::uint8_t>(int(w), int(u)) == kUnknownGray) continue;
      cx += x, cy += y, cn += 1.0;
    }
  if (cn == 0.0) return v;
  v.common = true;
  cx /= cn, cy /= cn;
  const Masks ma = masks_of(a, true, o), mb = masks_of(b, false, o);
  const int s = int(std::ceil(std::hypot(b.cols, b.rows))) + 2;  // b turned fits in s x s
  const int n = cv::getOptimalDFTSize(std::max(a.cols, a.rows) + s);
  const auto spectrum = [n](const cv::Mat& m) {
    cv::Mat padded = cv::Mat::zeros(n, n, CV_32F), out;
    m.copyTo(padded(cv::Rect(0, 0, m.cols, m.rows)));
    cv::dft(padded, out, 0, m.rows);
    return out;
  };
  std::vector<cv::Mat> face_bins;
  for (const auto& m : ma.face_bins) face_bins.push_back(spectrum(m));
  const cv::Mat a_far_free = spectrum(ma.far_free), a_walls = spectrum(ma.walls);
  const double bcx = (b.cols - 1) / 2.0, bcy = (b.rows - 1) / 2.0, cs = (s - 1) / 2.0;
  // The truth lays the common part's centre here.
  const double qx = c0 * cx - s0 * cy + truth.x, qy = s0 * cx + c0 * cy + truth.y;
  std::mutex mutex;
  double best_truth = -1e30, best_rival = -1e30;
  int rival_deg = 0;
  cv::Point rival_at;
  double rival_distance = 0.0;
  cv::parallel_for_(cv::Range(0, 360), [&](const cv::Range& range) {
    for (int deg = range.start; deg < range.end; ++deg) {
      const double th = deg * CV_PI / 180.0, c = std::cos(th), sn = std::sin(th);
      const cv::Mat turn = (cv::Mat_<double>(2, 3) << c, -sn, cs - (c * bcx - sn * bcy), sn, c, cs - (sn * bcx + c * bcy));
      cv::Mat walls, far_free, faces;
      cv::warpAffine(mb.walls, walls, turn, cv::Size(s, s), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      cv::warpAffine(mb.far_free, far_free, turn, cv::Size(s, s), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      cv::warpAffine(mb.faces, faces, turn, cv::Size(s, s), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      const cv::Mat bw = spectrum(walls), bf = spectrum(far_free), bc = spectrum(faces);
      cv::Mat matched[4], product, other, contradicted;
      for (std::size_t k = 0; k < 4; ++k) {
        cv::mulSpectrums(face_bins[k], bc, product, 0, true);
        cv::idft(product, matched[k], cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
      }
      cv::mulSpectrums(a_far_free, bw, product, 0, true);
      cv::mulSpectrums(a_walls, bf, other, 0, true);
      cv::idft(product + other, contradicted, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
      cv::Mat score(n, n, CV_32F);
      for (int y = 0; y < n; ++y) {
        const float *m0 = matched[0].ptr<float>(y), *m1 = matched[1].ptr<float>(y), *m2 = matched[2].ptr<float>(y),
                    *m3 = matched[3].ptr<float>(y), *cc = contradicted.ptr<float>(y);
        float* out = score.ptr<float>(y);
        for (int x = 0; x < n; ++x) {
          // Normals at 0, 45, 90 and 135 degrees.
          const float xx = m0[x] + 0.5f * (m1[x] + m3[x]), yy = m2[x] + 0.5f * (m1[x] + m3[x]), xy = 0.5f * (m1[x] - m3[x]);
          const float weakest = 0.5f * (xx + yy) - std::sqrt(0.25f * (xx - yy) * (xx - yy) + xy * xy);
          out[x] = weakest - float(o.contradiction_weight) * std::max(0.0f, cc[x]);
        }
      }
      cv::Mat full = unwrap(score, s);
      // The shift that lays the common part's centre where the truth does, at this rotation.
      const double sx = qx - (c * (cx - bcx) - sn * (cy - bcy) + cs), sy = qy - (sn * (cx - bcx) + c * (cy - bcy) + cs);
      double own = -1e30;
      if (std::abs(std::remainder(th - t0, 2.0 * CV_PI)) * 180.0 / CV_PI <= o.same_rotation_deg) {
        const double r = o.same_distance;
        for (int y = std::max(0, int(std::floor(sy - r)) + s); y <= std::min(n - 1, int(std::ceil(sy + r)) + s); ++y)
          for (int x = std::max(0, int(std::floor(sx - r)) + s); x <= std::min(n - 1, int(std::ceil(sx + r)) + s); ++x)
            if (std::hypot(x - s - sx, y - s - sy) <= r) {
              own = std::max(own, double(full.at<float>(y, x)));
              full.at<float>(y, x) = -1e30f;
            }
      }
      double most = 0.0;
      cv::Point at;
      cv::minMaxLoc(full, nullptr, &most, nullptr, &at);
      const std::lock_guard lock(mutex);
      best_truth = std::max(best_truth, own);
      if (most > best_rival || (most == best_rival && deg < rival_deg)) {
        best_rival = most, rival_deg = deg, rival_at = at;
        rival_distance = std::hypot(at.x - s - sx, at.y - s - sy);
      }
    }
  });
  v.truth = best_truth, v.rival = best_rival, v.rival_distance = rival_distance;
  // Back to the uncropped cells: q = R (p - bc) + cs + shift in the crops.
  const double th = rival_deg * CV_PI / 180.0, c = std::cos(th), sn = std::sin(th);
  const double tx = cs + (rival_at.x - s) - (c * bcx - sn * bcy), ty = cs + (rival_at.y - s) - (sn * bcx + c * bcy);
  v.rival_placement = {tx + oa.x - (c * ob.x - sn * ob.y), ty + oa.y - (sn * ob.x + c * ob.y), double(rival_deg)};
  return v;
}

struct Row {
  int pair = 0;
  std::string set, source;
  double overlap = 0.0;
  Placement truth;
  bool right = false;  // merged within the benchmark's 2 cells
};

// The fleetmap rows of fleetmap_bench_merging_real's --csv (pair, set, source, overlap, truth_x,
// truth_y, truth_deg, method, merged, found, ...).
std::vector<Row> read_rows(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read", path.string()));
  std::vector<Row> rows;
  std::string line;
  std::getline(in, line);
  for (int number = 2; std::getline(in, line); ++number) {
    std::stringstream fields(line);
    std::vector<std::string> f;
    std::string field;
    for (int i = 0; i < 10 && std::getline(fields, field, ','); ++i) f.push_back(field);
    if (f.size() < 10) throw std::runtime_error(fmt::format("{}:{}: fewer than 10 fields", path.string(), number));
    if (f[7] != "fleetmap") continue;
    try {
      rows.push_back({std::stoi(f[0]), f[1], f[2], std::stod(f[3]), {std::stod(f[4]), std::stod(f[5]), std::stod(f[6])},
                      f[8] == "1" && f[9] == "1"});
    } catch (const std::exception&) {
      throw std::runtime_error(fmt::format("{}:{}: not a row of fleetmap_bench_merging_real --csv", path.string(), number));
    }
  }
  return rows;
}

struct Args {
  fs::path csv, dump, out;
  bool lost = false;
  int right = 0;                    // merged-right pairs judged beside, spread evenly
  std::vector<int> only;
  std::vector<double> overlaps;     // empty: all
};

[[noreturn]] void usage(int code) {
  (code ? std::cerr : std::cout)
      << "Whether a pair's true placement could be told from every other (bench/README.md, \"An exhaustive judge of the lost windows\").\n"
         "usage: fleetmap_bench_placement_judge --csv FILE --dump DIR (--lost | --only K,...) [--right N]\n"
         "       [--overlaps 0.3,0.5,...] [--out FILE]\n"
         "  --csv, --dump   fleetmap_bench_merging_real's --csv and --dump of the same run\n"
         "  --lost          judge every pair that run did not merge right\n"
         "  --right N       and N of the pairs it merged right (a check of the judge)\n"
         "  --only K,...    judge these pairs\n"
         "  --out FILE      one CSV row per pair judged\n";
  std::exit(code);
}

Args parse(int argc, char** argv) {
  Args a;
  const auto list = [](const std::string& text, auto convert) {
    std::vector<decltype(convert(std::string()))> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) out.push_back(convert(item));
    return out;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << k << ": needs a value\n";
        usage(2);
      }
      return argv[++i];
    };
    try {
      if (k == "--help" || k == "-h") usage(0);
      else if (k == "--csv") a.csv = value();
      else if (k == "--dump") a.dump = value();
      else if (k == "--out") a.out = value();
      else if (k == "--lost") a.lost = true;
      else if (k == "--right") a.right = std::stoi(value());
      else if (k == "--only") a.only = list(value(), [](const std::string& t) { return std::stoi(t); });
      else if (k == "--overlaps") a.overlaps = list(value(), [](const std::string& t) { return std::stod(t); });
      else {
        std::cerr << k << ": unknown option\n";
        usage(2);
      }
    } catch (const std::logic_error&) {
      std::cerr << k << ": not a number: " << argv[i] << "\n";
      std::exit(2);
    }
  }
  if (a.csv.empty() || a.dump.empty() || (!a.lost && a.only.empty())) usage(2);
  return a;
}

std::string percent(int part, int whole) { return whole ? fmt::format("{:.0f}% ({}/{})", 100.0 * part / whole, part, whole) : "-"; }

}  // namespace

int main(int argc, char** argv) try {
  const Args args = parse(argc, argv);
  const std::vector<Row> rows = read_rows(args.csv);
  const auto wanted_overlap = [&](double f) {
    return args.overlaps.empty() ||
           std::any_of(args.overlaps.begin(), args.overlaps.end(), [f](double g) { return std::abs(f - g) < 1e-6; });
  };
  std::vector<const Row*> lost, right;
  for (const auto& r : rows) {
    if (!args.only.empty() && std::find(args.only.begin(), args.only.end(), r.pair) == args.only.end()) continue;
    if (!wanted_overlap(r.overlap)) continue;
    (r.right ? right : lost).push_back(&r);
  }
  if (args.only.empty() && args.right < int(right.size())) {  // every k-th, spread over the run
    std::vector<const Row*> spread;
    for (int i = 0; i < args.right; ++i) spread.push_back(right[std::size_t(i) * right.size() / std::size_t(args.right)]);
    right = spread;
  }
  if (!args.lost && args.only.empty()) lost.clear();
  std::ofstream out;
  if (!args.out.empty()) {
    std::error_code ec;
    if (fs::equivalent(args.out, args.csv, ec))
      throw std::runtime_error(fmt::format("{}: --out would overwrite an input of the judge", args.out.string()));
    out.open(args.out);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot write", args.out.string()));
    out << "pair,set,source,overlap,merged_right,truth_score,rival_score,rival_share,determinable,rival_x,rival_y,rival_deg,rival_cells\n";
  }
  const JudgeOptions options;
  struct Count {
    int judged = 0, determinable = 0, too_little = 0;
  };
  std::map<std::pair<std::string, double>, std::pair<Count, Count>> counts;  // (set, overlap) -> (lost, right)
  std::vector<const Row*> all = lost;
  all.insert(all.end(), right.begin(), right.end());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Row& r = *all[i];
    std::cerr << fmt::format("\rjudged: {}/{}   ", i + 1, all.size()) << std::flush;
    const auto image = [&](char which) {
      const fs::path p = args.dump / fmt::format("{}_{}.png", which, r.pair);
      cv::Mat m;
      if (fs::is_regular_file(p)) m = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
      if (m.empty()) throw std::runtime_error(fmt::format("{}: cannot read (is --dump the run's --dump?)", p.string()));
      return m;
    };
    const Verdict v = judge(image('a'), image('b'), r.truth, options);
    const bool determinable = v.common && v.truth >= options.min_truth && v.rival <= options.max_rival_share * v.truth;
    Count& c = r.right ? counts[{r.set, r.overlap}].second : counts[{r.set, r.overlap}].first;
    ++c.judged;
    c.determinable += determinable;
    c.too_little += !determinable && (!v.common || v.truth < options.min_truth);
    if (out)
      out << fmt::format("{},{},{},{:.2f},{},{:.1f},{:.1f},{},{},{:.2f},{:.2f},{:.0f},{:.1f}\n", r.pair, r.set, r.source,
                         r.overlap, int(r.right), v.truth, v.rival, v.truth >= 1.0 ? fmt::format("{:.3f}", v.rival / v.truth) : std::string(), int(determinable),
                         v.rival_placement.x, v.rival_placement.y, v.rival_placement.deg, v.rival_distance)
          << std::flush;
  }
  std::cerr << "\n";
  std::cout << "| set | overlap | pairs lost | determinable | ambiguous: a rival fits nearly as well | ambiguous: nothing pins the truth | "
               "pairs merged right, judged determinable |\n|---|---|---|---|---|---|---|\n";
  for (const auto& [key, c] : counts) {
    const auto& [l, r] = c;
    std::cout << fmt::format("| {} | {:.0f}% | {} | {} | {} | {} | {} |\n", key.first, 100.0 * key.second, l.judged,
                             percent(l.determinable, l.judged), l.judged - l.determinable - l.too_little, l.too_little,
                             percent(r.determinable, r.judged));
  }
  return 0;
} catch (const std::exception& e) {
  std::cerr << "fleetmap_bench_placement_judge: " << e.what() << "\n";
  return 1;
}
