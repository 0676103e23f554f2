// Merging's accept/refuse decision as a calibrated model: pairs of windows of real laser maps of
// one or more splits of buildings, and of HouseExpo floor plans (bench/real_maps/README.md,
// "Merging's decision model"), fleetmap's answer and the features of it (merging::DecisionFeatures
// with the rival search run on every answer, MergeOptions::complete_features, and the quality of
// the answer), and the ORB peer on the same pairs. Prints markdown for bench/README.md: success at each
// overlap for fleetmap's decision, for a logistic model of P(answer right | features), and for the
// peer; false merges on unrelated pairs; the model's reliability table (answers at probability p,
// share right). With --fit the model is fitted on these pairs (the training split) and its
// coefficients printed; otherwise the coefficients given with --model are used. The model is
// measured here only: decide() still decides (bench/README.md says why).
//
// The pairs: window a is axis-aligned, window b of the same size turned by a uniform angle and
// shifted until the stated share of the smaller one's known cells lies in both
// (merging::OverlapMeasure::Known), as bench/merging_real_bench.cpp cuts them. Unrelated pairs: a
// window of one building's map and one of another building's in the same split. An answer is
// right when b's known cells lie within 2 cells of where the truth puts them on average; for an
// unrelated pair no answer is right. Times are the thread's CPU time per pair (alignment only, the
// complete rival search included; bench/merging_real_bench.cpp times what `fleetmap merge` runs).
#include <fmt/format.h>
#include <opencv2/core/utility.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "bench/merging_bench_support.h"
#include "core/error.h"
#include "core/random.h"
#include "io/map_io.h"
#include "merging/evaluation.h"
#include "merging/merge.h"
#include "merging/resolutions.h"

namespace {

using namespace fleetmap;
namespace fs = std::filesystem;

// bench/real_maps/README.md, "Merging's decision model": fixed before any fitting.
const std::map<std::string, std::vector<std::string>> kSplits = {
    {"training",
     {"willow", "intel_lab", "uos_avz5", "uos_rilo", "strands_g4s_y2", "upo_uva_lab", "upo_uva_demo", "jsk_eng6_1f",
      "upo_elderly_center"}},
    {"validation",
     {"stata_basement", "utexas_gdc_1", "utexas_gdc_2", "utexas_gdc_3ne", "uos_cic", "strands_tsc", "strands_collection",
      "upo_45"}},
    {"test", {"bham_cs_lgfloor", "upo_centre_sportif", "ipa_office", "aist_conveni", "sapienza_diag"}},
};

// Maps of one building: unrelated pairs take two maps of different buildings.
std::string building(const std::string& map) {
  if (map.rfind("utexas_gdc", 0) == 0) return "utexas_gdc";
  if (map.rfind("upo_uva", 0) == 0) return "upo_uva";
  return map;
}

struct Args {
  fs::path maps = "/work/realmaps/maps";
  fs::path plans = "/work/shared/datasets/houseexpo";
  std::vector<std::string> splits = {"training"};
  int plan_window = 150;  // HouseExpo plans are 7-38 m across: 7.5 m windows at 0.05 m
  int pairs = 10;       // per map and overlap
  int unrelated = 100;  // pairs of windows of two buildings
  int window = 300;
  std::vector<double> overlaps = {0.5, 0.3, 0.2};
  std::uint64_t seed = 1;
  std::string csv;
  bool fit = false;
  std::vector<double> model;  // coefficients: intercept, then one per feature
};

[[noreturn]] void usage(const std::string& why) {
  std::cerr << why << "\nusage: fleetmap_bench_merging_model [--maps DIR] [--plans DIR] [--split S[,S...]] [--pairs N]\n"
                      "       [--unrelated N] [--window CELLS] [--plan-window CELLS] [--overlaps 0.5,0.3,0.2] [--seed N]\n"
                      "       [--csv FILE] [--fit | --model W0,W1,...]\n"
                      "  S: training, validation, test (real maps in --maps), plans-even, plans-odd (HouseExpo plans in --plans)\n";
  std::exit(2);
}

std::vector<double> numbers(const std::string& flag, const std::string& text) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    try {
      std::size_t used = 0;
      const std::string item = text.substr(start, comma - start);
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      usage(flag + ": '" + text + "' is not a comma-separated list of numbers");
    }
    start = comma + 1;
  }
  return out;
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    if (const auto eq = k.find('='); k.rfind("--", 0) == 0 && eq != std::string::npos) {
      // --model=-1,2: a list that starts with a minus sign.
      const std::string v = k.substr(eq + 1);
      k = k.substr(0, eq);
      if (k == "--model") {
        a.model = numbers(k, v);
        continue;
      }
      usage(k + ": give its value after a space");
    }
    if (k == "--fit") {
      a.fit = true;
      continue;
    }
    if (i + 1 >= argc) usage(k + ": needs a value");
    const std::string v = argv[++i];
    if (k == "--maps") a.maps = v;
    else if (k == "--split") {
      a.splits.clear();
      for (std::size_t start = 0; start <= v.size();) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        const std::string one = v.substr(start, comma - start);
        if (!kSplits.count(one) && one != "plans-even" && one != "plans-odd")
          usage("--split: '" + one + "' is not training, validation, test, plans-even or plans-odd");
        a.splits.push_back(one);
        start = comma + 1;
      }
    } else if (k == "--plans") a.plans = v;
    else if (k == "--plan-window") a.plan_window = int(numbers(k, v).at(0)); else if (k == "--pairs") a.pairs = int(numbers(k, v).at(0));
    else if (k == "--unrelated") a.unrelated = int(numbers(k, v).at(0));
    else if (k == "--window") a.window = int(numbers(k, v).at(0));
    else if (k == "--overlaps") a.overlaps = numbers(k, v);
    else if (k == "--seed") a.seed = std::uint64_t(numbers(k, v).at(0));
    else if (k == "--csv") a.csv = v;
    else if (k == "--model") a.model = numbers(k, v);
    else usage("unknown option " + k);
  }
  return a;
}

