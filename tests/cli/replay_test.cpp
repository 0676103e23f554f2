// `fleetmap explore --html`: the replay page, and the page in a real browser (Debian's chromium,
// headless): the maps its canvas shows at a step are the maps the run wrote for that step, the why
// panel ranks the strategy's candidates, and `fleetmap replay-compare` shows two runs at one step.
// The browser test fails where chromium is missing, unless FLEETMAP_NO_BROWSER=1 says there is none.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <regex>
#include <string>

#include "exploration/strategy.h"
#include "io/file_io.h"
#include "io/map_io.h"
#include "maps/builtin_maps.h"
#include "sim/run_replay.h"
#include "tests/cli_run.h"
#include "viz/render.h"

namespace fleetmap {
namespace {

using testing::run_fleetmap;
using testing::slurp;
using testing::TempDir;

// A short run of two robots on the maze: a few steps are enough to change the map every step.
const std::string kRun = "explore --map maze --robots 2 --seed 3 -q ";

TEST(ReplayPage, ExploreHtmlWritesOneSelfContainedPage) {
  TempDir dir;
  const auto r = run_fleetmap(kRun + "--steps 6 --html --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = slurp(dir / "run" / "replay.html");
  ASSERT_FALSE(page.empty());
  EXPECT_EQ(page.find("http"), std::string::npos);
  EXPECT_EQ(page.find("src="), std::string::npos);
  EXPECT_NE(slurp(dir / "run" / "outputs.txt").find("replay.html"), std::string::npos);
  // The scenario written beside it asks for the page again.
  EXPECT_NE(slurp(dir / "run" / "scenario.yaml").find("outputs:\n  html: true"), std::string::npos);
  // Every robot's first decision is in it, with the strategy's candidates and the one it chose.
  const std::size_t start = page.find(">", page.find("id=\"data\"")) + 1;
  const auto data = nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  EXPECT_EQ(data["scores"]["strategy"], "directional");
  EXPECT_EQ(data["scores"]["terms"].size(), 2u);
  for (const auto& robot : data["robots"]) {
    ASSERT_FALSE(robot["decisions"].empty());
    const auto& first = robot["decisions"][0];
    EXPECT_EQ(first["r"], 1);
    ASSERT_GE(first["c"].get<int>(), 0);
    EXPECT_LT(first["c"].get<int>(), int(first["k"].size()));
  }
}

// Recording the strategies' reasons for the page changes nothing the run does (the joint auction and
// the tours, which keep state between rounds, included).
TEST(ReplayPage, RecordingTheReasonsChangesNoResult) {
  TempDir dir;
  for (const std::string strategy : {"market", "tour"}) {
    const std::string run = "explore --map maze --robots 3 --seed 5 --steps 30 -q --strategy " + strategy;
    ASSERT_EQ(run_fleetmap(run + " --out plain", dir).exit_code, 0);
    ASSERT_EQ(run_fleetmap(run + " --html --out replay", dir).exit_code, 0);
    auto plain = nlohmann::json::parse(slurp(dir / "plain" / "metrics.json"));
    auto replay = nlohmann::json::parse(slurp(dir / "replay" / "metrics.json"));
    plain.erase("timing");
    replay.erase("timing");
    EXPECT_EQ(plain, replay) << strategy;
    std::filesystem::remove_all(dir / "plain");
    std::filesystem::remove_all(dir / "replay");
  }
}

// The comparison page: both runs, their distances as the runs report them (metrics.json), not
// re-measured from the page's poses; what is not a replay, or not an .html name, refused.
TEST(ReplayCompare, WritesOnePageWithTheRunsOwnNumbersAndRefusesWhatIsNotAReplay) {
  TempDir dir;
  ASSERT_EQ(run_fleetmap(kRun + "--steps 60 --html -o a", dir).exit_code, 0);
  ASSERT_EQ(run_fleetmap(kRun + "--steps 60 --strategy market --html --out b", dir).exit_code, 0);
  const auto r = run_fleetmap("replay-compare a/replay.html b/replay.html -o cmp.html", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = slurp(dir / "cmp.html");
  EXPECT_NE(page.find("<title>Comparing a and b</title>"), std::string::npos);
  EXPECT_EQ(page.find("http"), std::string::npos);
  const std::size_t start = page.find(">", page.find("id=\"summary\"")) + 1;
  const auto summary = nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  ASSERT_EQ(summary.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto metrics = nlohmann::json::parse(slurp(dir / (i == 0 ? "a" : "b") / "metrics.json"));
    const double distance = metrics["distance_m"].get<double>();
    ASSERT_GT(distance, 1.0);
    EXPECT_DOUBLE_EQ(summary[i]["distance"].get<double>(), std::round(distance * 10.0) / 10.0) << i;
  }
  // Not a replay page, a label per page missing, or not an .html name: one line, nothing written.
  EXPECT_ONE_LINE_ERROR(run_fleetmap("replay-compare a/replay.html a/map.yaml --out x.html", dir), "a/map.yaml: not a fleetmap replay page");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("replay-compare a/replay.html b/replay.html --label one --out x.html", dir), "--label");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("replay-compare a/replay.html --out x.html", dir), "two to four");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.html"));
  EXPECT_ONE_LINE_ERROR(run_fleetmap("replay-compare a/replay.html b/replay.html --out c.png", dir),
                        "--out c.png: the comparison is an HTML page; give a name ending in .html");
  EXPECT_FALSE(std::filesystem::exists(dir / "c.png"));
}

TEST(ReplayPage, ScenarioKeyAsksForThePage) {
  TempDir dir;
  dir.write("s.yaml", "map: maze\nsteps: 3\nrobots: {count: 2}\noutputs: {html: true}\n");
  ASSERT_EQ(run_fleetmap("explore --scenario s.yaml -q --out a", dir).exit_code, 0);
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "a" / "replay.html"));
  ASSERT_EQ(run_fleetmap("explore --map maze --steps 3 -q --out b", dir).exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "b" / "replay.html"));  // only when asked
  dir.write("bad.yaml", "map: maze\noutputs: {html: yes please}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario bad.yaml --out c", dir), "outputs.html");
  EXPECT_FALSE(std::filesystem::exists(dir / "c"));
}

