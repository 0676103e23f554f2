#include "io/map_image.h"
#include "io/map_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "io/file_io.h"
#include "tests/test_support.h"

namespace fleetmap::io {
namespace {

using core::GridGeometry;
using mapping::CellState;
using mapping::OccupancyGrid;
using mapping::OccupancyGridOptions;

using fleetmap::testing::expect_input_error;
using fleetmap::testing::TempDir;

OccupancyGrid random_grid(int w, int h, double res, std::uint32_t seed) {
  OccupancyGrid g(GridGeometry(res, w, h, core::Pose2(-3.5, 1.25, 0.0)));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> s(0, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) g.set_state({x, y}, static_cast<CellState>(s(rng)));
  return g;
}

TEST(MapIo, PngToGridToPgmYamlToGridIsIdentical) {
  TempDir dir;
  const auto original = random_grid(37, 23, 0.05, 1);
  save_map_image(original, dir / "a.png");
  MapLoadOptions load;
  load.default_resolution = 0.05;
  const auto from_png = load_map(dir / "a.png", load);
  ASSERT_EQ(from_png.width(), 37);
  ASSERT_EQ(from_png.height(), 23);
  for (int y = 0; y < 23; ++y)
    for (int x = 0; x < 37; ++x) ASSERT_EQ(from_png.state({x, y}), original.state({x, y})) << x << "," << y;

  // PGM + YAML keep resolution and origin too.
  save_map_yaml(original, dir / "saved.yaml");
  EXPECT_TRUE(std::filesystem::exists(dir / "saved.pgm"));
  const auto from_yaml = load_map(dir / "saved.yaml");
  EXPECT_TRUE(from_yaml.same_states(original));
  EXPECT_EQ(from_yaml.geometry(), original.geometry());
}

// map_image: map_saver's grey values, the top cell row as the image's first row.
TEST(MapImage, PixelsAreMapSaverValuesTopRowFirst) {
  OccupancyGrid g(GridGeometry(0.1, 3, 2, core::Pose2(1.0, -2.0, 0.0)));
  g.set_state({0, 0}, CellState::Occupied);  // bottom left
  g.set_state({1, 0}, CellState::Free);
  g.set_state({2, 1}, CellState::Free);      // top right
  g.set_state({0, 1}, CellState::Occupied);  // top left
  const MapImage image = map_image(g);
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 2);
  EXPECT_EQ(image.pixels, (std::vector<std::uint8_t>{0, 205, 254,     // top row: cell row 1
                                                     0, 254, 205}));  // bottom row: cell row 0
}

// An image of map_saver's values becomes a grid with map_server's rules and gives the same image
// back, directly and through files (save, load): 0 occupied, 254 free, 205 unknown.
TEST(MapImage, RoundTripKeepsMapServerValues) {
  std::mt19937 rng(7);
  const std::uint8_t values[3] = {0, 254, 205};
  std::uniform_int_distribution<int> pick(0, 2);
  MapImage image{29, 17, {}};
  for (int i = 0; i < image.width * image.height; ++i) image.pixels.push_back(values[pick(rng)]);
  MapYaml meta;
  meta.resolution = 0.025;
  meta.origin = core::Pose2(-1.5, 2.0, 0.0);
  const OccupancyGrid grid = grid_from_map_image(image, meta);
  EXPECT_EQ(grid.width(), image.width);
  EXPECT_EQ(grid.height(), image.height);
  EXPECT_DOUBLE_EQ(grid.resolution(), 0.025);
  // Image row r is cell row height - 1 - r.
  for (int r = 0; r < image.height; ++r) {
    for (int c = 0; c < image.width; ++c) {
      const std::uint8_t v = image.pixels[std::size_t(r * image.width + c)];
      const CellState expected = v == 0 ? CellState::Occupied : v == 254 ? CellState::Free : CellState::Unknown;
      ASSERT_EQ(grid.state({c, image.height - 1 - r}), expected) << "pixel " << c << ", " << r;
    }
  }
  EXPECT_EQ(map_image(grid).pixels, image.pixels);

  TempDir dir;
  save_map_yaml(grid, dir / "m.yaml");
  const OccupancyGrid loaded = load_map(dir / "m.yaml");
  EXPECT_DOUBLE_EQ(loaded.resolution(), 0.025);
  EXPECT_DOUBLE_EQ(loaded.geometry().origin().x, -1.5);
  EXPECT_EQ(map_image(loaded).pixels, image.pixels);
}

TEST(MapImageBadInput, WrongPixelCountOrEmptyImageIsRefused) {
  const MapYaml meta;
  expect_input_error([&] { grid_from_map_image(MapImage{3, 2, std::vector<std::uint8_t>(5, 254)}, meta); },
                     {"map image", "got 5 for 3 x 2"});
  expect_input_error([&] { grid_from_map_image(MapImage{}, meta); }, {"map image", "got 0 for 0 x 0"});
  expect_input_error([&] { grid_from_map_image(MapImage{-2, -3, std::vector<std::uint8_t>(6, 0)}, meta); },
                     {"map image", "-2 x -3"});
}

TEST(MapIo, YamlMatchesMapSaverFormat) {
  MapYaml y;
  y.image = "map.pgm";
  y.resolution = 0.05;
  y.origin = core::Pose2(-10.0, -5.5, 0.0);
  const std::string text = format_map_yaml(y);
  EXPECT_NE(text.find("image: map.pgm\n"), std::string::npos);
  EXPECT_NE(text.find("origin: [-10.000000, -5.500000, 0.000000]"), std::string::npos);
  EXPECT_NE(text.find("occupied_thresh: 0.650"), std::string::npos);
  EXPECT_NE(text.find("free_thresh: 0.196"), std::string::npos);
  const MapYaml back = parse_map_yaml(text, "test.yaml");
  EXPECT_EQ(back.image, y.image);
  EXPECT_DOUBLE_EQ(back.resolution, 0.05);
  EXPECT_DOUBLE_EQ(back.origin.x, -10.0);
  EXPECT_DOUBLE_EQ(back.origin.y, -5.5);
}

// Numbers a user chose come back as chosen, not rounded to map_saver's six decimals; file names
// that YAML would misread are quoted.
TEST(MapIo, YamlKeepsEveryDigitAndOddFileNames) {
  MapYaml y;
  y.image = "my map: v2.pgm";
  y.resolution = 0.05 / 3.0;
  y.origin = core::Pose2(-10.0, 1e-7, 0.25);
  y.free_thresh = 0.1965;
  const std::string text = format_map_yaml(y);
  const MapYaml back = parse_map_yaml(text, "test.yaml");
  EXPECT_EQ(back.image, y.image);
  EXPECT_EQ(back.resolution, y.resolution) << text;
  EXPECT_EQ(back.origin, y.origin) << text;
  EXPECT_EQ(back.free_thresh, y.free_thresh) << text;
  EXPECT_NE(text.find("origin: [-10.000000, "), std::string::npos);  // map_saver's form where it is exact
}

cv::Mat decode(const std::string& bytes) { return decode_map_image(bytes, "test.pgm"); }

std::vector<int> pixels(const cv::Mat& m) {
  std::vector<int> v;
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols * m.channels(); ++x) v.push_back(m.ptr<std::uint8_t>(y)[x]);
  return v;
}

