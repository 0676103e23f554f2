#include "viz/replay.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "core/error.h"
#include "tests/test_support.h"
#include "viz/replay_compare.h"

namespace fleetmap::viz {
namespace {

using core::GridGeometry;

// The page's decoding, written again from the format replay.h documents.
std::vector<std::uint8_t> unbase64(const std::string& s) {
  const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<std::uint8_t> out;
  std::uint32_t bits = 0;
  int n = 0;
  for (char c : s) {
    if (c == '=') break;
    bits = bits << 6 | std::uint32_t(digits.find(c));
    n += 6;
    if (n >= 8) {
      n -= 8;
      out.push_back(std::uint8_t(bits >> n));
    }
  }
  return out;
}

std::vector<std::uint64_t> varints(const std::string& s) {
  std::vector<std::uint64_t> out;
  const auto bytes = unbase64(s);
  for (std::size_t i = 0; i < bytes.size();) {
    std::uint64_t v = 0;
    int shift = 0;
    std::uint8_t b = 0;
    do {
      b = bytes[i++];
      v |= std::uint64_t(b & 127) << shift;
      shift += 7;
    } while (b & 128);
    out.push_back(v);
  }
  return out;
}

std::vector<ReplayCell> decode_runs(const std::string& s) {
  std::vector<ReplayCell> out;
  for (auto v : varints(s)) out.insert(out.end(), v >> 2, ReplayCell(v & 3));
  return out;
}

// Applies encoded changes forward (new codes) or backward (old codes); false when an old code
// does not match what the cell holds.
bool apply(std::vector<ReplayCell>& cells, const std::string& s, bool forward) {
  long p = -1;
  for (auto v : varints(s)) {
    p += long(v >> 4) + 1;
    const auto old = ReplayCell((v >> 2) & 3), now = ReplayCell(v & 3);
    if (cells.at(std::size_t(p)) != (forward ? old : now)) return false;
    cells[std::size_t(p)] = forward ? now : old;
  }
  return true;
}

std::vector<ReplayCell> random_cells(std::mt19937& rng, std::size_t n) {
  std::vector<ReplayCell> out(n);
  std::uniform_int_distribution<int> code(0, 3);
  // Long runs, as maps have.
  for (std::size_t i = 0; i < n;) {
    const auto c = ReplayCell(code(rng));
    const std::size_t run = std::uniform_int_distribution<std::size_t>(1, 300)(rng);
    for (std::size_t k = 0; k < run && i < n; ++k) out[i++] = c;
  }
  return out;
}

TEST(ReplayEncoding, RunsDecodeToTheCells) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    const auto cells = random_cells(rng, 5000 + std::size_t(trial) * 37);
    EXPECT_EQ(decode_runs(encode_runs(cells)), cells);
  }
}

TEST(ReplayEncoding, ChangesStepForwardAndBack) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const auto before = random_cells(rng, 20000);
    auto after = before;
    // A few scattered changes and one dense patch, as a scan makes; sometimes none.
    const int changes = trial % 5 == 0 ? 0 : 1 + int(rng() % 400);
    for (int k = 0; k < changes; ++k) after[rng() % after.size()] = ReplayCell(rng() % 4);
    const std::string encoded = encode_changes(before, after);
    if (before == after) {
      EXPECT_TRUE(encoded.empty());
      continue;
    }
    auto cells = before;
    ASSERT_TRUE(apply(cells, encoded, true));
    EXPECT_EQ(cells, after);
    ASSERT_TRUE(apply(cells, encoded, false));
    EXPECT_EQ(cells, before);
  }
}

TEST(ReplayEncoding, FewChangesCostFewBytes) {
  // A step that changes 100 cells of a 1200 x 1200 map is stored in about 100 varints.
  std::vector<ReplayCell> before(1200 * 1200, ReplayCell::Unknown);
  auto after = before;
  for (int k = 0; k < 100; ++k) after[std::size_t(600 * 1200 + 500 + k)] = ReplayCell::Free;
  EXPECT_LE(encode_changes(before, after).size(), 4u * (100 + 3) / 3 + 8);
}

