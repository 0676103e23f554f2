#include "viz/replay.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <cstring>

#include "core/error.h"
#include "viz/html.h"

namespace fleetmap::viz {

using nlohmann::json;

namespace {

void put_varint(std::vector<std::uint8_t>& out, std::uint64_t v) {
  while (v >= 0x80) {
    out.push_back(std::uint8_t(v | 0x80));
    v >>= 7;
  }
  out.push_back(std::uint8_t(v));
}

std::uint64_t code(ReplayCell c) { return std::uint64_t(c); }

// Positions in centimetres and headings in milliradians keep the page small.
long cm(double metres) { return std::lround(metres * 100.0); }
long mrad(double radians) { return std::lround(radians * 1000.0); }

// A number to three decimals; NaN and infinities become null.
json value(double v) { return std::isfinite(v) ? json(std::round(v * 1000.0) / 1000.0) : json(nullptr); }

// Each distinct note once: decisions refer to it by index.
struct Notes {
  std::vector<std::string> texts;
  std::map<std::string, int> index;
  int of(const std::string& text) {
    const auto [it, added] = index.try_emplace(text, int(texts.size()));
    if (added) texts.push_back(text);
    return it->second;
  }
};

// Per decision {"s": step, "l": leader, "g": group (when not alone), "n": candidates weighed, "c": the
// chosen one (index into "k"), "kept", "r": scores reported, "t": note, "goal": [x, y] cm,
// "k": candidates [frontier x, y, goal x, y (cm), cells, score, taken by, terms...]}.
json decisions_json(const std::vector<ReplayDecision>& decisions, Notes& notes) {
  json out = json::array();
  for (const auto& d : decisions) {
    json one = {{"s", d.step}, {"l", d.leader}, {"n", d.weighed}, {"c", d.chosen}, {"r", d.reported ? 1 : 0}};
    if (d.group.size() > 1) one["g"] = d.group;
    if (d.kept) one["kept"] = 1;
    if (!d.note.empty()) one["t"] = notes.of(d.note);
    if (d.goal_m) one["goal"] = {cm(d.goal_m->x()), cm(d.goal_m->y())};
    json candidates = json::array();
    for (const auto& c : d.candidates) {
      json row = {cm(c.frontier_m.x()), cm(c.frontier_m.y()), cm(c.goal_m.x()), cm(c.goal_m.y()), c.cells, value(c.score), c.taken_by};
      for (double v : c.terms) row.push_back(value(v));
      candidates.push_back(std::move(row));
    }
    one["k"] = std::move(candidates);
    out.push_back(std::move(one));
  }
  return out;
}

json poses_json(const std::vector<core::Pose2>& poses) {
  json out = json::array();
  for (const auto& p : poses) {
    out.push_back(cm(p.x));
    out.push_back(cm(p.y));
    out.push_back(mrad(p.theta));
  }
  return out;
}

std::string hex(const Color& c) { return fmt::format("#{:02x}{:02x}{:02x}", c.r, c.g, c.b); }

}  // namespace

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = std::uint32_t(bytes[i]) << 16 | (i + 1 < bytes.size() ? std::uint32_t(bytes[i + 1]) << 8 : 0) |
                            (i + 2 < bytes.size() ? std::uint32_t(bytes[i + 2]) : 0);
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

std::string encode_runs(const std::vector<ReplayCell>& cells) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i < cells.size();) {
    std::size_t j = i + 1;
    while (j < cells.size() && cells[j] == cells[i]) ++j;
    put_varint(out, std::uint64_t(j - i) << 2 | code(cells[i]));
    i = j;
  }
  return base64(out);
}

std::string encode_changes(const std::vector<ReplayCell>& before, const std::vector<ReplayCell>& after) {
  if (before.size() != after.size()) throw Error("encode_changes: the two steps have different cell counts");
  std::vector<std::uint8_t> out;
  std::size_t next = 0;  // the first cell after the last change
  const std::size_t n = after.size();
  for (std::size_t i = 0; i < n; ++i) {
    // Whole unchanged stretches are skipped eight cells at a time.
    while (i + 8 <= n && std::memcmp(&before[i], &after[i], 8) == 0) i += 8;
    if (i >= n) break;
    if (before[i] == after[i]) continue;
    put_varint(out, std::uint64_t(i - next) << 4 | code(before[i]) << 2 | code(after[i]));
    next = i + 1;
  }
  return out.empty() ? std::string() : base64(out);
}