// PGM, PBM and PPM, plain and raw, 8- and 16-bit: samples scaled to 0-255 by maxval; PBM 1 is black;
// PPM comes out blue first, as OpenCV's images.
TEST(MapIo, EveryNetpbmKindDecodes) {
  EXPECT_EQ(pixels(decode("P2\n# a comment\n3 1\n15\n0 15 7\n")), (std::vector<int>{0, 255, 119}));
  EXPECT_EQ(pixels(decode(std::string("P5 2 1 255\n\x00\xc8", 13))), (std::vector<int>{0, 200}));
  EXPECT_EQ(pixels(decode(std::string("P5\n2 1\n65535\n\x00\x00\xff\xff", 17))), (std::vector<int>{0, 255}));
  EXPECT_EQ(pixels(decode("P1\n3 1\n0 1 0\n")), (std::vector<int>{255, 0, 255}));
  EXPECT_EQ(pixels(decode("P1\n3 1\n010")), (std::vector<int>{255, 0, 255}));
  EXPECT_EQ(pixels(decode("P4\n3 1\n\x40")), (std::vector<int>{255, 0, 255}));
  EXPECT_EQ(pixels(decode("P6 1 1 255\n\x0a\x14\x1e")), (std::vector<int>{30, 20, 10}));
  EXPECT_EQ(pixels(decode("P3\n1 1\n255\n10 20 30\n")), (std::vector<int>{30, 20, 10}));
  const cv::Mat decoded = decode("P2\n2 2\n255\n1 2\n3 4\n");
  EXPECT_EQ(decoded.rows, 2);
  EXPECT_EQ(decoded.at<std::uint8_t>(1, 0), 3);
  // What OpenCV writes reads back the same.
  cv::Mat image(5, 7, CV_8UC1);
  for (int i = 0; i < 35; ++i) image.data[i] = std::uint8_t(i * 7);
  std::vector<std::uint8_t> pgm;
  cv::imencode(".pgm", image, pgm);
  EXPECT_EQ(pixels(decode(std::string(pgm.begin(), pgm.end()))), pixels(image));
}

