#include "exploration/tour_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/error.h"

namespace fleetmap::exploration {

namespace {

constexpr int kStart = -1;  // the robot's own position, before its first target

// A leg cost no real tour can reach: unreachable legs cost this, so that any tour using one is worse
// than every tour without.
double impossible_cost(const TourProblem& p) {
  double largest = 0.0;
  for (const Eigen::MatrixXd* m : {&p.start_cost, &p.between}) {
    for (Eigen::Index i = 0; i < m->size(); ++i) {
      if (std::isfinite(m->data()[i])) largest = std::max(largest, std::abs(m->data()[i]));
    }
  }
  return 1e6 * (largest + 1.0) * double(p.between.rows() + 1);
}

}  // namespace

double tour_length(const TourProblem& problem, int robot, const std::vector<int>& tour) {
  double sum = 0.0;
  for (std::size_t k = 0; k < tour.size(); ++k) {
    sum += k == 0 ? problem.start_cost(robot, tour[k]) : problem.between(tour[k - 1], tour[k]);
  }
  return sum;
}

namespace {

// Local search for plan_latency_tours: insertion, then relocate, exchange and 2-opt moves, each
// accepted when the total weighted latency drops. Tours are short (a few targets per robot), so a
// move is scored by recomputing the one or two tours it changes.
class LatencySearch {
 public:
  LatencySearch(const TourProblem& p, const std::vector<double>& w, const TourOptions& o)
      : p_(p), o_(o), n_(int(p.start_cost.rows())), m_(int(p.between.rows())), w_(w) {
    if (w_.empty()) w_.assign(std::size_t(m_), 1.0);
    impossible_ = impossible_cost(p);
    tours_.resize(std::size_t(n_));
    cost_.assign(std::size_t(n_), 0.0);
  }

  bool reachable(int r, int t) const { return std::isfinite(p_.start_cost(r, t)); }

  double leg(int r, int from, int to) const {
    const double c = from == kStart ? p_.start_cost(r, to) : p_.between(from, to);
    return std::isfinite(c) ? c : impossible_;
  }

  // Weighted latency of a tour given as a function of position.
  template <typename At>
  double latency_at(int r, At at, std::size_t size) const {
    double arrival = 0.0, sum = 0.0;
    int prev = kStart;
    for (std::size_t k = 0; k < size; ++k) {
      const int t = at(k);
      arrival += leg(r, prev, t);
      sum += w_[std::size_t(t)] * arrival;
      prev = t;
    }
    return sum;
  }
  double latency(int r, const std::vector<int>& tour) const {
    return latency_at(r, [&](std::size_t k) { return tour[k]; }, tour.size());
  }

  void set_initial(const Tours& initial) {
    std::vector<char> used(std::size_t(m_), false);
    for (int r = 0; r < n_ && r < int(initial.size()); ++r) {
      for (int t : initial[std::size_t(r)]) {
        if (t < 0 || t >= m_ || used[std::size_t(t)] || !reachable(r, t)) continue;
        used[std::size_t(t)] = true;
        tours_[std::size_t(r)].push_back(t);
      }
    }
    for (int r = 0; r < n_; ++r) cost_[std::size_t(r)] = latency(r, tours_[std::size_t(r)]);
    // The rest, heaviest first: they decide most of the total.
    std::vector<int> rest;
    for (int t = 0; t < m_; ++t) {
      bool any = false;
      for (int r = 0; r < n_ && !any; ++r) any = reachable(r, t);
      if (!used[std::size_t(t)] && any) rest.push_back(t);
    }
    std::stable_sort(rest.begin(), rest.end(), [&](int a, int b) { return w_[std::size_t(a)] > w_[std::size_t(b)]; });
    for (int t : rest) insert(t);
  }

  void improve() {
    for (int pass = 0; pass < o_.max_passes; ++pass) {
      bool improved = false;
      for (int a = 0; a < n_; ++a)
        for (std::size_t p = 0; p < tours_[std::size_t(a)].size();)
          if (relocate(a, p)) improved = true;
          else ++p;
      improved |= exchange();
      for (int r = 0; r < n_; ++r) improved |= two_opt(r);
      if (!improved) break;
    }
  }

  Tours take() { return std::move(tours_); }

 private:
  // Cheapest insertion of target t.
  void insert(int t) {
    int best_r = -1;
    std::size_t best_q = 0;
    double best = 0.0;
    for (int r = 0; r < n_; ++r) {
      if (!reachable(r, t)) continue;
      auto& tour = tours_[std::size_t(r)];
      for (std::size_t q = 0; q <= tour.size(); ++q) {
        tour.insert(tour.begin() + std::ptrdiff_t(q), t);
        const double delta = latency(r, tour) - cost_[std::size_t(r)];
        tour.erase(tour.begin() + std::ptrdiff_t(q));
        if (best_r < 0 || delta < best - o_.tolerance) best_r = r, best_q = q, best = delta;
      }
    }
    auto& tour = tours_[std::size_t(best_r)];
    tour.insert(tour.begin() + std::ptrdiff_t(best_q), t);
    cost_[std::size_t(best_r)] += best;
  }

