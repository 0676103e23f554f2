#include "maps/builtin_maps.h"
#include "maps/generated_maps.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <opencv2/imgproc.hpp>

#include "core/format.h"
#include "core/error.h"
#include "core/suggest.h"
#include "core/random.h"
#include "io/file_io.h"
#include "io/map_image.h"

#ifndef FLEETMAP_SOURCE_MAPS_DIR
#define FLEETMAP_SOURCE_MAPS_DIR ""
#endif

namespace fleetmap::maps {

namespace fs = std::filesystem;

namespace {

constexpr std::uint8_t kFree = 254;
constexpr std::uint8_t kWall = 0;
constexpr double kResolution = 0.1;  // metres per cell for every built-in map

// All drawing is in image coordinates: x = column, y = row from the top.
void fill(cv::Mat& img, int x0, int y0, int x1, int y1, std::uint8_t v) {
  cv::rectangle(img, cv::Point(x0, y0), cv::Point(x1 - 1, y1 - 1), cv::Scalar(v), cv::FILLED);
}
void wall(cv::Mat& img, int x0, int y0, int x1, int y1) { fill(img, x0, y0, x1, y1, kWall); }
void clear(cv::Mat& img, int x0, int y0, int x1, int y1) { fill(img, x0, y0, x1, y1, kFree); }

void border(cv::Mat& img, int t) {
  wall(img, 0, 0, img.cols, t);
  wall(img, 0, img.rows - t, img.cols, img.rows);
  wall(img, 0, 0, t, img.rows);
  wall(img, img.cols - t, 0, img.cols, img.rows);
}

// Keeps the largest 4-connected free region; every other free cell becomes wall.
void keep_largest_free_region(cv::Mat& img) {
  cv::Mat free = img == kFree, labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(free, labels, stats, centroids, 4, CV_32S);
  int best = -1, best_area = 0;
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) > best_area) best_area = stats.at<int>(i, cv::CC_STAT_AREA), best = i;
  }
  img.setTo(kWall, labels != best);
}