TEST(MapIoBadInput, BrokenNetpbmImages) {
  expect_input_error([] { decode(std::string("P5\n4 4\n255\n\x00\x00", 13)); }, {"test.pgm", "cannot decode PGM", "truncated"});
  expect_input_error([] { decode("P2\n2 1\n15\n3 16\n"); }, {"test.pgm", "above maxval 15"});
  expect_input_error([] { decode("P2\n2 1\n0\n0 0\n"); }, {"test.pgm", "maxval"});
  expect_input_error([] { decode("P2\n2 1\n255\n0\n"); }, {"test.pgm", "ends before"});
  expect_input_error([] { decode("P3\n1 1\n255\n10 x 30\n"); }, {"test.pgm", "cannot decode PPM"});
}

TEST(MapIoBadInput, HugeDeclaredSizesAreRefusedWithoutOverflow) {
  // Found by fuzzing: a PNG header of about 2^31 x 2^30 pixels made the size message multiply past 64 bits.
  const std::string pgm = "P5\n1099511627776 1099511627776\n255\n";
  expect_input_error([&] { decode(pgm); }, {"image is 1099511627776x1099511627776 = more than 9e18 cells, over the size limit"});
}

// One row of grey pixels; map_server: occ = (255 - v) / 255, occupied > 0.65, free < 0.196.
cv::Mat grey_row(const std::vector<int>& values) {
  cv::Mat m(1, int(values.size()), CV_8UC1);
  for (std::size_t i = 0; i < values.size(); ++i) m.at<std::uint8_t>(0, int(i)) = std::uint8_t(values[i]);
  return m;
}

std::vector<CellState> states(const OccupancyGrid& g) {
  std::vector<CellState> s;
  for (int x = 0; x < g.width(); ++x) s.push_back(g.state({x, 0}));
  return s;
}

TEST(MapIo, TrinaryThresholdsAsMapServer) {
  using S = CellState;
  const cv::Mat row = grey_row({0, 50, 89, 100, 150, 205, 206, 230, 254, 255});
  MapYaml meta;
  // occ:                      1     .80   .651  .608  .41   .196078 .192  .098  .004  0
  EXPECT_EQ(states(grid_from_image(row, meta)),
            (std::vector<S>{S::Occupied, S::Occupied, S::Occupied, S::Unknown, S::Unknown, S::Unknown, S::Free,
                            S::Free, S::Free, S::Free}));
  meta.occupied_thresh = 0.5;
  meta.free_thresh = 0.3;
  // map_saver's unknown grey 205 stays unknown in trinary mode whatever free_thresh says (nav2's
  // map_saver wrote 0.25); scale mode and negated maps keep the thresholds' reading.
  EXPECT_EQ(states(grid_from_image(row, meta)),
            (std::vector<S>{S::Occupied, S::Occupied, S::Occupied, S::Occupied, S::Unknown, S::Unknown, S::Free,
                            S::Free, S::Free, S::Free}));
  meta.mode = MapMode::Scale;
  EXPECT_EQ(grid_from_image(row, meta).state({5, 0}), S::Free);
  meta.mode = MapMode::Trinary;
  meta.negate = true;  // 205 reads as 50: occ 0.80, a wall
  EXPECT_EQ(grid_from_image(row, meta).state({5, 0}), S::Occupied);
}

