// `fleetmap explore --html`: the replay page, and the page in a real browser (Debian's chromium,
// headless): the maps its canvas shows at a step are the maps the run wrote for that step.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <string>

#include "io/map_io.h"
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
  if (!have_chromium()) GTEST_SKIP() << "chromium is not installed (apt-get install chromium): the replay page is not checked in a browser";
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
}

}  // namespace
}  // namespace fleetmap