// Morphological opening of the free space by a disc of radius r, keeping one connected region:
// removes passages and nooks narrower than 2r cells, so a robot of radius r (and some margin)
// reaches every free cell.
void open_free_space(cv::Mat& img, int r) {
  const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  cv::Mat free = img == kFree, core;
  cv::erode(free, core, disc, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat core_img(img.size(), CV_8UC1, cv::Scalar(kWall));
  core_img.setTo(kFree, core);
  keep_largest_free_region(core_img);
  cv::Mat opened;
  cv::dilate(core_img == kFree, opened, disc);
  img.setTo(kWall);
  img.setTo(kFree, opened & free);
  keep_largest_free_region(img);
}

struct Rect {
  int x0, y0, x1, y1;
  int w() const { return x1 - x0; }
  int h() const { return y1 - y0; }
};

struct OfficeStyle {
  int wall = 2;            // wall thickness
  int corridor = 16;       // corridor width
  int door = 10;           // door width
  int min_room = 30, max_room = 48;
  double connect_rooms = 0.3;  // chance of a door between neighbouring rooms
  double furniture = 0.5;      // chance a room gets a table
  bool entrances = false;      // openings at both corridor ends
};

// One building: outer walls, a corridor along its longer side, rooms on both sides with doors.
void draw_office(cv::Mat& img, const Rect& r, const OfficeStyle& s, core::Random& rng) {
  const int t = s.wall;
  wall(img, r.x0, r.y0, r.x1, r.y1);
  clear(img, r.x0 + t, r.y0 + t, r.x1 - t, r.y1 - t);
  const bool horizontal = r.w() >= r.h();
  // Work in (along, across) coordinates; `put` maps them back to the image.
  const int len = horizontal ? r.w() : r.h(), depth = horizontal ? r.h() : r.w();
  const auto put = [&](int a0, int c0, int a1, int c1, std::uint8_t v) {
    if (horizontal) fill(img, r.x0 + a0, r.y0 + c0, r.x0 + a1, r.y0 + c1, v);
    else fill(img, r.x0 + c0, r.y0 + a0, r.x0 + c1, r.y0 + a1, v);
  };
  const int c_lo = (depth - s.corridor) / 2, c_hi = c_lo + s.corridor;
  // Corridor walls, then rooms on each side.
  put(t, c_lo - t, len - t, c_lo, kWall);
  put(t, c_hi, len - t, c_hi + t, kWall);
  for (int side = 0; side < 2; ++side) {
    const int room_c0 = side == 0 ? t : c_hi + t, room_c1 = side == 0 ? c_lo - t : depth - t;
    int a = t;
    int previous_wall = -1;
    while (a < len - t) {
      int w = rng.uniform_int(s.min_room, s.max_room);
      if (len - t - (a + w) < s.min_room) w = len - t - a;  // the last room takes the rest
      const int a_end = a + w;
      // Door to the corridor.
      const int door_at = rng.uniform_int(a + 3, std::max(a + 3, a_end - s.door - 3));
      if (side == 0) put(door_at, c_lo - t, door_at + s.door, c_lo, kFree);
      else put(door_at, c_hi, door_at + s.door, c_hi + t, kFree);
      // Sometimes a door to the previous room.
      if (previous_wall >= 0 && rng.bernoulli(s.connect_rooms) && room_c1 - room_c0 > s.door + 6) {
        const int d = rng.uniform_int(room_c0 + 3, room_c1 - s.door - 3);
        put(previous_wall, d, previous_wall + t, d + s.door, kFree);
      }
      // A table in the middle of some rooms.
      const int room_depth = room_c1 - room_c0;
      if (rng.bernoulli(s.furniture) && w > 24 && room_depth > 24) {
        const int tw = rng.uniform_int(6, w / 3), td = rng.uniform_int(4, room_depth / 4);
        const int ta = a + (w - tw) / 2, tc = room_c0 + (room_depth - td) / 2;
        put(ta, tc, ta + tw, tc + td, kWall);
      }
      if (a_end < len - t) {
        put(a_end, room_c0, a_end + t, room_c1, kWall);
        previous_wall = a_end;
      }
      a = a_end + t;
    }
  }
  if (s.entrances) {
    put(0, c_lo, t, c_hi, kFree);
    put(len - t, c_lo, len, c_hi, kFree);
  }
}

cv::Mat make_empty() {
  cv::Mat img(200, 200, CV_8UC1, cv::Scalar(kFree));
  border(img, 2);
  return img;
}

// Scattered convex and concave obstacles of many sizes (wave-algorithm paper, Fig. 5B).
cv::Mat make_unstructured() {
  cv::Mat img(200, 200, CV_8UC1, cv::Scalar(kFree));
  core::Random rng(5003);
  for (int i = 0; i < 34; ++i) {
    const cv::Point c(rng.uniform_int(12, 188), rng.uniform_int(12, 188));
    if (c.x < 45 && c.y > 155) continue;  // keep the lower-left start area open
    switch (rng.uniform_int(0, 2)) {
      case 0:
        cv::ellipse(img, c, cv::Size(rng.uniform_int(3, 12), rng.uniform_int(3, 12)), rng.uniform(0, 180), 0, 360,
                    cv::Scalar(kWall), cv::FILLED);
        break;
      case 1: {
        const cv::RotatedRect box(c, cv::Size2f(float(rng.uniform_int(4, 26)), float(rng.uniform_int(4, 12))),
                                  float(rng.uniform(0, 180)));
        cv::Point2f v[4];
        box.points(v);
        std::vector<cv::Point> poly(v, v + 4);
        cv::fillConvexPoly(img, poly, cv::Scalar(kWall));
        break;
      }
      default: {
        std::vector<cv::Point> poly;
        const int n = rng.uniform_int(5, 8);
        for (int k = 0; k < n; ++k) {
          const double a = 2.0 * std::numbers::pi * k / n, rad = rng.uniform(4.0, 15.0);
          poly.emplace_back(c.x + int(rad * std::cos(a)), c.y + int(rad * std::sin(a)));
        }
        cv::fillPoly(img, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(kWall));
      }
    }
  }
  border(img, 2);
  open_free_space(img, 4);
  return img;
}

// An office floor: a corridor with rooms on both sides (wave-algorithm paper, Fig. 5C).
cv::Mat make_office() {
  cv::Mat img(200, 200, CV_8UC1, cv::Scalar(kWall));
  core::Random rng(5005);
  OfficeStyle style;
  style.corridor = 18;
  draw_office(img, {0, 0, 200, 200}, style, rng);
  keep_largest_free_region(img);
  return img;
}

// Long corridors 12 cells wide in a solid block: a ring, a cross and side alcoves (wave-algorithm paper, Fig. 5D).
cv::Mat make_corridor() {
  cv::Mat img(200, 200, CV_8UC1, cv::Scalar(kWall));
  const int w = 12, lo = 4, hi = 196;
  clear(img, lo, lo, hi, lo + w);            // top
  clear(img, lo, hi - w, hi, hi);            // bottom
  clear(img, lo, lo, lo + w, hi);            // left
  clear(img, hi - w, lo, hi, hi);            // right
  clear(img, lo, 94, hi, 94 + w);            // middle horizontal
  clear(img, 94, lo, 94 + w, hi);            // middle vertical
  clear(img, lo, 50, 100, 50 + w);           // upper-left branch
  clear(img, 100, 144, hi, 144 + w);         // lower-right branch
  clear(img, 50, 94, 50 + w, hi);            // lower-left branch
  clear(img, 144, lo, 144 + w, 100);         // upper-right branch
  // Dead-end alcoves off the corridors.
  clear(img, 30, 16, 46, 36);
  clear(img, 126, 62, 144, 78);
  clear(img, 16, 118, 40, 132);
  clear(img, 160, 118, 176, 144);
  clear(img, 62, 160, 84, 184);
  return img;
}

// Natural caves from a cellular automaton on a coarse grid, smoothed up to 200x200.
cv::Mat make_cave() {
  core::Random rng(5007);
  const int n = 50;
  cv::Mat coarse(n, n, CV_8UC1);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) coarse.at<std::uint8_t>(y, x) = rng.bernoulli(0.45) ? 1 : 0;
  for (int iter = 0; iter < 5; ++iter) {
    cv::Mat next = coarse.clone();
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        int walls = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            const int xx = x + dx, yy = y + dy;
            walls += (xx < 0 || yy < 0 || xx >= n || yy >= n) ? 1 : coarse.at<std::uint8_t>(yy, xx);
          }
        next.at<std::uint8_t>(y, x) = walls >= 5 ? 1 : (walls <= 3 ? 0 : coarse.at<std::uint8_t>(y, x));
      }
    }
    coarse = next;
  }
  cv::Mat walls_f, smooth;
  coarse.convertTo(walls_f, CV_32F);
  cv::resize(walls_f, smooth, cv::Size(200, 200), 0, 0, cv::INTER_LINEAR);
  cv::GaussianBlur(smooth, smooth, cv::Size(0, 0), 3.0);
  cv::Mat img(200, 200, CV_8UC1, cv::Scalar(kFree));
  img.setTo(kWall, smooth > 0.5f);
  border(img, 2);
  open_free_space(img, 4);
  return img;
}