bool have_chromium() { return std::system("command -v chromium >/dev/null 2>&1") == 0; }

// Skips only where FLEETMAP_NO_BROWSER=1 says there is no browser; else a missing chromium fails.
#define REQUIRE_CHROMIUM()                                                                                      \
  do {                                                                                                          \
    const char* no_browser = std::getenv("FLEETMAP_NO_BROWSER");                                                \
    if (no_browser && std::string(no_browser) == "1") GTEST_SKIP() << "FLEETMAP_NO_BROWSER=1: pages not checked in a browser"; \
    if (!have_chromium())                                                                                       \
      FAIL() << "chromium is not installed: run scripts/install-deps.sh (or set FLEETMAP_NO_BROWSER=1 to skip)";  \
  } while (false)

// The page's DOM after its script ran (and, with a virtual time budget, after its frames talked).
std::string dump_dom(const TempDir& dir, const std::filesystem::path& page, const std::string& fragment) {
  const auto out = dir / "dom.html";
  const std::string cmd = "timeout 120 chromium --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir='" +
                          (dir / "profile").string() + "' --virtual-time-budget=5000 --dump-dom 'file://" + page.string() +
                          "#" + fragment + "' >'" + out.string() + "' 2>'" + (dir / "chromium.log").string() + "'";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "chromium.log");
  return slurp(out);
}

