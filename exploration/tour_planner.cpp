// Over 500 lines on purpose: the two local searches (the longest tour, and the weighted latency)
// make the same kinds of moves (insertion, relocate, exchange, 2-opt) on different objectives and
// are kept side by side.
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

// The local search's state: the tours, their lengths, and costs with +inf replaced by a cost
// above any tour without it, so that differences of lengths stay finite.
class Search {
 public:
  Search(const TourProblem& p, const TourOptions& o) : p_(p), o_(o), n_(int(p.start_cost.rows())), m_(int(p.between.rows())) {
    impossible_ = impossible_cost(p);
    tours_.resize(std::size_t(n_));
    length_.assign(std::size_t(n_), 0.0);
  }

  bool reachable(int robot, int t) const { return std::isfinite(p_.start_cost(robot, t)); }

  // Cost of the leg from `from` (a target, or kStart) to target `to` on robot `robot`'s tour.
  double leg(int robot, int from, int to) const {
    const double c = from == kStart ? p_.start_cost(robot, to) : p_.between(from, to);
    return std::isfinite(c) ? c : impossible_;
  }

  double length_of(int robot, const std::vector<int>& tour) const {
    double sum = 0.0;
    int prev = kStart;
    for (int t : tour) {
      sum += leg(robot, prev, t);
      prev = t;
    }
    return sum;
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
    for (int r = 0; r < n_; ++r) length_[std::size_t(r)] = length_of(r, tours_[std::size_t(r)]);
    // The rest, farthest from every robot first: those are the ones that decide the longest tour.
    std::vector<int> rest;
    std::vector<double> nearest(std::size_t(m_), std::numeric_limits<double>::infinity());
    for (int t = 0; t < m_; ++t) {
      for (int r = 0; r < n_; ++r) nearest[std::size_t(t)] = std::min(nearest[std::size_t(t)], p_.start_cost(r, t));
      if (!used[std::size_t(t)] && std::isfinite(nearest[std::size_t(t)])) rest.push_back(t);
    }
    std::stable_sort(rest.begin(), rest.end(), [&](int a, int b) { return nearest[std::size_t(a)] > nearest[std::size_t(b)]; });
    for (int t : rest) insert(t);
    if (o_.every_robot_busy) give_idle_robots_a_target();
  }

  // Each robot without a target takes one from a tour of two or more, where the tours get the best
  // score; robots in team order.
  void give_idle_robots_a_target() {
    for (int r = 0; r < n_; ++r) {
      if (!tours_[std::size_t(r)].empty()) continue;
      int donor = -1;
      std::size_t at = 0;
      double best_longest = 0.0, best_sum = 0.0;
      const double sum = total();
      for (int d = 0; d < n_; ++d) {
        const auto& tour = tours_[std::size_t(d)];
        if (tour.size() < 2) continue;
        for (std::size_t p = 0; p < tour.size(); ++p) {
          if (!reachable(r, tour[p])) continue;
          const double new_d = length_[std::size_t(d)] + remove_delta(d, tour, p), new_r = leg(r, kStart, tour[p]);
          const double longest = std::max({longest_except(d, r), new_d, new_r});
          const double new_sum = sum - length_[std::size_t(d)] + new_d + new_r;
          if (donor < 0 || better(longest, new_sum, best_longest, best_sum)) donor = d, at = p, best_longest = longest, best_sum = new_sum;
        }
      }
      if (donor < 0) continue;
      auto& from = tours_[std::size_t(donor)];
      tours_[std::size_t(r)].push_back(from[at]);
      from.erase(from.begin() + std::ptrdiff_t(at));
      length_[std::size_t(donor)] = length_of(donor, from);
      length_[std::size_t(r)] = length_of(r, tours_[std::size_t(r)]);
    }
  }

  // Cheapest min-max insertion of target t.
  void insert(int t) {
    int best_robot = -1;
    std::size_t best_pos = 0;
    double best_longest = 0.0, best_delta = 0.0;
    for (int r = 0; r < n_; ++r) {
      if (!reachable(r, t)) continue;
      const auto& tour = tours_[std::size_t(r)];
      const double others = longest_except(r, r);
      for (std::size_t q = 0; q <= tour.size(); ++q) {
        const double delta = insert_delta(r, tour, q, t, tour.size());
        const double longest = std::max(others, length_[std::size_t(r)] + delta);
        if (best_robot < 0 || longest < best_longest - o_.tolerance ||
            (longest <= best_longest + o_.tolerance && delta < best_delta - o_.tolerance)) {
          best_robot = r, best_pos = q, best_longest = longest, best_delta = delta;
        }
      }
    }
    auto& tour = tours_[std::size_t(best_robot)];
    tour.insert(tour.begin() + std::ptrdiff_t(best_pos), t);
    length_[std::size_t(best_robot)] += best_delta;
  }

