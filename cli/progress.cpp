#include "cli/progress.h"

#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>

namespace fleetmap::cli {

namespace {
double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

std::string format_percent(double fraction) {
  return fmt::format("{:.1f}%", 100.0 * fraction);
}

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)), started_(now_s()) {}

void ProgressBar::update(long done, long total, const std::string& note) {
  if (!enabled_ || total <= 0) return;
  const double t = now_s();
  if (done < total && t - last_draw_ < 0.1) return;
  last_draw_ = t;
  constexpr int kWidth = 30;
  const double f = double(done) / double(total);
  const int filled = int(f * kWidth);
  const double elapsed = t - started_;
  const double eta = done > 0 ? elapsed * double(total - done) / double(done) : 0.0;
  fmt::print(stderr, "\r[{}{}] {}/{} {}  {:.0f}s elapsed, eta {}   ", std::string(std::size_t(filled), '#'),
             std::string(std::size_t(kWidth - filled), ' '), done, total, note, elapsed,
             done > 0 ? fmt::format("{:.0f}s", eta) : std::string("unknown"));
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (drawn_) fmt::print(stderr, "\n");
  drawn_ = false;
}

}  // namespace fleetmap::cli