TEST(ReplayLayer, WholePictureOnlyWhereTheGeometryChanges) {
  ReplayLayer layer("robot 1's map");
  const GridGeometry small(0.1, 20, 10), large(0.1, 40, 40, core::Pose2(-2, -2, 0.5));
  std::vector<ReplayCell> cells(200, ReplayCell::Unknown);
  layer.add_step(small, cells);
  cells[45] = ReplayCell::Free;
  layer.add_step(small, cells);
  layer.add_step(small, cells);
  std::vector<ReplayCell> moved(1600, ReplayCell::Occupied);
  layer.add_step(large, moved);
  const auto j = layer.to_json();
  ASSERT_EQ(j["frames"].size(), 2u);
  EXPECT_EQ(j["frames"][0]["step"], 0);
  EXPECT_EQ(j["frames"][1]["step"], 3);
  EXPECT_EQ(j["frames"][1]["width"], 40);
  EXPECT_DOUBLE_EQ(j["frames"][1]["origin"][2].get<double>(), 0.5);
  EXPECT_EQ(decode_runs(j["frames"][1]["cells"]), moved);
  ASSERT_EQ(j["changes"].size(), 4u);
  EXPECT_NE(j["changes"][1], "");  // the one changed cell
  EXPECT_EQ(j["changes"][2], "");  // nothing changed
  EXPECT_EQ(j["changes"][3], "");  // a whole picture instead
  EXPECT_THROW(layer.add_step(small, moved), Error);  // codes for another geometry
}

Replay tiny_replay() {
  Replay r;
  r.title = "test <map>";
  r.coverage = {0.1, 0.2};
  r.merged = ReplayLayer("merged map");
  const GridGeometry g(0.1, 10, 10);
  std::vector<ReplayCell> cells(100, ReplayCell::Free);
  r.merged.add_step(g, cells);
  r.merged.add_step(g, cells);
  ReplayRobot robot;
  robot.name = "robot 1";
  robot.color = palette_color(0);
  robot.truth = robot.estimate = robot.frame = {core::Pose2(0.5, 0.5, 0), core::Pose2(0.6, 0.5, 0)};
  robot.plan = {-1, -1};
  robot.passed = {0, 0};
  robot.finished = {0, 1};
  r.robots.push_back(robot);
  r.robot_maps.push_back(r.merged);
  r.events.push_back({1, "refused merge", 0, -1, "a text with </script> and <b>", std::nullopt});
  return r;
}

TEST(ReplayPage, SelfContainedAndItsDataCannotCloseTheScript) {
  const std::string page = replay_html(tiny_replay());
  // Nothing is fetched: no address, no external script, style or image.
  for (const char* fetch : {"http://", "https://", "src=", "<link", "@import", "url("}) {
    EXPECT_EQ(page.find(fetch), std::string::npos) << fetch;
  }
  // The data script and the page's script close once each; the event's "</script>" is escaped.
  std::size_t closes = 0;
  for (std::size_t p = page.find("</script>"); p != std::string::npos; p = page.find("</script>", p + 1)) ++closes;
  EXPECT_EQ(closes, 2u);
  EXPECT_NE(page.find("<title>test &lt;map&gt;</title>"), std::string::npos);
  // The data parses back as JSON with what went in.
  const std::size_t start = page.find(">", page.find("id=\"data\"")) + 1;
  const auto data = nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  EXPECT_EQ(data["events"][0]["text"], "a text with </script> and <b>");
  EXPECT_EQ(data["robots"][0]["finished"], "01");
  EXPECT_EQ(data["robots"][0]["truth"][3], 60);  // centimetres
  EXPECT_FALSE(data["robots"][0].contains("estimate"));  // ideal localization: the truth is drawn
}

// The strategy's reasons: each decision's candidates as compact rows, NaN scores as null, and a note
// shared by many decisions stored once.
TEST(ReplayPage, DecisionsKeepTheirCandidatesAndNotesOnce) {
  Replay r = tiny_replay();
  r.scores = {"directional", {"wave cost (m)", "off its direction (0-1)"}, "rank", true, "the lowest rank wins"};
  ReplayDecision d;
  d.step = 1;
  d.weighed = 5;
  d.chosen = 0;
  d.reported = true;
  d.note = "its own direction: 0 deg";
  d.goal_m = Eigen::Vector2d(0.7, 0.5);
  d.candidates = {{{0.8, 0.5}, {0.7, 0.5}, 4, {1.23456, 0.5}, 0.9, -1},
                  {{0.2, 0.9}, {0.2, 0.8}, 3, {2.0, std::numeric_limits<double>::quiet_NaN()}, std::numeric_limits<double>::quiet_NaN(), 0}};
  r.robots[0].decisions = {d, d};
  r.robots[0].decisions[1].step = 2;
  const std::string page = replay_html(r);
  const std::size_t start = page.find(">", page.find("id=\"data\"")) + 1;
  const auto data = nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  EXPECT_EQ(data["scores"]["terms"].size(), 2u);
  EXPECT_EQ(data["scores"]["lower"], true);
  ASSERT_EQ(data["robots"][0]["decisions"].size(), 2u);
  EXPECT_EQ(data["notes"].size(), 1u);
  const auto& first = data["robots"][0]["decisions"][0];
  EXPECT_EQ(first["t"], 0);
  EXPECT_EQ(first["n"], 5);
  EXPECT_EQ(first["goal"], nlohmann::json::array({70, 50}));
  // [frontier x, y, goal x, y (cm), cells, score, taken by, terms...], three decimals.
  EXPECT_EQ(first["k"][0], nlohmann::json::parse("[80, 50, 70, 50, 4, 0.9, -1, 1.235, 0.5]"));
  EXPECT_TRUE(first["k"][1][5].is_null());
  EXPECT_TRUE(first["k"][1][8].is_null());
  EXPECT_EQ(first["k"][1][6], 0);
}