void ReplayLayer::add_step(const core::GridGeometry& geometry, const std::vector<ReplayCell>& cells, bool relative) {
  if (std::int64_t(cells.size()) != geometry.cell_count()) throw Error("replay layer " + name_ + ": one code per cell expected");
  if (steps_ == 0 || !(geometry == geometry_) || relative != relative_) {
    const auto& o = geometry.origin();
    json frame = {{"step", steps_},          {"width", geometry.width()}, {"height", geometry.height()},
                  {"resolution", geometry.resolution()}, {"origin", {o.x, o.y, o.theta}},
                  {"relative", relative},   {"cells", encode_runs(cells)}};
    bytes_ += frame["cells"].get_ref<const std::string&>().size();
    frames_.push_back(std::move(frame));
    changes_.push_back("");
    geometry_ = geometry;
    relative_ = relative;
  } else {
    std::string changes = encode_changes(cells_, cells);
    bytes_ += changes.size();
    changes_.push_back(std::move(changes));
  }
  cells_ = cells;
  ++steps_;
}

json ReplayLayer::to_json() const { return {{"name", name_}, {"frames", frames_}, {"changes", changes_}}; }

json replay_json(const Replay& r) {
  json j;
  j["title"] = r.title;
  j["facts"] = r.facts;
  j["radius"] = r.robot_radius_m;
  j["period"] = r.period_s;
  j["estimates"] = r.estimates;
  json coverage = json::array();
  for (double c : r.coverage) coverage.push_back(std::round(c * 1e4) / 1e4);
  j["coverage"] = std::move(coverage);
  j["merged"] = r.merged.to_json();
  j["own"] = json::array();
  for (const auto& layer : r.robot_maps) j["own"].push_back(layer.to_json());
  j["robots"] = json::array();
  Notes notes;
  for (const auto& robot : r.robots) {
    json plans = json::array();
    for (const auto& plan : robot.plans) {
      json points = json::array();
      for (const auto& p : plan) {
        points.push_back(cm(p.x()));
        points.push_back(cm(p.y()));
      }
      plans.push_back(std::move(points));
    }
    // The frame changes rarely: [step, x, y, theta] where it does.
    json frames = json::array();
    for (std::size_t k = 0; k < robot.frame.size(); ++k) {
      if (k > 0 && robot.frame[k].x == robot.frame[k - 1].x && robot.frame[k].y == robot.frame[k - 1].y &&
          robot.frame[k].theta == robot.frame[k - 1].theta)
        continue;
      frames.push_back({k, cm(robot.frame[k].x), cm(robot.frame[k].y), mrad(robot.frame[k].theta)});
    }
    std::string finished(robot.finished.size(), '0');
    for (std::size_t k = 0; k < robot.finished.size(); ++k) finished[k] = robot.finished[k] ? '1' : '0';
    json one = {{"name", robot.name},
                {"color", hex(robot.color)},
                {"truth", poses_json(robot.truth)},
                {"frames", std::move(frames)},
                {"plans", std::move(plans)},
                {"plan", robot.plan},
                {"passed", robot.passed},
                {"finished", std::move(finished)},
                {"distance", robot.distance_m}};
    if (r.estimates) one["estimate"] = poses_json(robot.estimate);
    one["decisions"] = decisions_json(robot.decisions, notes);
    j["robots"].push_back(std::move(one));
  }
  j["notes"] = notes.texts;
  j["scores"] = {{"strategy", r.scores.strategy},
                 {"terms", r.scores.terms},
                 {"score", r.scores.score},
                 {"lower", r.scores.lower_is_better},
                 {"rule", r.scores.rule}};
  j["events"] = json::array();
  for (const auto& e : r.events) {
    json one = {{"step", e.step}, {"kind", e.kind}, {"robot", e.robot}, {"other", e.other}, {"text", e.text}};
    if (e.at_m) one["at"] = {cm(e.at_m->x()), cm(e.at_m->y())};
    j["events"].push_back(std::move(one));
  }
  return j;
}

std::string replay_html(const Replay& replay) {
  std::string data = replay_json(replay).dump();
  // Inside a <script> element nothing may read as a closing tag: every '<' (only ever inside JSON
  // strings) is written as an escape.
  std::string safe;
  safe.reserve(data.size());
  for (char c : data) {
    if (c == '<') safe += "\\u003c";
    else safe += c;
  }
  return replay_page(replay.title, safe);
}

}  // namespace fleetmap::viz