// A 10x10 maze (recursive backtracker) with a few walls removed to make loops.
cv::Mat make_maze() {
  const int n = 10, cell = 20, t = 3;
  core::Random rng(5011);
  // walls_e[y][x]: wall east of (x, y); walls_s[y][x]: wall south of (x, y).
  std::vector<std::vector<bool>> east(n, std::vector<bool>(n, true)), south(n, std::vector<bool>(n, true));
  std::vector<std::vector<bool>> seen(n, std::vector<bool>(n, false));
  std::vector<std::pair<int, int>> stack = {{0, n - 1}};
  seen[n - 1][0] = true;
  while (!stack.empty()) {
    const auto [x, y] = stack.back();
    std::vector<std::pair<int, int>> next;
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int k = 0; k < 4; ++k) {
      const int xx = x + dx[k], yy = y + dy[k];
      if (xx >= 0 && yy >= 0 && xx < n && yy < n && !seen[yy][xx]) next.emplace_back(xx, yy);
    }
    if (next.empty()) {
      stack.pop_back();
      continue;
    }
    const auto [xx, yy] = next[static_cast<std::size_t>(rng.uniform_int(0, int(next.size()) - 1))];
    if (xx != x) east[y][std::min(x, xx)] = false;
    else south[std::min(y, yy)][x] = false;
    seen[yy][xx] = true;
    stack.emplace_back(xx, yy);
  }
  for (int k = 0; k < 8; ++k) {  // loops
    const int x = rng.uniform_int(0, n - 2), y = rng.uniform_int(0, n - 2);
    if (rng.bernoulli(0.5)) east[y][x] = false;
    else south[y][x] = false;
  }
  cv::Mat img(n * cell, n * cell, CV_8UC1, cv::Scalar(kFree));
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if (x + 1 < n && east[y][x]) wall(img, (x + 1) * cell - t / 2 - 1, y * cell - 1, (x + 1) * cell + t / 2, (y + 1) * cell + 2);
      if (y + 1 < n && south[y][x]) wall(img, x * cell - 1, (y + 1) * cell - t / 2 - 1, (x + 1) * cell + 2, (y + 1) * cell + t / 2);
    }
  }
  border(img, t);
  keep_largest_free_region(img);
  return img;
}

