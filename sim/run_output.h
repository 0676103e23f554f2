#pragma once
// What a run leaves behind: pictures, metrics.json, the merged map as map_server and OctoMap
// files, and optionally a video. Every file is written to a temporary name and renamed.
#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "viz/render.h"
#include "sim/simulation.h"

namespace fleetmap::sim {

// Every number of a run; all but "timing" are identical for two runs with the same inputs.
nlohmann::json metrics_json(const RunResult& result, const std::string& map_label);

// The merged map with every robot's true trajectory (solid), estimated trajectory (dashed, when
// the localization is not ideal), final pose and landmarks; legend and scale bar.
// `extra` is drawn on top (e.g. a path planned on the merged map).
cv::Mat render_merged(const RunResult& result, const std::string& map_label, const viz::Overlays& extra = {});
// Robot i's own map with its trajectory.
cv::Mat render_robot(const RunResult& result, int robot, const std::string& map_label);

// The names write_run_outputs gives its files for a run of `scenario`, and replay.html when the
// scenario asks for it (written by the caller, from a RunReplay).
std::vector<std::string> run_output_files(const Scenario& scenario);

// Writes merged.png, robot_<k>.png (k from 1), metrics.json, map.pgm + map.yaml, map.bt and
// scenario.yaml (its map path relative to `dir`) into `dir`. Returns the files written.
std::vector<std::filesystem::path> write_run_outputs(const RunResult& result, const std::string& map_label,
                                                     const std::filesystem::path& dir,
                                                     const viz::Overlays& extra = {});

// The video formats RunVideo writes, by the file's extension: ".mp4" (H.264, which browsers play;
// MPEG-4 Part 2 where OpenCV's FFmpeg has no H.264 encoder) and ".webm" (VP9, else VP8).
const std::vector<std::string>& video_extensions();

// A video of a run, a frame per step (the merged map, robots, their paths and planned paths).
class RunVideo {
 public:
  // Throws InputError when the extension is not one of video_extensions().
  RunVideo(std::filesystem::path path, double fps = 12.0);
  ~RunVideo();
  void add_frame(const Simulation& sim, const std::string& map_label);
  // Closes the video and moves it into place. Throws fleetmap::Error when nothing could be written.
  void finish();
  // After the first frame: the codec written ("H.264", "MPEG-4 Part 2", "VP9", "VP8").
  const std::string& codec() const;
  // After the first frame: why the preferred codec was not used, or empty.
  const std::string& fallback_note() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fleetmap::sim