TEST(MapIo, NegateInvertsColours) {
  using S = CellState;
  MapYaml meta;
  meta.negate = true;
  // With negate, occ = v / 255: white is occupied, black free.
  EXPECT_EQ(states(grid_from_image(grey_row({0, 40, 50, 200, 255}), meta)),
            (std::vector<S>{S::Free, S::Free, S::Unknown, S::Occupied, S::Occupied}));
}

TEST(MapIo, ColourPixelsUseTheMeanOfRgbAndRowsAreFlipped) {
  cv::Mat img(2, 2, CV_8UC3, cv::Scalar(255, 255, 255));
  img.at<cv::Vec3b>(0, 0) = {0, 0, 255};    // mean 85: occ 0.667, occupied; top-left pixel
  img.at<cv::Vec3b>(1, 1) = {0, 255, 255};  // mean 170: occ 0.333, unknown
  const auto g = grid_from_image(img, MapYaml{});
  EXPECT_EQ(g.state({0, 1}), CellState::Occupied);  // image row 0 is the top row of the map
  EXPECT_EQ(g.state({1, 0}), CellState::Unknown);
  EXPECT_EQ(g.state({0, 0}), CellState::Free);
}

TEST(MapIo, ScaleModeKeepsProbabilitiesAndAlphaMeansUnknown) {
  MapYaml meta;
  meta.mode = MapMode::Scale;
  const auto g = grid_from_image(grey_row({150}), meta);
  const double occ = (255.0 - 150.0) / 255.0;
  const double p = (1.0 + 98.0 * (occ - 0.196) / (0.65 - 0.196)) / 100.0;
  EXPECT_NEAR(g.probability({0, 0}), p, 1e-4);
  cv::Mat rgba(1, 2, CV_8UC4, cv::Scalar(150, 150, 150, 255));
  rgba.at<cv::Vec4b>(0, 1)[3] = 100;
  const auto ga = grid_from_image(rgba, meta);
  EXPECT_NEAR(ga.probability({0, 0}), p, 1e-4);
  EXPECT_FLOAT_EQ(ga.log_odds({1, 0}), 0.0f);
}

// Every grey value, as map_server reads it: map_server's rules for opaque pixels and partly transparent ones (between the thresholds: unknown
// in scale mode); a pixel less than half opaque is unknown whatever its colour (a transparent
// background was never drawn on).
TEST(MapIo, EveryGreyValueOpaquePartlyTransparentOrTransparent) {
  MapYaml meta;
  meta.mode = MapMode::Scale;
  cv::Mat rgba(3, 256, CV_8UC4);
  for (int v = 0; v < 256; ++v) {
    rgba.at<cv::Vec4b>(0, v) = {std::uint8_t(v), std::uint8_t(v), std::uint8_t(v), 255};
    rgba.at<cv::Vec4b>(1, v) = {std::uint8_t(v), std::uint8_t(v), std::uint8_t(v), 200};
    rgba.at<cv::Vec4b>(2, v) = {std::uint8_t(v), std::uint8_t(v), std::uint8_t(v), 0};
  }
  const auto g = grid_from_image(rgba, meta);
  for (int v = 0; v < 256; ++v) {
    const double occ = (255.0 - v) / 255.0;
    EXPECT_EQ(g.log_odds({v, 0}), 0.0f) << v;  // image row 2, transparent: unknown
    for (const bool opaque : {true, false}) {
      const float l = g.log_odds({v, opaque ? 2 : 1});  // image row 0 is the map's top row
      if (occ > meta.occupied_thresh) EXPECT_EQ(l, g.max_log_odds()) << v;
      else if (occ < meta.free_thresh) EXPECT_EQ(l, g.min_log_odds()) << v;
      else if (!opaque) EXPECT_EQ(l, 0.0f) << v;
      else {
        // Clamped as every update is (the grid's bounds keep it able to change).
        const double p = (1.0 + 98.0 * (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh)) / 100.0;
        EXPECT_NEAR(g.probability({v, 2}), std::clamp(p, g.options().min_probability, g.options().max_probability), 1e-6) << v;
      }
    }
  }
}