  bool relocate(int a, std::size_t p) {
    auto& from = tours_[std::size_t(a)];
    const int t = from[p];
    std::vector<int> reduced = from;
    reduced.erase(reduced.begin() + std::ptrdiff_t(p));
    const double without = latency(a, reduced);
    for (int b = 0; b < n_; ++b) {
      if (!reachable(b, t)) continue;
      std::vector<int> to = b == a ? reduced : tours_[std::size_t(b)];
      const double base = b == a ? cost_[std::size_t(a)] : cost_[std::size_t(a)] + cost_[std::size_t(b)];
      for (std::size_t q = 0; q <= to.size(); ++q) {
        if (b == a && q == p) continue;
        to.insert(to.begin() + std::ptrdiff_t(q), t);
        const double now = b == a ? latency(a, to) : without + latency(b, to);
        if (now < base - o_.tolerance) {
          if (b == a) {
            from = to;
            cost_[std::size_t(a)] = now;
          } else {
            from = reduced;
            cost_[std::size_t(a)] = without;
            cost_[std::size_t(b)] = now - without;
            tours_[std::size_t(b)] = to;
          }
          return true;
        }
        to.erase(to.begin() + std::ptrdiff_t(q));
      }
    }
    return false;
  }

  bool exchange() {
    bool any = false;
    for (int a = 0; a < n_; ++a) {
      for (int b = a + 1; b < n_; ++b) {
        auto& ta = tours_[std::size_t(a)];
        auto& tb = tours_[std::size_t(b)];
        for (std::size_t p = 0; p < ta.size(); ++p) {
          for (std::size_t q = 0; q < tb.size(); ++q) {
            if (!reachable(a, tb[q]) || !reachable(b, ta[p])) continue;
            std::swap(ta[p], tb[q]);
            const double ca = latency(a, ta), cb = latency(b, tb);
            if (ca + cb < cost_[std::size_t(a)] + cost_[std::size_t(b)] - o_.tolerance) {
              cost_[std::size_t(a)] = ca, cost_[std::size_t(b)] = cb;
              any = true;
            } else {
              std::swap(ta[p], tb[q]);
            }
          }
        }
      }
    }
    return any;
  }

  bool two_opt(int r) {
    auto& tour = tours_[std::size_t(r)];
    bool any = false;
    for (std::size_t i = 0; i + 1 < tour.size(); ++i) {
      for (std::size_t j = i + 1; j < tour.size(); ++j) {
        std::reverse(tour.begin() + std::ptrdiff_t(i), tour.begin() + std::ptrdiff_t(j) + 1);
        const double c = latency(r, tour);
        if (c < cost_[std::size_t(r)] - o_.tolerance) {
          cost_[std::size_t(r)] = c;
          any = true;
        } else {
          std::reverse(tour.begin() + std::ptrdiff_t(i), tour.begin() + std::ptrdiff_t(j) + 1);
        }
      }
    }
    return any;
  }

  const TourProblem& p_;
  const TourOptions& o_;
  int n_, m_;
  std::vector<double> w_;
  double impossible_ = 0.0;
  Tours tours_;
  std::vector<double> cost_;
};

}  // namespace

double tour_latency(const TourProblem& problem, const std::vector<double>& weight, int robot, const std::vector<int>& tour) {
  double arrival = 0.0, sum = 0.0;
  for (std::size_t k = 0; k < tour.size(); ++k) {
    arrival += k == 0 ? problem.start_cost(robot, tour[k]) : problem.between(tour[k - 1], tour[k]);
    if (!std::isfinite(arrival)) return std::numeric_limits<double>::infinity();
    sum += (weight.empty() ? 1.0 : weight[std::size_t(tour[k])]) * arrival;
  }
  return sum;
}

Tours plan_latency_tours(const TourProblem& problem, const std::vector<double>& weight, const Tours& initial,
                         const TourOptions& options) {
  if (problem.between.rows() != problem.between.cols() || problem.start_cost.cols() != problem.between.rows() ||
      (!weight.empty() && weight.size() != std::size_t(problem.between.rows()))) {
    throw Error("plan_latency_tours: start_cost must be robots x targets, between targets x targets, one weight per target");
  }
  for (double w : weight)
    if (!(w >= 0.0) || !std::isfinite(w)) throw Error("plan_latency_tours: a target's weight must be finite and not negative");
  LatencySearch search(problem, weight, options);
  search.set_initial(initial);
  search.improve();
  return search.take();
}

}  // namespace fleetmap::exploration