  void improve() {
    for (int pass = 0; pass < o_.max_passes; ++pass) {
      for (int r = 0; r < n_; ++r) length_[std::size_t(r)] = length_of(r, tours_[std::size_t(r)]);  // no drift
      bool improved = false;
      for (int r = 0; r < n_; ++r) improved |= two_opt(r);
      improved |= relocate();
      improved |= exchange();
      if (!improved) break;
    }
  }

  Tours take() { return std::move(tours_); }

 private:
  // The longest tour among the robots other than a and b (0 when there are none).
  double longest_except(int a, int b) const {
    double m = 0.0;
    for (int r = 0; r < n_; ++r)
      if (r != a && r != b) m = std::max(m, length_[std::size_t(r)]);
    return m;
  }

  double total() const { return std::accumulate(length_.begin(), length_.end(), 0.0); }

  // Whether tours with longest `longest` and total `sum` beat the current ones.
  bool better(double longest, double sum, double current_longest, double current_sum) const {
    return longest < current_longest - o_.tolerance || (longest <= current_longest && sum < current_sum - o_.tolerance);
  }

  // The change in length when t is inserted before position q of a tour of `size` targets, read
  // through `at` (which may skip an element, see relocate).
  template <typename At>
  double insert_delta_at(int r, At at, std::size_t q, int t, std::size_t size) const {
    const int prev = q == 0 ? kStart : at(q - 1);
    if (q == size) return leg(r, prev, t);
    const int next = at(q);
    return leg(r, prev, t) + leg(r, t, next) - leg(r, prev, next);
  }
  double insert_delta(int r, const std::vector<int>& tour, std::size_t q, int t, std::size_t size) const {
    return insert_delta_at(r, [&](std::size_t k) { return tour[k]; }, q, t, size);
  }

  // The change in length when the target at position p leaves the tour.
  double remove_delta(int r, const std::vector<int>& tour, std::size_t p) const {
    const int prev = p == 0 ? kStart : tour[p - 1];
    const int t = tour[p];
    if (p + 1 == tour.size()) return -leg(r, prev, t);
    const int next = tour[p + 1];
    return leg(r, prev, next) - leg(r, prev, t) - leg(r, t, next);
  }

  // 2-opt on an open tour: reverse tour[i..j]. The legs inside the segment keep their costs
  // (symmetric), only the two at its ends change.
  bool two_opt(int r) {
    auto& tour = tours_[std::size_t(r)];
    bool any = false;
    const std::size_t len = tour.size();
    for (std::size_t i = 0; i + 1 < len; ++i) {
      for (std::size_t j = i + 1; j < len; ++j) {
        const int prev = i == 0 ? kStart : tour[i - 1];
        double delta = leg(r, prev, tour[j]) - leg(r, prev, tour[i]);
        if (j + 1 < len) delta += leg(r, tour[i], tour[j + 1]) - leg(r, tour[j], tour[j + 1]);
        if (delta >= -o_.tolerance) continue;
        // Only this tour shortens: the longest cannot grow, the total drops.
        std::reverse(tour.begin() + std::ptrdiff_t(i), tour.begin() + std::ptrdiff_t(j) + 1);
        length_[std::size_t(r)] += delta;
        any = true;
      }
    }
    return any;
  }

  // Move one target to another place, in its own tour or another robot's.
  bool relocate() {
    bool any = false;
    for (int a = 0; a < n_; ++a) {
      for (std::size_t p = 0; p < tours_[std::size_t(a)].size();) {
        if (!relocate_one(a, p)) ++p;
        else any = true;  // position p now holds the next target
      }
    }
    return any;
  }