// --- features -----------------------------------------------------------------------------------

// What the model reads of an answer, each meaningful on any map (cells, shares, counts): the
// walls' agreement where both maps know the cells, the walls in the other map's open space, the
// cells' agreement, distinctiveness against the best rival of the complete search, how well the fit
// pins its weakest direction (the covariance's largest standard deviation at the overlap), how
// tightly the walls fit, the matched structure beyond two straight walls (what tells a place from
// any corner of any building), and the best turned rival's share of the evidence (a symmetric room).
const std::vector<std::string> kFeatureNames = {
    "log((matched + 1) / (contradicted + 1))",
    "log(1 + open_space_walls)",
    "logit(acceptance)",
    "distinctiveness (complete rival search)",
    "log(largest std at the overlap, cells)",
    "log(residual rms, cells)",
    "log(1 + matched structure off the two strongest lines)",
    "turned rival's share of the evidence",
};

std::vector<double> features_of(const merging::MergeResult& r) {
  const auto& q = r.quality;
  const double omega = std::clamp(r.acceptance, 0.0, 1.0);
  // Without a covariance (too few walls in common) the placement is free in every direction.
  const double largest_std = r.covariance ? std::min(r.features.largest_std_cells, 1e3) : 1e3;
  return {
      std::log((q.matched + 1.0) / (q.contradicted + 1.0)),
      std::log1p(double(q.open_space_walls)),
      std::log((omega + 1e-3) / (1.0 - omega + 1e-3)),
      std::clamp(r.features.distinctiveness, 0.0, 1.0),
      std::log(largest_std + 0.01),
      std::log(q.residual_rms + 0.05),
      std::log1p(double(q.beyond_corner + q.wall_ends + q.common_openings)),
      std::clamp(r.features.turned, 0.0, 2.0),
  };
}

double probability(const std::vector<double>& w, const std::vector<double>& x) {
  double z = w.at(0);
  for (std::size_t i = 0; i < x.size(); ++i) z += w.at(i + 1) * x[i];
  return 1.0 / (1.0 + std::exp(-z));
}