// Racks in three blocks with aisles, a loading area with pallets and pillars, and an office.
cv::Mat make_warehouse() {
  cv::Mat img(200, 300, CV_8UC1, cv::Scalar(kFree));
  core::Random rng(5013);
  border(img, 3);
  for (const int bx : {40, 120, 200}) {
    for (int y = 34; y + 5 <= 140; y += 18) wall(img, bx, y, bx + 64, y + 5);
  }
  // Office in the top-left corner, door to the floor.
  wall(img, 3, 3, 34, 34);
  clear(img, 3, 3, 32, 32);
  clear(img, 12, 32, 24, 34);
  // Pillars on a grid in the loading area, pallets between them.
  for (int x = 40; x < 290; x += 50) wall(img, x, 158, x + 4, 162);
  for (int i = 0; i < 10; ++i) {
    const int x = rng.uniform_int(20, 270), y = rng.uniform_int(168, 185);
    wall(img, x, y, x + 8, y + 8);
  }
  // Loading-dock bays along the bottom wall.
  for (int x = 30; x < 290; x += 40) wall(img, x, 188, x + 3, 197);
  keep_largest_free_region(img);
  return img;
}

// A 1200x1200 campus (120 m square): six office buildings with entrances, paths between them,
// trees and a pond, inside a fence.
cv::Mat make_campus() {
  cv::Mat img(1200, 1200, CV_8UC1, cv::Scalar(kFree));
  core::Random rng(5017);
  border(img, 4);
  const std::vector<Rect> buildings = {{80, 80, 440, 300},   {560, 70, 820, 420},  {900, 100, 1120, 520},
                                       {90, 420, 360, 780},  {470, 560, 860, 800}, {200, 900, 700, 1110}};
  OfficeStyle style;
  style.wall = 3;
  style.corridor = 24;
  style.door = 12;
  style.min_room = 40;
  style.max_room = 70;
  style.entrances = true;
  for (const auto& b : buildings) draw_office(img, b, style, rng);
  // A pond.
  cv::ellipse(img, cv::Point(960, 850), cv::Size(110, 70), 20, 0, 360, cv::Scalar(kWall), cv::FILLED);
  // Trees, kept clear of buildings and entrances.
  const auto clear_of_buildings = [&](int x, int y, int margin) {
    for (const auto& b : buildings) {
      if (x > b.x0 - margin && x < b.x1 + margin && y > b.y0 - margin && y < b.y1 + margin) return false;
    }
    return true;
  };
  for (int i = 0; i < 220; ++i) {
    const int x = rng.uniform_int(30, 1170), y = rng.uniform_int(30, 1170);
    if (!clear_of_buildings(x, y, 40)) continue;
    cv::circle(img, cv::Point(x, y), rng.uniform_int(4, 9), cv::Scalar(kWall), cv::FILLED);
  }
  keep_largest_free_region(img);
  return img;
}

struct Generator {
  const char* name;
  const char* description;
  cv::Mat (*make)();
};

// The committed maps/ files are these generators' output.
const std::vector<Generator>& generators() {
  static const std::vector<Generator> kGenerators = {
      {"empty", "the wave-algorithm paper's Fig. 5A: an empty walled square", make_empty},
      {"unstructured", "the wave-algorithm paper's Fig. 5B: scattered obstacles of many shapes", make_unstructured},
      {"office", "the wave-algorithm paper's Fig. 5C: rooms on both sides of a corridor", make_office},
      {"corridor", "the wave-algorithm paper's Fig. 5D: a network of long corridors with alcoves", make_corridor},
      {"cave", "natural caves (cellular automaton)", make_cave},
      {"maze", "a 10x10 maze with a few loops", make_maze},
      {"warehouse", "rack aisles, a loading area with pallets, an office", make_warehouse},
      {"campus", "six office buildings, trees and a pond (large map)", make_campus},
  };
  return kGenerators;
}

