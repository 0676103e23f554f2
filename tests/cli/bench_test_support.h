#pragma once
// Shared by the `fleetmap bench` end-to-end tests: two small maps, and results.csv read as a table.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cli_run.h"

namespace fleetmap::testing {

// NAME.png and NAME.yaml (map_server, 0.1 m cells) from a grey image: 0 wall, 254 free.
inline void write_map(const TempDir& dir, const std::string& name, const cv::Mat& image) {
  std::vector<unsigned char> png;
  cv::imencode(".png", image, png);
  dir.write(name + ".png", std::string(png.begin(), png.end()));
  dir.write(name + ".yaml", "image: " + name + ".png\nresolution: 0.1\norigin: [0, 0, 0]\n");
}

// room.yaml (24 x 8 m: three rooms in a row joined by doors) and hall.yaml (15 x 10 m with two
// pillars), 0.1 m cells: each larger than what one scan sees, small enough for short runs.
inline void write_bench_maps(const TempDir& dir) {
  const cv::Scalar wall(0), free(254);
  cv::Mat room(80, 240, CV_8UC1, free);
  cv::rectangle(room, cv::Rect(0, 0, 240, 80), wall, 1);
  cv::line(room, cv::Point(80, 0), cv::Point(80, 79), wall, 1);
  cv::line(room, cv::Point(80, 10), cv::Point(80, 24), free, 1);  // doors
  cv::line(room, cv::Point(160, 0), cv::Point(160, 79), wall, 1);
  cv::line(room, cv::Point(160, 55), cv::Point(160, 69), free, 1);
  cv::Mat hall(100, 150, CV_8UC1, free);
  cv::rectangle(hall, cv::Rect(0, 0, 150, 100), wall, 1);
  cv::rectangle(hall, cv::Rect(30, 30, 10, 10), wall, cv::FILLED);
  cv::rectangle(hall, cv::Rect(105, 55, 10, 10), wall, cv::FILLED);
  write_map(dir, "room", room);
  write_map(dir, "hall", hall);
}

inline std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(line);
  while (std::getline(in, item, sep)) out.push_back(item);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

// A CSV file as rows of named cells.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
};

inline CsvTable read_csv(const std::filesystem::path& path) {
  CsvTable t;
  const auto lines = lines_of(slurp(path));
  if (lines.empty()) return t;
  t.header = split(lines[0]);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto cells = split(lines[i]);
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < t.header.size() && c < cells.size(); ++c) row[t.header[c]] = cells[c];
    t.rows.push_back(row);
  }
  return t;
}

// results.csv's lines without the wall_time_s column: equal for equal runs.
inline std::vector<std::string> rows_without_wall_time(const std::filesystem::path& results) {
  const auto lines = lines_of(slurp(results));
  std::vector<std::string> out;
  if (lines.empty()) return out;
  const auto header = split(lines[0]);
  const auto wall = std::size_t(std::find(header.begin(), header.end(), "wall_time_s") - header.begin());
  for (const auto& line : lines) {
    auto cells = split(line);
    if (wall < cells.size()) cells.erase(cells.begin() + std::ptrdiff_t(wall));
    std::string joined;
    for (std::size_t i = 0; i < cells.size(); ++i) joined += (i ? "," : "") + cells[i];
    out.push_back(joined);
  }
  return out;
}

}  // namespace fleetmap::testing
