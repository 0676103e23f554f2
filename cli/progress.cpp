#include "cli/progress.h"

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
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f%%", 100.0 * fraction);
  return buf;
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
  std::fprintf(stderr, "\r[%.*s%*s] %ld/%ld %s  %.0fs elapsed, eta %.0fs   ", filled, "##############################",
               kWidth - filled, "", done, total, note.c_str(), elapsed, eta);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace fleetmap::cli