// A built-in map's committed YAML, if `name` is one of the generated maps.
std::optional<fs::path> generated_file(std::string_view name) {
  for (const auto& g : generators()) {
    if (g.name == name) return builtin_maps_dir() / (std::string(name) + ".yaml");
  }
  return std::nullopt;
}

}  // namespace

core::Registry<MapFactory>& map_registry() {
  static core::Registry<MapFactory> registry("map");
  static const bool built_in = [] {
    for (const auto& g : generators()) {
      const std::string name = g.name;
      registry.add(name, g.description, [name](const io::MapLoadOptions& options) {
        const fs::path yaml = *generated_file(name);
        if (!io::path_exists(yaml)) {
          throw InputError("map '" + name + "': built-in map file " + yaml.string() +
                           " is missing (set FLEETMAP_MAPS_DIR to the maps/ folder)");
        }
        return io::load_map(yaml, options);
      });
    }
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_map(std::string name, std::string description, MapFactory make) {
  map_registry().add(std::move(name), std::move(description), std::move(make));
}

std::vector<BuiltinMapInfo> builtin_maps() {
  std::vector<BuiltinMapInfo> v;
  for (const auto& name : map_registry().names()) v.push_back({name, map_registry().get(name).help});
  return v;
}

bool is_builtin_map(std::string_view name) { return map_registry().contains(name); }

std::string builtin_map_names() { return core::join(map_registry().names()); }

GeneratedMap generate_builtin_map(std::string_view name) {
  for (const auto& g : generators()) {
    if (g.name != name) continue;
    GeneratedMap m;
    m.image = g.make();
    m.yaml.image = std::string(g.name) + ".png";
    m.yaml.resolution = kResolution;
    return m;
  }
  throw InputError("unknown built-in map '" + std::string(name) + "' (built-in maps: " + builtin_map_names() + ")");
}

std::string encode_png(const cv::Mat& image) {
  return io::encode_png(image, 9);
}

fs::path builtin_maps_dir() {
  if (const char* env = std::getenv("FLEETMAP_MAPS_DIR"); env && *env) return env;
  const fs::path source = FLEETMAP_SOURCE_MAPS_DIR;
  if (!source.empty() && io::path_exists(source / "empty.yaml")) return source;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "fleetmap" / "maps";
    if (io::path_exists(installed / "empty.yaml")) return installed;
  }
  return source;
}

namespace {

// A file of that name wins over a map of the registry; a folder named like one (e.g. the output
// folder of `fleetmap explore --map maze`, out/maze) does not hide it. A link that leads nowhere
// (or in a loop) is still the user's file: reading it says what is wrong.
bool is_user_file(const std::string& name_or_path) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(name_or_path, ec))) return false;
  return !(is_builtin_map(name_or_path) && io::is_folder(name_or_path));
}

}  // namespace

std::vector<fs::path> map_source_files(const std::string& name_or_path) {
  if (is_user_file(name_or_path)) return io::map_files(name_or_path);
  if (const auto file = generated_file(name_or_path)) return io::map_files(*file);
  return {};
}

mapping::OccupancyGrid load_map_source(const std::string& name_or_path, const io::MapLoadOptions& options) {
  if (name_or_path.empty()) throw InputError("map: empty name (built-in maps: " + builtin_map_names() + ")");
  if (is_user_file(name_or_path)) return io::load_map(name_or_path, options);
  if (is_builtin_map(name_or_path)) return map_registry().get(name_or_path).make(options);
  const bool looks_like_path = name_or_path.find_first_of("/.") != std::string::npos;
  if (looks_like_path) throw InputError(name_or_path + ": no such file");
  std::vector<std::string> names;
  for (const auto& m : builtin_maps()) names.push_back(m.name);
  throw InputError("unknown map '" + name_or_path + "'" + core::did_you_mean(name_or_path, names) +
                   ": not a file and not a built-in map (built-in maps: " + builtin_map_names() + ")");
}

}  // namespace fleetmap::maps
