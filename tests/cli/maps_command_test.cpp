// End-to-end: `fleetmap maps` as a user runs it.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::TempDir;

TEST(MapsCommand, ListShowsEveryMapWithSizes) {
  TempDir dir;
  const auto r = run_fleetmap("maps list", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"empty", "unstructured", "office", "corridor", "cave", "maze", "warehouse", "campus"}) {
    EXPECT_NE(r.out.find(name), std::string::npos) << name;
  }
  EXPECT_NE(r.out.find("200x200"), std::string::npos);
  EXPECT_NE(r.out.find("20.0 x 20.0 m"), std::string::npos);
  EXPECT_NE(r.out.find("1200x1200"), std::string::npos);
}

TEST(MapsCommand, ShowRendersBuiltinAndFileMaps) {
  TempDir dir;
  auto r = run_fleetmap("maps show office --out office.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat img = cv::imread((dir / "office.png").string());
  ASSERT_FALSE(img.empty());
  EXPECT_GE(img.rows, 800);  // 200 cells scaled up by 4
  // A user's own image, and the same map through its YAML.
  r = run_fleetmap("maps show " + std::string(FLEETMAP_SOURCE_DIR) + "/maps/maze.yaml --out sub/maze.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "sub" / "maze.png"));
  r = run_fleetmap("maps show " + std::string(FLEETMAP_SOURCE_DIR) + "/maps/cave.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "cave_map.png"));
}

TEST(MapsCommand, BadInputGetsOneLineAndNonZeroExit) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show ofice", dir), "unknown map 'ofice'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show ofice", dir), "office");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show missing.png", dir), "missing.png: no such file");
  dir.write("empty.png", "");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show empty.png", dir), "empty.png: empty file");
  dir.write("junk.png", "junk junk junk");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show junk.png", dir), "junk.png: not a PNG or PGM image");
  dir.write("nores.yaml", "image: x.png\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show nores.yaml", dir), "missing key 'resolution'");
  dir.write("noimage.yaml", "resolution: 0.1\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show noimage.yaml", dir), "missing key 'image'");
  dir.write("neg.yaml", "image: x.png\nresolution: -1\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show neg.yaml", dir), "'resolution'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show office --max-cells 1000", dir), "size limit of 1000");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show office --resolution -2", dir), "--resolution");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps frobnicate", dir), "frobnicate");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("", dir), "subcommand");
  cv::imwrite((dir / "mine.png").string(), cv::Mat(20, 20, CV_8UC1, cv::Scalar(254)));
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show mine.png --out mine.png", dir), "overwrite");
}

TEST(MapsCommand, HelpExplainsTheFlags) {
  TempDir dir;
  const auto r = run_fleetmap("maps show --help", dir);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--out"), std::string::npos);
  EXPECT_NE(r.out.find("--max-cells"), std::string::npos);
  EXPECT_NE(r.out.find("64000000"), std::string::npos);
}

}  // namespace
}  // namespace fleetmap::cli