// Logistic regression by Newton's method (IRLS) on standardised features with a small ridge
// (1e-2 on the standardised weights, not the intercept: separable training sets otherwise have
// no maximum), then back to the features' own units.
std::vector<double> fit_logistic(const std::vector<std::vector<double>>& x, const std::vector<int>& y) {
  const std::size_t n = x.size(), d = x.at(0).size();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(Eigen::Index(d)), sd = Eigen::VectorXd::Zero(Eigen::Index(d));
  for (const auto& row : x)
    for (std::size_t j = 0; j < d; ++j) mean(Eigen::Index(j)) += row[j] / double(n);
  for (const auto& row : x)
    for (std::size_t j = 0; j < d; ++j) sd(Eigen::Index(j)) += std::pow(row[j] - mean(Eigen::Index(j)), 2) / double(n);
  sd = sd.cwiseSqrt().cwiseMax(1e-9);
  Eigen::MatrixXd m(Eigen::Index(n), Eigen::Index(d + 1));
  for (std::size_t i = 0; i < n; ++i) {
    m(Eigen::Index(i), 0) = 1.0;
    for (std::size_t j = 0; j < d; ++j)
      m(Eigen::Index(i), Eigen::Index(j + 1)) = (x[i][j] - mean(Eigen::Index(j))) / sd(Eigen::Index(j));
  }
  Eigen::VectorXd w = Eigen::VectorXd::Zero(Eigen::Index(d + 1));
  constexpr double kRidge = 1e-2;
  for (int it = 0; it < 50; ++it) {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(w.size());
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(w.size(), w.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::VectorXd xi = m.row(Eigen::Index(i)).transpose();
      const double p = 1.0 / (1.0 + std::exp(-xi.dot(w)));
      g += (p - y[i]) * xi;
      h += std::max(p * (1.0 - p), 1e-9) * xi * xi.transpose();
    }
    for (Eigen::Index j = 1; j < w.size(); ++j) g(j) += kRidge * w(j), h(j, j) += kRidge;
    const Eigen::VectorXd step = h.ldlt().solve(g);
    w -= step;
    if (step.norm() < 1e-8) break;
  }
  std::vector<double> out(d + 1);
  out[0] = w(0);
  for (std::size_t j = 0; j < d; ++j) {
    out[j + 1] = w(Eigen::Index(j + 1)) / sd(Eigen::Index(j));
    out[0] -= out[j + 1] * mean(Eigen::Index(j));
  }
  return out;
}

// --- pairs ----------------------------------------------------------------------------------------

struct Row {
  std::string map;
  double overlap = 0.0;  // 0: unrelated
  bool right = false;    // fleetmap's answer (merged or not) is within 2 cells of the truth
  bool merged = false;
  double error = -1.0, ms = 0.0;
  bool peer_merged = false, peer_right = false;
  double peer_error = -1.0, peer_ms = 0.0;
  std::vector<double> x;
  double p = 0.0;
  double mahalanobis2 = -1.0;  // the transform's error (tx, ty, theta) squared in the covariance's metric
  int refusal = 0;           // merging::Refusal, as a number
  double confidence = 0.0;
};

constexpr double kSuccessCells = 2.0;