// The comparison page holds every run's page whole (as JSON text) and a summary of each: nothing
// is fetched, and no run's text can close the page's scripts.
TEST(ReplayCompare, HoldsEveryRunAndItsSummary) {
  Replay a = tiny_replay(), b = tiny_replay();
  a.robots[0].distance_m = 0.1234;  // the run's own, which the poses (0.1 m apart) need not match
  a.facts = {{"steps", "2"}, {"95%", "never"}};
  b.facts = {{"steps", "2"}, {"95%", "step 1"}};
  b.coverage = {0.1, 0.96};
  const std::vector<ComparedReplay> runs = {{"run <a>", replay_html(a)}, {"b", replay_html(b)}};
  const std::string page = replay_comparison_html(runs);
  for (const char* fetch : {"http://", "https://", "src=", "<link", "@import", "url("}) EXPECT_EQ(page.find(fetch), std::string::npos) << fetch;
  std::size_t closes = 0;
  for (std::size_t p = page.find("</script>"); p != std::string::npos; p = page.find("</script>", p + 1)) ++closes;
  EXPECT_EQ(closes, 4u);  // the summary, two pages, the script
  EXPECT_NE(page.find("<title>Comparing run &lt;a&gt; and b</title>"), std::string::npos);
  const auto script = [&](const std::string& id) {
    const std::size_t start = page.find(">", page.find("id=\"" + id + "\"")) + 1;
    return nlohmann::json::parse(page.substr(start, page.find("</script>", start) - start));
  };
  const auto summary = script("summary");
  ASSERT_EQ(summary.size(), 2u);
  EXPECT_EQ(summary[0]["label"], "run <a>");
  EXPECT_EQ(summary[1]["coverage"][1], 0.96);
  EXPECT_EQ(summary[1]["facts"][1][1], "step 1");
  EXPECT_EQ(summary[0]["events"]["refused merge"], 1);
  EXPECT_NEAR(summary[0]["distance"].get<double>(), 0.1, 1e-9);
  EXPECT_EQ(script("page0").get<std::string>(), runs[0].page);
  EXPECT_EQ(script("page1").get<std::string>(), runs[1].page);
  // A page written before pages carried the run's distance: none shown rather than one re-measured.
  std::string old_page = runs[1].page;
  const std::size_t at = old_page.find("\"distance\":0.0,");
  ASSERT_NE(at, std::string::npos);
  old_page.erase(at, std::string("\"distance\":0.0,").size());
  const std::string old_compare = replay_comparison_html({runs[0], {"old", old_page}});
  const std::size_t start = old_compare.find(">", old_compare.find("id=\"summary\"")) + 1;
  const auto old_summary = nlohmann::json::parse(old_compare.substr(start, old_compare.find("</script>", start) - start));
  EXPECT_FALSE(old_summary[1].contains("distance"));
}

TEST(ReplayCompare, RefusesWhatIsNotAReplay) {
  fleetmap::testing::expect_input_error([] { replay_page_data("<html><body>a page</body></html>", "x.html"); },
                                        {"x.html", "not a fleetmap replay page"});
  const std::string page = replay_html(tiny_replay());
  fleetmap::testing::expect_input_error([&] { replay_comparison_html({{"a", page}}); }, {"two replay pages"});
  std::string broken = page;
  broken.insert(broken.find(">", broken.find("id=\"data\"")) + 1, "{");
  fleetmap::testing::expect_input_error([&] { replay_comparison_html({{"a", page}, {"b", broken}}); }, {"b:", "does not parse"});
}

}  // namespace
}  // namespace fleetmap::viz