  bool relocate_one(int a, std::size_t p) {
    auto& from = tours_[std::size_t(a)];
    const int t = from[p];
    const double removed = remove_delta(a, from, p);
    const double current_longest = longest_except(-1, -1), current_sum = total();
    for (int b = 0; b < n_; ++b) {
      // Emptying a tour is a move only when it hands the target to an idle robot (the number of busy
      // robots stays): a robot far away must not keep a target that an idle one stands beside.
      if (!reachable(b, t) || (b != a && o_.every_robot_busy && from.size() == 1 && !tours_[std::size_t(b)].empty())) continue;
      if (b == a) {
        // Insert into the tour without t: position k of the reduced tour is from[k < p ? k : k + 1].
        const auto reduced = [&](std::size_t k) { return from[k < p ? k : k + 1]; };
        const std::size_t size = from.size() - 1;
        for (std::size_t q = 0; q <= size; ++q) {
          if (q == p) continue;  // where it was
          const double new_len = length_[std::size_t(a)] + removed + insert_delta_at(a, reduced, q, t, size);
          const double longest = std::max(longest_except(a, a), new_len);
          if (!better(longest, current_sum - length_[std::size_t(a)] + new_len, current_longest, current_sum)) continue;
          from.erase(from.begin() + std::ptrdiff_t(p));
          from.insert(from.begin() + std::ptrdiff_t(q), t);
          length_[std::size_t(a)] = new_len;
          return true;
        }
        continue;
      }
      auto& to = tours_[std::size_t(b)];
      const double others = longest_except(a, b);
      const double new_a = length_[std::size_t(a)] + removed;
      for (std::size_t q = 0; q <= to.size(); ++q) {
        const double new_b = length_[std::size_t(b)] + insert_delta(b, to, q, t, to.size());
        const double longest = std::max({others, new_a, new_b});
        const double sum = current_sum - length_[std::size_t(a)] - length_[std::size_t(b)] + new_a + new_b;
        if (!better(longest, sum, current_longest, current_sum)) continue;
        from.erase(from.begin() + std::ptrdiff_t(p));
        to.insert(to.begin() + std::ptrdiff_t(q), t);
        length_[std::size_t(a)] = new_a;
        length_[std::size_t(b)] = new_b;
        return true;
      }
    }
    return false;
  }

  // The change in length when the target at position p is replaced by u.
  double replace_delta(int r, const std::vector<int>& tour, std::size_t p, int u) const {
    const int prev = p == 0 ? kStart : tour[p - 1];
    double delta = leg(r, prev, u) - leg(r, prev, tour[p]);
    if (p + 1 < tour.size()) delta += leg(r, u, tour[p + 1]) - leg(r, tour[p], tour[p + 1]);
    return delta;
  }

  // Swap two targets of different tours.
  bool exchange() {
    bool any = false;
    for (int a = 0; a < n_; ++a) {
      for (int b = a + 1; b < n_; ++b) {
        auto& ta = tours_[std::size_t(a)];
        auto& tb = tours_[std::size_t(b)];
        for (std::size_t p = 0; p < ta.size(); ++p) {
          for (std::size_t q = 0; q < tb.size(); ++q) {
            if (!reachable(a, tb[q]) || !reachable(b, ta[p])) continue;
            const double new_a = length_[std::size_t(a)] + replace_delta(a, ta, p, tb[q]);
            const double new_b = length_[std::size_t(b)] + replace_delta(b, tb, q, ta[p]);
            const double current_sum = total();
            const double longest = std::max({longest_except(a, b), new_a, new_b});
            const double sum = current_sum - length_[std::size_t(a)] - length_[std::size_t(b)] + new_a + new_b;
            if (!better(longest, sum, longest_except(-1, -1), current_sum)) continue;
            std::swap(ta[p], tb[q]);
            length_[std::size_t(a)] = new_a;
            length_[std::size_t(b)] = new_b;
            any = true;
          }
        }
      }
    }
    return any;
  }

  const TourProblem& p_;
  const TourOptions& o_;
  int n_, m_;
  double impossible_ = 0.0;
  Tours tours_;
  std::vector<double> length_;
};

}  // namespace

double tour_length(const TourProblem& problem, int robot, const std::vector<int>& tour) {
  double sum = 0.0;
  for (std::size_t k = 0; k < tour.size(); ++k) {
    sum += k == 0 ? problem.start_cost(robot, tour[k]) : problem.between(tour[k - 1], tour[k]);
  }
  return sum;
}

Tours plan_tours(const TourProblem& problem, const Tours& initial, const TourOptions& options) {
  if (problem.between.rows() != problem.between.cols() || problem.start_cost.cols() != problem.between.rows()) {
    throw Error("plan_tours: start_cost must be robots x targets and between targets x targets");
  }
  Search search(problem, options);
  search.set_initial(initial);
  search.improve();
  return search.take();
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