TEST(MapIo, RawModeReadsPercentages) {
  MapYaml meta;
  meta.mode = MapMode::Raw;
  const auto g = grid_from_image(grey_row({0, 100, 90, 255}), meta);
  EXPECT_EQ(g.state({0, 0}), CellState::Free);
  EXPECT_EQ(g.state({1, 0}), CellState::Occupied);
  EXPECT_NEAR(g.probability({2, 0}), 0.9, 1e-4);
  EXPECT_EQ(g.state({3, 0}), CellState::Unknown);
}

// ---- bad input: every kind gets one line naming the file and the problem ----

TEST(MapIoBadInput, MissingFile) {
  TempDir dir;
  expect_input_error([&] { load_map(dir / "nope.png"); }, {"nope.png", "no such file"});
  expect_input_error([&] { load_map(dir / "nope.yaml"); }, {"nope.yaml", "no such file"});
}

TEST(MapIoBadInput, DirectoryInsteadOfFile) {
  TempDir dir;
  std::filesystem::create_directories(dir / "d.png");
  expect_input_error([&] { load_map(dir / "d.png"); }, {"d.png", "directory"});
}

TEST(MapIoBadInput, EmptyAndUndecodableImages) {
  TempDir dir;
  expect_input_error([&] { load_map(dir.write("empty.png", "")); }, {"empty.png", "empty file"});
  expect_input_error([&] { load_map(dir.write("text.png", "this is not an image")); }, {"text.png", "not a PNG or PGM image"});
  std::vector<std::uint8_t> png;
  cv::imencode(".png", cv::Mat(50, 50, CV_8UC1, cv::Scalar(254)), png);
  const std::string truncated(png.begin(), png.begin() + 40);
  expect_input_error([&] { load_map(dir.write("cut.png", truncated)); }, {"cut.png", "cannot decode"});
  // Formats OpenCV could decode but that are no map format are refused before decoding.
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", cv::Mat(50, 50, CV_8UC1, cv::Scalar(254)), jpeg);
  expect_input_error([&] { load_map(dir.write("photo.png", std::string(jpeg.begin(), jpeg.end()))); },
                     {"photo.png", "a JPEG image; fleetmap reads maps as PNG or PGM: convert it to PNG"});
}

TEST(MapIoBadInput, ImageOverTheSizeLimit) {
  TempDir dir;
  cv::imwrite((dir / "big.png").string(), cv::Mat(300, 300, CV_8UC1, cv::Scalar(254)));
  MapLoadOptions o;
  o.max_cells = 10000;
  expect_input_error([&] { load_map(dir / "big.png", o); }, {"big.png", "300x300", "size limit of 10000"});
  // A PGM whose header declares a huge size is refused before any decoding.
  expect_input_error([&] { load_map(dir.write("huge.pgm", "P5\n100000 100000\n255\n"), o); },
                     {"huge.pgm", "100000x100000", "size limit"});
}