Row run(const std::string& map, double overlap, const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
        const std::optional<core::Transform2>& truth) {
  Row row;
  row.map = map;
  row.overlap = overlap;
  const double c0 = bench::thread_seconds();
  // As `fleetmap merge` aligns them, with the rival search run on every answer (the features are
  // then complete; the decision is decide()'s own).
  merging::MergeOptions options;
  options.complete_features = true;
  const merging::MergeResult r = merging::align_across_resolutions(a, b, options);
  row.ms = 1e3 * (bench::thread_seconds() - c0);
  row.merged = r.merged;
  row.refusal = int(r.refusal);
  row.confidence = r.confidence;
  if (truth && r.candidates > 0) {
    row.error = merging::mean_displacement(r.transform, *truth, b);
    row.right = row.error < kSuccessCells;
    if (r.covariance) {
      Eigen::Vector3d e(r.transform.translation().x() - truth->translation().x(),
                        r.transform.translation().y() - truth->translation().y(),
                        std::remainder(r.transform.rotation() - truth->rotation(), 2.0 * std::numbers::pi));
      row.mahalanobis2 = e.dot(r.covariance->ldlt().solve(e));
    }
  }
  row.x = features_of(r);
  const double c1 = bench::thread_seconds();
  const bench::PeerResult peer = bench::orb_peer(a, b);
  row.peer_ms = 1e3 * (bench::thread_seconds() - c1);
  row.peer_merged = peer.merged;
  if (truth && peer.b_to_a) {
    row.peer_error = merging::mean_displacement(*peer.b_to_a, *truth, b);
    row.peer_right = row.peer_error < kSuccessCells;
  }
  return row;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string percent(int k, int n) { return n > 0 ? fmt::format("{:.0f}% ({}/{})", 100.0 * k / n, k, n) : "-"; }

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse(argc, argv);
  cv::setNumThreads(1);
  core::Random random(args.seed);
  std::vector<Row> rows;
  std::size_t map_count = 0;
  for (const std::string& split : args.splits) {
    // HouseExpo's plans (ideal walls, many bare rooms: generic corners and rooms are common there)
    // split by their sorted order, every other plan.
    const bool plans = split.rfind("plans-", 0) == 0;
    std::vector<fs::path> files;
    if (plans) {
      std::vector<fs::path> all;
      for (const auto& e : fs::directory_iterator(args.plans))
        if (e.path().extension() == ".yaml") all.push_back(e.path());
      std::sort(all.begin(), all.end());
      for (std::size_t i = split == "plans-even" ? 0 : 1; i < all.size(); i += 2) files.push_back(all[i]);
    } else {
      for (const auto& name : kSplits.at(split)) files.push_back(args.maps / (name + ".yaml"));
    }
    std::vector<std::pair<std::string, mapping::OccupancyGrid>> maps;
    for (const auto& yaml : files) {
      try {
        maps.emplace_back(yaml.stem().string(), io::load_map(yaml));
      } catch (const Error& e) {
        std::cerr << yaml.string() << ": " << e.what() << "\n";
        return 2;
      }
    }
    map_count += maps.size();
    merging::CropPairOptions window;
    window.width = window.height = plans ? args.plan_window : args.window;
    window.measure = merging::OverlapMeasure::Known;
    window.min_known = 0.25;
    window.max_tries = 60;
    for (const auto& [name, map] : maps) {
      for (const double f : args.overlaps) {
        window.overlap = f;
        for (int k = 0; k < args.pairs; ++k) {
          try {
            const merging::CropPair c = merging::make_crop_pair(map, window, random);
            rows.push_back(run(name, f, c.a, c.b, c.b_to_a));
          } catch (const Error&) {
            std::cerr << fmt::format("{}: no {} x {} windows at {:.0f}% overlap\n", name, window.width, window.height, 100 * f);
            break;
          }
        }
      }
      std::cerr << name << ": " << rows.size() << " pairs so far\n";
    }
    merging::CropPairOptions one = window;
    one.overlap = 0.9;
    for (int k = 0, tries = 0; k < args.unrelated && maps.size() >= 2 && tries < 20 * args.unrelated; ++k, ++tries) {
      const std::size_t i = std::size_t(random.uniform_int(0, int(maps.size()) - 1));
      const std::size_t j = std::size_t(random.uniform_int(0, int(maps.size()) - 1));
      if (building(maps[i].first) == building(maps[j].first)) {
        --k;
        continue;
      }
      try {
        const merging::CropPair ci = merging::make_crop_pair(maps[i].second, one, random);
        const merging::CropPair cj = merging::make_crop_pair(maps[j].second, one, random);
        rows.push_back(run(maps[i].first + "/" + maps[j].first, 0.0, ci.a, cj.b, std::nullopt));
      } catch (const Error&) {
      }
    }
  }
  std::string split_names;
  for (const auto& sp : args.splits) split_names += (split_names.empty() ? "" : "+") + sp;

  std::vector<double> model = args.model;
  if (args.fit) {
    std::vector<std::vector<double>> x;
    std::vector<int> y;
    for (const auto& r : rows) x.push_back(r.x), y.push_back(r.right ? 1 : 0);
    model = fit_logistic(x, y);
    fmt::print("Fitted on {} pairs of the {} split (seed {}). Coefficients (--model):\n\n```\n", rows.size(), split_names,
               args.seed);
    for (std::size_t i = 0; i < model.size(); ++i) fmt::print("{}{:.6g}", i ? "," : "", model[i]);
    fmt::print("\n```\n\n| feature | weight |\n|---|---|\n| intercept | {:.4g} |\n", model[0]);
    for (std::size_t i = 0; i < kFeatureNames.size(); ++i) fmt::print("| {} | {:.4g} |\n", kFeatureNames[i], model[i + 1]);
    fmt::print("\nThe right answers' medians of the features:\n\n```\n");
    for (std::size_t i = 0; i < kFeatureNames.size(); ++i) {
      std::vector<double> v;
      for (const auto& r : rows)
        if (r.right) v.push_back(r.x[i]);
      fmt::print("{}{:.6g}", i ? ", " : "", median(v));
    }
    fmt::print("\n```\n");
    fmt::print("\n");
  }
  if (!model.empty() && model.size() != kFeatureNames.size() + 1)
    usage(fmt::format("--model: {} coefficients given, {} expected (intercept and one per feature)", model.size(),
                      kFeatureNames.size() + 1));
  for (auto& r : rows) r.p = model.empty() ? 0.0 : probability(model, r.x);

  fmt::print("Split `{}`: {} maps, {} x {} windows, {} pairs per map and overlap, seed {}{}.\n\n", split_names, map_count,
             args.window, args.window, args.pairs, args.seed, args.fit ? " (the model's own training pairs)" : "");
  fmt::print("| overlap | pairs | fleetmap (decide) | model p >= 0.5 | ORB peer | answer right (merged or not) |\n|---|---|---|---|---|---|\n");
  for (const double f : args.overlaps) {
    int n = 0, fm = 0, mm = 0, pm = 0, found = 0;
    for (const auto& r : rows) {
      if (r.overlap != f) continue;
      ++n;
      fm += r.merged && r.right;
      mm += r.p >= 0.5 && r.right;
      pm += r.peer_merged && r.peer_right;
      found += r.right;
    }
    fmt::print("| {:.0f}% | {} | {} | {} | {} | {} |\n", 100 * f, n, percent(fm, n), model.empty() ? "-" : percent(mm, n),
               percent(pm, n), percent(found, n));
  }
  int wrong_f = 0, wrong_m = 0, wrong_p = 0, unrelated = 0;
  for (const auto& r : rows) {
    if (r.overlap == 0.0) {
      ++unrelated;
      wrong_f += r.merged, wrong_m += r.p >= 0.5, wrong_p += r.peer_merged;
    } else {
      wrong_f += r.merged && !r.right, wrong_m += r.p >= 0.5 && !r.right, wrong_p += r.peer_merged && !r.peer_right;
    }
  }
  int unrelated_f = 0, unrelated_m = 0, unrelated_p = 0;
  for (const auto& r : rows)
    if (r.overlap == 0.0) unrelated_f += r.merged, unrelated_m += r.p >= 0.5, unrelated_p += r.peer_merged;
  fmt::print("\nWrong merges, all pairs: fleetmap {}, model {}, ORB {}; of them on {} unrelated pairs: fleetmap {}, model {}, ORB {}.\n",
             wrong_f, model.empty() ? "-" : std::to_string(wrong_m), wrong_p, unrelated, unrelated_f,
             model.empty() ? "-" : std::to_string(unrelated_m), unrelated_p);
  std::vector<double> err_f, err_p, ms_f, ms_p;
  for (const auto& r : rows) {
    if (r.merged && r.right) err_f.push_back(r.error);
    if (r.peer_merged && r.peer_right) err_p.push_back(r.peer_error);
    if (r.overlap > 0.0) ms_f.push_back(r.ms), ms_p.push_back(r.peer_ms);
  }
  fmt::print("Median error of right merges: fleetmap {:.3f} cells, ORB {:.3f} cells. Median CPU time per pair: fleetmap {:.0f} ms, ORB {:.0f} ms.\n",
             median(err_f), median(err_p), median(ms_f), median(ms_p));
  // An honest covariance makes the squared Mahalanobis distance of the error chi-square with 3
  // degrees of freedom: median 2.366, 95% below 7.815.
  std::vector<double> d2;
  for (const auto& r : rows)
    if (r.merged && r.right && r.mahalanobis2 >= 0.0) d2.push_back(r.mahalanobis2);
  if (!d2.empty())
    fmt::print("Right merges' error in the covariance's metric (squared Mahalanobis distance, chi-square 3 if honest: "
               "median 2.37, 95% under 7.81): median {:.2f}, {:.0f}% under 7.81.\n",
               median(d2), 100.0 * double(std::count_if(d2.begin(), d2.end(), [](double v) { return v < 7.815; })) / double(d2.size()));
  fmt::print("\n");
  if (!model.empty()) {
    fmt::print("Reliability of the model (all pairs: answers at probability p, share right):\n\n| p | answers | right |\n|---|---|---|\n");
    for (int bin = 0; bin < 10; ++bin) {
      const double lo = bin / 10.0, hi = (bin + 1) / 10.0;
      int n = 0, k = 0;
      for (const auto& r : rows)
        if (r.p >= lo && (r.p < hi || (bin == 9 && r.p <= 1.0))) ++n, k += r.right;
      fmt::print("| {:.1f}-{:.1f} | {} | {} |\n", lo, hi, n, n ? fmt::format("{:.0f}%", 100.0 * k / n) : "-");
    }
  }
  if (!args.csv.empty()) {
    std::ofstream out(args.csv);
    out << "map,overlap,right,merged,error,ms,peer_merged,peer_right,peer_error,peer_ms,p,refusal,confidence";
    for (std::size_t i = 0; i < kFeatureNames.size(); ++i) out << ",f" << i;
    out << "\n";
    for (const auto& r : rows) {
      out << fmt::format("{},{},{},{},{:.4f},{:.1f},{},{},{:.4f},{:.1f},{:.4f}", r.map, r.overlap, int(r.right), int(r.merged),
                         r.error, r.ms, int(r.peer_merged), int(r.peer_right), r.peer_error, r.peer_ms, r.p)
          << fmt::format(",{},{:.4f}", r.refusal, r.confidence);
      for (const double v : r.x) out << fmt::format(",{:.6g}", v);
      out << "\n";
    }
  }
  return 0;
}
