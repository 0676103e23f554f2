#pragma once
// A progress bar on stderr, drawn only when stderr is a terminal.
#include <string>

namespace fleetmap::cli {

std::string format_percent(double fraction);

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled);
  void update(long done, long total, const std::string& note = "");
  void finish();

 private:
  bool enabled_ = false;
  bool drawn_ = false;
  double started_ = 0.0;
  double last_draw_ = -1.0;
};

}  // namespace fleetmap::cli