// The why panel's rows: (class, score; NaN for none, taken by).
struct WhyRow {
  std::string cls;
  double score;
  int taken;
};
std::vector<WhyRow> why_rows(const std::string& dom) {
  std::vector<WhyRow> rows;
  const std::regex row(R"re(<tr class="([a-z]*)" data-score="([^"]*)" data-taken="(-?[0-9]+)")re");
  for (auto it = std::sregex_iterator(dom.begin(), dom.end(), row); it != std::sregex_iterator(); ++it) {
    const std::string s = (*it)[2];
    rows.push_back({(*it)[1], s.empty() ? std::numeric_limits<double>::quiet_NaN() : std::stod(s), std::stoi((*it)[3])});
  }
  return rows;
}

// A strategy a program registers that tells nothing of its reasons: each robot to its nearest target.
class SilentStrategy final : public exploration::CoordinationStrategy {
 public:
  std::string name() const override { return "silent-nearest"; }
  bool joint() const override { return false; }
  std::vector<int> assign(const exploration::AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    exploration::nearest_targets(input, out);
    return out;
  }
};

// A screenshot of `page#fragment` in headless chromium, `size` pixels wide and high.
cv::Mat screenshot(const TempDir& dir, const std::filesystem::path& page, const std::string& fragment, int size) {
  const auto shot = dir / "shot.png";
  std::filesystem::remove(shot);
  const std::string cmd = "timeout 120 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run "
                          "--user-data-dir='" + (dir / "profile").string() + "' --window-size=" + std::to_string(size) + "," +
                          std::to_string(size) + " --screenshot='" + shot.string() + "' 'file://" + page.string() + "#" +
                          fragment + "' >'" + (dir / "chromium.log").string() + "' 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "chromium.log");
  return cv::imread(shot.string(), cv::IMREAD_COLOR);
}

// Cells whose colour on the screenshot (at `scale` pixels per cell from the top-left corner)
// differs from the map's picture (viz::colorize, the colours of the PNGs a run writes).
int wrong_cells(const cv::Mat& shot, const mapping::OccupancyGrid& map, int scale, std::string& first) {
  const cv::Mat expected = viz::colorize(map);
  int wrong = 0;
  for (int y = 0; y < expected.rows; ++y)
    for (int x = 0; x < expected.cols; ++x) {
      const cv::Vec3b want = expected.at<cv::Vec3b>(y, x), got = shot.at<cv::Vec3b>(y * scale + scale / 2, x * scale + scale / 2);
      if (want == got) continue;
      if (wrong++ == 0) first = "cell column " + std::to_string(x) + ", image row " + std::to_string(y);
    }
  return wrong;
}

TEST(ReplayBrowser, CanvasShowsTheMapOfTheStep) {
  REQUIRE_CHROMIUM();
  TempDir dir;
  // The same run stopped at step 4 wrote the map of step 4; the replay of the run to step 8 must
  // show that map at step 4 (decoded forward from step 0) and its own map at step 8.
  ASSERT_EQ(run_fleetmap(kRun + "--steps 4 --out early", dir).exit_code, 0);
  ASSERT_EQ(run_fleetmap(kRun + "--steps 8 --html --out run", dir).exit_code, 0);
  const auto early = io::load_map(dir / "early" / "map.yaml");
  const auto late = io::load_map(dir / "run" / "map.yaml");
  ASSERT_FALSE(early.same_states(late)) << "the run should change the map between the steps compared";
  constexpr int kScale = 3;
  const int size = kScale * std::max(late.width(), late.height());
  const auto page = std::filesystem::absolute(dir / "run" / "replay.html");
  for (const auto& [step, map] : {std::pair{4, &early}, std::pair{8, &late}}) {
    const cv::Mat shot = screenshot(dir, page, "step=" + std::to_string(step) + "&only=map&overlays=0&scale=" + std::to_string(kScale), size);
    ASSERT_FALSE(shot.empty()) << "no screenshot: " << slurp(dir / "chromium.log");
    ASSERT_GE(shot.cols, map->width() * kScale);
    ASSERT_GE(shot.rows, map->height() * kScale);
    std::string first;
    EXPECT_EQ(wrong_cells(shot, *map, kScale, first), 0) << "step " << step << ", first at " << first;
  }
  // A robot's own map (in its own frame, stored against the merged map) at step 4: robot_2.yaml of
  // the early run.
  const auto own = io::load_map(dir / "early" / "robot_2.yaml");
  const cv::Mat own_shot = screenshot(dir, page, "step=4&only=robot&robot=2&scale=" + std::to_string(kScale), size);
  ASSERT_FALSE(own_shot.empty());
  std::string first_own;
  EXPECT_EQ(wrong_cells(own_shot, own, kScale, first_own), 0) << "robot 2's map at step 4, first at " << first_own;
  // With the overlays the robots are drawn over the map: the picture differs from the bare map.
  const cv::Mat decorated = screenshot(dir, page, "step=8&only=map&scale=" + std::to_string(kScale), size);
  std::string first;
  EXPECT_GT(wrong_cells(decorated, late, kScale, first), 0);

  // The why panel of robot 2 at step 8: the directional strategy's candidates ranked by its score,
  // the chosen one first and no candidate with a lower score (it decides robot by robot).
  const std::string dom = dump_dom(dir, page, "step=8&robot=2");
  EXPECT_NE(dom.find("<div id=\"whyText\"><b>Chosen: cost / largest cost + weight * off = "), std::string::npos) << dom.substr(0, 2000);
  const std::vector<WhyRow> rows = why_rows(dom);
  ASSERT_GE(rows.size(), 2u) << "the why panel shows the candidates weighed";
  EXPECT_EQ(rows[0].cls, "chosen");
  for (const WhyRow& row : rows) EXPECT_GE(row.score, rows[0].score - 1e-9) << "a candidate scored better than the chosen one";
  for (std::size_t k = 1; k < rows.size(); ++k) EXPECT_GE(rows[k].score, rows[k - 1].score - 1e-9) << "the candidates are ranked";

  // Two runs compared: both frames show the step of the comparison page's slider, each with its why panel.
  ASSERT_EQ(run_fleetmap(kRun + "--steps 8 --strategy coordinated --html --out other", dir).exit_code, 0);
  ASSERT_EQ(run_fleetmap("replay-compare run/replay.html other/replay.html --out cmp.html", dir).exit_code, 0);
  const std::string cmp = dump_dom(dir, std::filesystem::absolute(dir / "cmp.html"), "step=5");
  EXPECT_NE(cmp.find("data-shown0=\"5\""), std::string::npos) << cmp.substr(0, 1500);
  EXPECT_NE(cmp.find("data-shown1=\"5\""), std::string::npos) << cmp.substr(0, 1500);
  EXPECT_NE(cmp.find("data-why1=\"Chosen: utility - beta * cost / largest cost = "), std::string::npos);
  EXPECT_NE(cmp.find("step 5 of 8: run "), std::string::npos);
}

// A strategy a program registers may report no scores: the page says so instead of breaking.
TEST(ReplayBrowser, AStrategyThatReportsNoScoresIsSaidSo) {
  REQUIRE_CHROMIUM();
  if (!exploration::strategy_registry().contains("silent-nearest"))
    exploration::register_strategy("silent-nearest", "nearest target, no scores",
                                    [](const exploration::StrategyOptions&) { return std::make_unique<SilentStrategy>(); });
  sim::Scenario s;
  s.map = "maze";
  s.robot_count = 2;
  s.steps = 4;
  s.exploration.strategy = "silent-nearest";
  s.html_replay = true;
  sim::Simulation simulation(s, maps::load_map_source("maze"));
  sim::RunReplay replay;
  const sim::RunResult result = simulation.run({}, [&](const sim::Simulation& sim) { replay.add_step(sim); });
  TempDir dir;
  const auto page = std::filesystem::absolute(dir / "replay.html");
  io::write_file_atomic(page, replay.html(result, "maze"));
  const std::string dom = dump_dom(dir, page, "step=4&robot=1");
  EXPECT_NE(dom.find("data-ready=\"1\""), std::string::npos) << "the page's script stopped";
  EXPECT_NE(dom.find("reports no scores"), std::string::npos) << dom.substr(0, 2000);
  EXPECT_TRUE(why_rows(dom).empty());
}

}  // namespace
}  // namespace fleetmap
