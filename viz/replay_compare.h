#pragma once
// Two (or more) replay pages (replay.h) side by side on one timeline: both runs at the same step,
// their coverage curves on one plot, and their metrics with the differences. One self-contained
// page, like the replays it holds.
#include <string>
#include <string_view>
#include <vector>

namespace fleetmap::viz {

struct ComparedReplay {
  std::string label;  // what the page calls the run, e.g. its folder
  std::string page;   // the whole replay page, as replay_html wrote it
};

// The replay's data (the JSON text inside the page). Throws InputError naming `name` when the
// text is not a fleetmap replay page.
std::string replay_page_data(std::string_view page, const std::string& name);

// The comparison page. Its address may carry step=K (open both runs at step K). Throws InputError
// when a page is not a replay page or fewer than two are given.
std::string replay_comparison_html(const std::vector<ComparedReplay>& runs);

}  // namespace fleetmap::viz
