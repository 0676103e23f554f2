#pragma once
// The files a run leaves behind (installed: fleetmap's own types only): merged.png, a picture
// and map_server files per robot, metrics.json, the merged map as map_server and OctoMap files,
// scenario.yaml, and optionally a video. Every file is written to a temporary name and renamed.
// The pictures with overlays of one's own are sim/run_output.h's (inside the build: OpenCV images).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::sim {

// The names write_run_outputs gives its files for a run of `scenario`, and replay.html when the
// scenario asks for it (written by the caller, from a RunReplay).
std::vector<std::string> run_output_files(const Scenario& scenario);

// Writes merged.png (the merged map with every robot's true and estimated trajectory, final pose
// and landmarks; legend and scale bar), robot_<k>.png + robot_<k>.pgm/.yaml (k from 1: robot k's
// own map, in its own frame), metrics.json (sim/run_metrics.h's text), map.pgm + map.yaml, map.bt
// and scenario.yaml (its map path relative to `dir`) into `dir`, which is created when missing.
// `map_label` names the map in the pictures' titles and metrics.json. Returns the files written.
std::vector<std::filesystem::path> write_run_outputs(const RunResult& result, const std::string& map_label,
                                                     const std::filesystem::path& dir);

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