TEST(MapIoBadInput, YamlProblemsNameTheKey) {
  TempDir dir;
  cv::imwrite((dir / "m.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(254)));
  const auto yaml = [&](const std::string& name, const std::string& text) { return dir.write(name, text); };
  expect_input_error([&] { load_map(yaml("noimage.yaml", "resolution: 0.05\n")); }, {"noimage.yaml", "missing key 'image'"});
  expect_input_error([&] { load_map(yaml("nores.yaml", "image: m.png\n")); }, {"nores.yaml", "missing key 'resolution'"});
  expect_input_error([&] { load_map(yaml("zero.yaml", "image: m.png\nresolution: 0\n")); },
                     {"zero.yaml:2", "'resolution'", "a number >= 0.0001 and <= 1000"});
  expect_input_error([&] { load_map(yaml("neg.yaml", "image: m.png\nresolution: -0.1\n")); },
                     {"neg.yaml:2", "'resolution'", "-0.1"});
  expect_input_error([&] { load_map(yaml("text.yaml", "image: m.png\nresolution: fine\n")); },
                     {"text.yaml:2", "'resolution'", "fine"});
  expect_input_error([&] { load_map(yaml("nan.yaml", "image: m.png\nresolution: .nan\n")); },
                     {"nan.yaml:2", "'resolution'"});
  expect_input_error([&] { load_map(yaml("key.yaml", "image: m.png\nresolution: 0.1\ncolour: red\n")); },
                     {"key.yaml:3", "unknown key 'colour'"});
  expect_input_error([&] { load_map(yaml("origin.yaml", "image: m.png\nresolution: 0.1\norigin: [1, 2]\n")); },
                     {"origin.yaml:3", "'origin'", "[x, y, yaw]"});
  expect_input_error([&] { load_map(yaml("mode.yaml", "image: m.png\nresolution: 0.1\nmode: fancy\n")); },
                     {"mode.yaml:3", "'mode'", "fancy"});
  expect_input_error([&] { load_map(yaml("thresh.yaml", "image: m.png\nresolution: 0.1\nfree_thresh: 0.8\n")); },
                     {"thresh.yaml", "free_thresh"});
  expect_input_error([&] { load_map(yaml("syntax.yaml", "image: [m.png\nresolution: 0.1\n")); },
                     {"syntax.yaml", "not valid YAML"});
  expect_input_error([&] { load_map(yaml("lost.yaml", "image: gone.png\nresolution: 0.1\n")); },
                     {"lost.yaml", "gone.png", "does not exist"});
  expect_input_error([&] { load_map(yaml("list.yaml", "- 1\n- 2\n")); }, {"list.yaml", "expected a map_server YAML"});
}

TEST(MapIoBadInput, BareImageWithBadResolution) {
  TempDir dir;
  cv::imwrite((dir / "m.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(254)));
  MapLoadOptions o;
  o.default_resolution = 0.0;
  expect_input_error([&] { load_map(dir / "m.png", o); }, {"m.png", "resolution"});
}

// fleetmap writes PNG with libpng itself (it does not link OpenCV's image-file module); the files
// must stay byte for byte what cv::imencode writes, as the committed maps and every earlier output
// were: seeded images of each kind fleetmap writes (map images, pictures with and without alpha,
// 16-bit), noise and flat areas with lines, at OpenCV's fast default and at level 9.
TEST(MapIoEncode, PngBytesAreOpenCvsAndPgmIsNetpbm) {
  cv::RNG rng(7);
  const int types[] = {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1};
  for (int i = 0; i < 24; ++i) {
    const int w = 1 + rng.uniform(0, 200), h = 1 + rng.uniform(0, 200);
    cv::Mat image(h, w, types[i % 4]);
    if (i % 3 == 0) {
      rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    } else {
      image.setTo(cv::Scalar::all(205));
      image(cv::Rect(w / 4, h / 4, std::max(1, w / 2), std::max(1, h / 2))).setTo(cv::Scalar::all(254));
      image.row(h / 2).setTo(cv::Scalar::all(0));
    }
    for (const int level : {-1, 9}) {
      std::vector<uchar> expected;
      std::vector<int> params;
      if (level >= 0) params = {cv::IMWRITE_PNG_COMPRESSION, level};
      ASSERT_TRUE(cv::imencode(".png", image, expected, params));
      EXPECT_EQ(encode_png(image, level), std::string(expected.begin(), expected.end()))
          << "type " << image.type() << ", " << w << " x " << h << ", level " << level;
    }
    if (image.channels() == 1) {
      std::vector<uchar> expected;
      ASSERT_TRUE(cv::imencode(".pgm", image, expected));
      EXPECT_EQ(encode_image(".pgm", image, "test"), std::string(expected.begin(), expected.end()));
    }
  }
  // What fleetmap cannot write is refused, naming the output.
  expect_input_error([] { encode_image(".pgm", cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(0)), "out.pgm"); }, {"out.pgm", ".png"});
  expect_input_error([] { encode_image(".png", cv::Mat(4, 4, CV_32FC1, cv::Scalar::all(0)), "out.png"); }, {"out.png"});
  expect_input_error([] { encode_image(".jpg", cv::Mat(4, 4, CV_8UC1, cv::Scalar::all(0)), "out.jpg"); }, {"out.jpg"});
}

}  // namespace
}  // namespace fleetmap::io
