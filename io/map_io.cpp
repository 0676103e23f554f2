#include "io/map_io.h"

#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <png.h>
#include <yaml-cpp/yaml.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <span>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "io/file_io.h"
#include "io/map_image.h"
#include "io/yaml_reader.h"

namespace fleetmap::io {

namespace fs = std::filesystem;

namespace {

// A pixel less opaque than this is transparent: nothing was drawn there, so it is unknown.
constexpr int kOpaqueAlpha = 128;

// map_saver writes unknown cells as this grey (and never negates). A trinary map holds only
// map_saver's three values, so the thresholds merely have to separate them; nav2's map_saver wrote free_thresh 0.25, under
// which this grey (occ 0.196) reads as free and the unmapped surround becomes floor. In trinary mode
// it is unknown whatever the thresholds (as nav2's loader decided in 2025, PR #5278).
constexpr int kSaverUnknown = 205;

// No image side is longer (2^40 pixels); a header declaring more is refused as such.
constexpr std::int64_t kHugeSide = std::int64_t{1} << 40;

// Reads width and height from a PNG or PNM header without decoding the image.
std::optional<std::pair<std::int64_t, std::int64_t>> peek_image_size(const std::string& bytes) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 24 && std::equal(kPng, kPng + 8, reinterpret_cast<const unsigned char*>(bytes.data()))) {
    const auto be32 = [&](std::size_t at) {
      const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + at);
      return (std::int64_t{p[0]} << 24) | (std::int64_t{p[1]} << 16) | (std::int64_t{p[2]} << 8) | p[3];
    };
    return std::pair{be32(16), be32(20)};
  }
  if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6') {
    std::int64_t dims[2] = {0, 0};
    std::size_t i = 2;
    for (int k = 0; k < 2; ++k) {
      while (i < bytes.size() && (std::isspace(static_cast<unsigned char>(bytes[i])) || bytes[i] == '#')) {
        if (bytes[i] == '#') {
          while (i < bytes.size() && bytes[i] != '\n') ++i;
        } else {
          ++i;
        }
      }
      if (i >= bytes.size() || !std::isdigit(static_cast<unsigned char>(bytes[i]))) return std::nullopt;
      // Every digit is read; past kHugeSide the value stays just above it.
      while (i < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[i]))) {
        dims[k] = std::min(dims[k] * 10 + (bytes[i] - '0'), kHugeSide + 1);
        ++i;
      }
    }
    return std::pair{dims[0], dims[1]};
  }
  return std::nullopt;
}

void check_size(const std::string& path, std::int64_t w, std::int64_t h, const MapLoadOptions& options) {
  if (w <= 0 || h <= 0) throw InputError(fmt::format("{}: image has no pixels ({}x{})", path, w, h));
  if (w > kHugeSide || h > kHugeSide) {
    throw InputError(fmt::format("{}: image declares a {} of more than {} pixels, over the size limit of {} cells", path,
                                 w > kHugeSide ? "width" : "height", kHugeSide, options.max_cells));
  }
  if (w > options.max_cells / h) {  // w * h > max_cells, without overflow
    const std::string cells = w <= INT64_MAX / h ? std::to_string(w * h) : std::string("more than 9e18");
    throw InputError(fmt::format("{}: image is {}x{} = {} cells, over the size limit of {} cells", path, w, h, cells,
                                 options.max_cells));
  }
}

// Decodes a PNG with libpng's simplified API, which reports every problem in its return value and
// never prints (OpenCV's PNG decoder lets libpng print "libpng error/warning: ..." to stderr).
// Pixels come out as OpenCV would give them: grey, grey+alpha, BGR or BGRA; 16-bit stays 16-bit.
cv::Mat decode_png(const std::string& bytes, const std::string& source, const MapLoadOptions& options) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  const auto fail = [&](const char* what) {
    const std::string message = png.message[0] ? png.message : "invalid data";
    png_image_free(&png);
    throw InputError(source + ": " + what + " (" + message + ")");
  };
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) fail("cannot decode PNG");
  check_size(source, png.width, png.height, options);
  // 16-bit files are linear in libpng's model: read them as linear 16-bit so that no gamma
  // conversion happens (alpha then comes premultiplied; map images rarely carry partial alpha).
  const bool sixteen = (png.format & PNG_FORMAT_FLAG_LINEAR) != 0;
  const bool colour = (png.format & PNG_FORMAT_FLAG_COLOR) != 0, alpha = (png.format & PNG_FORMAT_FLAG_ALPHA) != 0;
  png.format = (colour ? PNG_FORMAT_FLAG_COLOR | PNG_FORMAT_FLAG_BGR : 0) | (alpha ? PNG_FORMAT_FLAG_ALPHA : 0) |
               (sixteen ? PNG_FORMAT_FLAG_LINEAR : 0);
  const int channels = (colour ? 3 : 1) + (alpha ? 1 : 0);
  cv::Mat image(static_cast<int>(png.height), static_cast<int>(png.width), CV_MAKETYPE(sixteen ? CV_16U : CV_8U, channels));
  if (!png_image_finish_read(&png, nullptr, image.data, static_cast<png_int_32>(image.step[0] / (sixteen ? 2 : 1)),
                             nullptr)) {
    fail("cannot decode PNG, truncated or corrupt");
  }
  png_image_free(&png);
  return image;
}

// Decodes a Netpbm image (P1-P6) without OpenCV: cv::imdecode picks its decoder by content, and an
// input that starts like a PGM can still reach another decoder (fuzz_map_image found a "P6" file
// that sent OpenCV to its DICOM reader, which aborts). Samples are scaled to 0-255 by the file's
// maxval (as ROS map_server reads them); grey (P1, P2, P4, P5) or BGR (P3, P6), 8-bit.
cv::Mat decode_pnm(const std::string& bytes, const std::string& source, const MapLoadOptions& options) {
  const char kind = bytes[1];
  const bool bitmap = kind == '1' || kind == '4', binary = kind >= '4', colour = kind == '3' || kind == '6';
  const auto fail = [&](const std::string& what) -> void {
    throw InputError(source + ": cannot decode " + (colour ? "PPM" : (bitmap ? "PBM" : "PGM")) + " (" + what + ")");
  };
  std::size_t i = 2;
  const auto skip_space = [&](bool comments) {
    while (i < bytes.size()) {
      if (comments && bytes[i] == '#') {
        while (i < bytes.size() && bytes[i] != '\n') ++i;
      } else if (std::isspace(static_cast<unsigned char>(bytes[i]))) {
        ++i;
      } else {
        break;
      }
    }
  };
  // A decimal number up to `most`, after whitespace (and comments in the header).
  const auto number = [&](bool comments, std::int64_t most, const char* what) {
    skip_space(comments);
    if (i >= bytes.size()) fail(std::string("file ends before the ") + what);
    if (!std::isdigit(static_cast<unsigned char>(bytes[i]))) fail(std::string("expected a number for the ") + what);
    std::int64_t v = 0;
    while (i < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[i]))) {
      v = v * 10 + (bytes[i++] - '0');
      if (v > most) fail(std::string(what) + " too large");
    }
    return v;
  };
  const std::int64_t w = number(true, kHugeSide, "width"), h = number(true, kHugeSide, "height");
  check_size(source, w, h, options);
  const int maxval = bitmap ? 1 : int(number(true, 65535, "maxval"));
  if (maxval < 1) fail("maxval must be 1 to 65535");
  if (binary) {
    if (i >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[i]))) fail("no whitespace after the header");
    ++i;
  }
  const int channels = colour ? 3 : 1;
  const int sample_bytes = maxval > 255 ? 2 : 1;
  const std::int64_t row_bytes = bitmap ? (w + 7) / 8 : w * channels * sample_bytes;
  if (binary && std::int64_t(bytes.size() - i) < row_bytes * h) fail("truncated pixel data");
  cv::Mat image(int(h), int(w), CV_8UC(channels));
  const auto scaled = [&](std::int64_t v) {
    if (v > maxval) fail("a sample is above maxval " + std::to_string(maxval));
    return static_cast<std::uint8_t>((v * 255 + maxval / 2) / maxval);
  };
  const auto* raw = reinterpret_cast<const unsigned char*>(bytes.data());
  for (int y = 0; y < int(h); ++y) {
    auto* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < int(w); ++x) {
      for (int c = 0; c < channels; ++c) {
        std::int64_t v = 0;
        if (kind == '4') {
          v = (raw[i + std::size_t(x / 8)] >> (7 - x % 8)) & 1;
        } else if (binary) {
          const std::size_t at = i + std::size_t((std::int64_t(x) * channels + c) * sample_bytes);
          v = sample_bytes == 2 ? (std::int64_t{raw[at]} << 8) | raw[at + 1] : raw[at];
        } else if (kind == '1') {
          skip_space(false);
          if (i >= bytes.size() || (bytes[i] != '0' && bytes[i] != '1')) fail("expected 0 or 1");
          v = bytes[i++] - '0';
        } else {
          v = number(false, 65535, "sample");
        }
        // PBM: 1 is black. PPM: OpenCV's channel order, blue first.
        row[x * channels + (colour ? 2 - c : 0)] = bitmap ? (v ? 0 : 255) : scaled(v);
      }
    }
    if (binary) i += std::size_t(row_bytes);
  }
  return image;
}

cv::Mat read_image(const fs::path& path, const MapLoadOptions& options) {
  return decode_map_image(io::read_file(path), path.string(), options);
}

}  // namespace

namespace {

// The name of an image format that is not a map format, from its first bytes; "" when unknown.
std::string image_format_name(const std::string& bytes) {
  const auto starts = [&](std::string_view magic) { return bytes.compare(0, magic.size(), magic) == 0; };
  if (starts("\xFF\xD8\xFF")) return "JPEG";
  if (starts("GIF8")) return "GIF";
  if (starts("BM")) return "BMP";
  if (starts(std::string_view("II*\0", 4)) || starts(std::string_view("MM\0*", 4))) return "TIFF";
  if (starts("RIFF") && bytes.size() >= 12 && bytes.compare(8, 4, "WEBP") == 0) return "WebP";
  return "";
}

// The decoded samples, 8- or 16-bit as the file holds them.
cv::Mat decode_samples(const std::string& bytes, const std::string& source, const MapLoadOptions& options) {
  if (bytes.empty()) throw InputError(source + ": empty file, expected a PNG or PGM image");
  if (bytes.size() > std::size_t{INT32_MAX}) throw InputError(source + ": file too large for an image");
  if (const auto size = peek_image_size(bytes)) check_size(source, size->first, size->second, options);
  static const unsigned char kPng[4] = {0x89, 'P', 'N', 'G'};
  const bool is_png = bytes.size() >= 4 && std::equal(kPng, kPng + 4, reinterpret_cast<const unsigned char*>(bytes.data()));
  // PGM/PPM/PBM ("P1".."P6"); other formats OpenCV could decode (JPEG 2000, TIFF, ...) are not map
  // formats, and their decoders log to stderr.
  const bool is_pnm = bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6';
  if (!is_png && !is_pnm) {
    const std::string kind = image_format_name(bytes);
    throw InputError(source + ": " + (kind.empty() ? "not a PNG or PGM image" : "a " + kind + " image; fleetmap reads maps as "
                                                      "PNG or PGM: convert it to PNG"));
  }
  cv::Mat image;
  if (is_png) {
    image = decode_png(bytes, source, options);
  } else {
    image = decode_pnm(bytes, source, options);
  }
  if (image.empty()) throw InputError(source + ": cannot decode image (not a valid PNG/PGM, or truncated)");
  check_size(source, image.cols, image.rows, options);
  if (image.depth() != CV_8U && image.depth() != CV_16U) {
    throw InputError(source + ": unsupported image format (expected 8- or 16-bit grey, RGB or RGBA)");
  }
  return image;
}

}  // namespace

cv::Mat decode_map_image(const std::string& bytes, const std::string& source, const MapLoadOptions& options) {
  cv::Mat image = decode_samples(bytes, source, options);
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.channels() > 4) throw InputError(source + ": unsupported image format (expected 8- or 16-bit grey, RGB or RGBA)");
  return image;
}

MapYaml parse_map_yaml(std::string_view text, const std::string& source) {
  const YAML::Node root = io::parse_yaml(std::string(text), source);
  if (!root.IsMap()) throw InputError(source + ": expected a map_server YAML mapping with 'image' and 'resolution'");
  io::YamlMap m(root, source);
  MapYaml y;
  if (!m.has("image")) throw InputError(source + ": missing key 'image' (the map image file)");
  y.image = m.text("image", "");
  if (y.image.empty()) throw InputError(m.where("image") + ": expected a file name");
  if (!m.has("resolution")) throw InputError(source + ": missing key 'resolution' (metres per cell)");
  {
    const auto n = *m.node("resolution");
    const auto v = n.IsScalar() ? core::parse_in_range(n.Scalar(), kResolutionRange) : std::nullopt;
    if (!v) {
      throw InputError(m.where("resolution") + ": expected metres per cell, " + core::expected_text(kResolutionRange) +
                       ", got " + io::describe_node(n));
    }
    y.resolution = *v;
  }
  if (const auto o = m.node("origin")) {
    if (!o->IsSequence() || o->size() != 3) {
      throw InputError(m.where("origin") + ": expected [x, y, yaw], got " + io::describe_node(*o));
    }
    const auto v = m.numbers("origin", 3);
    for (const double c : v) {
      if (!core::parse_in_range(fmt::format("{}", c), kOriginRange)) {
        throw InputError(m.where("origin") + ": expected [x, y, yaw] with each " + core::expected_text(kOriginRange) +
                         ", got " + fmt::format("{}", c));
      }
    }
    y.origin = core::Pose2(v[0], v[1], v[2]);
  }
  if (const auto n = m.node("negate")) {
    // map_server writes 0 / 1; true / false are accepted too.
    const std::string s = n->IsScalar() ? n->Scalar() : "";
    if (s == "0" || s == "1") y.negate = s == "1";
    else y.negate = m.boolean("negate", false);
  }
  y.occupied_thresh = m.number("occupied_thresh", y.occupied_thresh, 0.0, 1.0);
  y.free_thresh = m.number("free_thresh", y.free_thresh, 0.0, 1.0);
  if (y.free_thresh > y.occupied_thresh) {
    throw InputError(fmt::format("{}: free_thresh ({}) is above occupied_thresh ({})", source, y.free_thresh,
                                 y.occupied_thresh));
  }
  const std::string mode = m.choice("mode", "trinary", {"trinary", "scale", "raw"});
  y.mode = mode == "trinary" ? MapMode::Trinary : (mode == "scale" ? MapMode::Scale : MapMode::Raw);
  m.finish();
  return y;
}

namespace {

// As map_saver writes numbers ("%.6f", or "%.3f" for thresholds) when that reads back as the same
// number, else the shortest text that does (a resolution of 0.05 / 3 must not lose digits).
std::string exact_number(double v, int decimals) {
  const std::string text = fmt::format("{:.{}f}", v, decimals);
  if (std::strtod(text.c_str(), nullptr) == v) return text;
  return fmt::format("{}", v);
}

// A file name as map_saver writes it (plain), or quoted when YAML would read a plain one otherwise.
std::string yaml_file_name(const std::string& name) {
  const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == '/';
  });
  return plain ? name : io::yaml_quoted(name);
}

}  // namespace

std::string format_map_yaml(const MapYaml& y) {
  const char* mode = y.mode == MapMode::Trinary ? "trinary" : (y.mode == MapMode::Scale ? "scale" : "raw");
  return "image: " + yaml_file_name(y.image.string()) + "\nmode: " + mode + "\nresolution: " + exact_number(y.resolution, 6) +
         "\norigin: [" + exact_number(y.origin.x, 6) + ", " + exact_number(y.origin.y, 6) + ", " +
         exact_number(y.origin.theta, 6) + "]\nnegate: " + (y.negate ? "1" : "0") +
         "\noccupied_thresh: " + exact_number(y.occupied_thresh, 3) + "\nfree_thresh: " + exact_number(y.free_thresh, 3) +
         "\n";
}

mapping::OccupancyGrid grid_from_image(const cv::Mat& image, const MapYaml& meta, const mapping::OccupancyGridOptions& grid_options) {
  if (image.empty() || image.depth() != CV_8U || image.channels() > 4) {
    throw Error("grid_from_image: expected a non-empty 8-bit image with 1 to 4 channels");
  }
  mapping::OccupancyGrid grid(core::GridGeometry(meta.resolution, image.cols, image.rows, meta.origin), grid_options);
  const int channels = image.channels();
  const bool has_alpha = channels == 2 || channels == 4;
  const int colour_channels = has_alpha ? channels - 1 : channels;
  const float lo = grid.min_log_odds(), hi = grid.max_log_odds();
  // A cell's log-odds depends only on the sum of its colour channels and whether it is opaque:
  // worked out once per value, not once per cell.
  const int sums = 255 * colour_channels + 1;
  std::vector<float> table(std::size_t(2 * sums), 0.0f);
  for (int opaque = 0; opaque < 2; ++opaque) {
    for (int sum = 0; sum < sums; ++sum) {
      double colour = static_cast<double>(sum) / colour_channels;
      if (meta.negate) colour = 255.0 - colour;
      std::optional<double> probability;  // nullopt: unknown
      if (meta.mode == MapMode::Raw) {
        const int v = static_cast<int>(std::lround(colour));
        if (v <= 100) probability = v / 100.0;
      } else if (meta.mode == MapMode::Trinary && !meta.negate && sum == kSaverUnknown * colour_channels) {
        // map_saver's unknown grey, whatever the thresholds say (below).
      } else {
        const double occ = (255.0 - colour) / 255.0;
        if (occ > meta.occupied_thresh) probability = 1.0;
        else if (occ < meta.free_thresh) probability = 0.0;
        else if (meta.mode == MapMode::Scale && opaque) {
          const double ratio = (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh);
          probability = (1.0 + 98.0 * ratio) / 100.0;
        }
      }
      float l = 0.0f;
      if (probability) {
        l = *probability <= 0.0 ? lo
            : *probability >= 1.0 ? hi
                                  : std::clamp(static_cast<float>(mapping::probability_to_log_odds(*probability)), lo, hi);
      }
      table[std::size_t(opaque * sums + sum)] = l;
    }
  }
  for (int row = 0; row < image.rows; ++row) {
    const std::uint8_t* p = image.ptr<std::uint8_t>(row);
    const int y = image.rows - 1 - row;  // image top row is the map's last row
    for (int x = 0; x < image.cols; ++x, p += channels) {
      int sum = 0;
      for (int k = 0; k < colour_channels; ++k) sum += p[k];
      if (has_alpha && p[channels - 1] < kOpaqueAlpha) {
        grid.set_log_odds({x, y}, 0.0f);  // transparent: nothing was drawn here
        continue;
      }
      const bool opaque = !has_alpha || p[channels - 1] == 255;
      grid.set_log_odds({x, y}, table[std::size_t((opaque ? sums : 0) + sum)]);
    }
  }
  return grid;
}

cv::Mat grid_to_image(const mapping::OccupancyGrid& grid) {
  cv::Mat image(grid.height(), grid.width(), CV_8UC1);
  for (int row = 0; row < grid.height(); ++row) {
    std::uint8_t* p = image.ptr<std::uint8_t>(row);
    const int y = grid.height() - 1 - row;
    for (int x = 0; x < grid.width(); ++x) {
      switch (grid.state({x, y})) {
        case mapping::CellState::Free: p[x] = 254; break;
        case mapping::CellState::Occupied: p[x] = 0; break;
        case mapping::CellState::Unknown: p[x] = 205; break;
      }
    }
  }
  return image;
}

mapping::OccupancyGrid load_map(const fs::path& path, const MapLoadOptions& options) {
  const std::string ext = path.extension().string();
  if (ext == ".yaml" || ext == ".yml") {
    const MapYaml meta = parse_map_yaml(io::read_file(path, 1 << 20), path.string());
    const fs::path image_path = meta.image.is_absolute() ? meta.image : path.parent_path() / meta.image;
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(image_path, ec))) {
      throw InputError(path.string() + ": key 'image': file '" + image_path.string() + "' does not exist");
    }
    return grid_from_image(read_image(image_path, options), meta, options.grid);
  }
  if (!core::parse_in_range(fmt::format("{}", options.default_resolution), kResolutionRange)) {
    throw InputError(fmt::format("{}: resolution: expected metres per cell, {}, got {}", path.string(),
                                 core::expected_text(kResolutionRange), options.default_resolution));
  }
  MapYaml meta;
  meta.resolution = options.default_resolution;
  return grid_from_image(read_image(path, options), meta, options.grid);
}

namespace {

std::string share(std::int64_t n, std::int64_t of) {
  return fmt::format("{} pixel{} ({:.1f}%)", n, n == 1 ? "" : "s", of > 0 ? 100.0 * double(n) / double(of) : 0.0);
}

}  // namespace

std::vector<std::string> map_reading_notes(const fs::path& path, const MapLoadOptions& options,
                                           const std::string& resolution_source) {
  const std::string ext = path.extension().string();
  const bool bare = ext != ".yaml" && ext != ".yml";
  MapYaml meta;
  fs::path image_path = path;
  if (bare) {
    meta.resolution = options.default_resolution;
  } else {
    meta = parse_map_yaml(io::read_file(path, 1 << 20), path.string());
    image_path = meta.image.is_absolute() ? meta.image : path.parent_path() / meta.image;
  }
  cv::Mat image = decode_samples(io::read_file(image_path), image_path.string(), options);
  std::vector<std::string> notes;
  const std::string name = path.string();
  if (bare) {
    // The defaults a bare image takes, said once: its resolution (unless the user gave it) and the
    // thresholds, in greys.
    const std::string resolution =
        resolution_source.empty() ? "" : fmt::format(", read at {} m per cell, {};", meta.resolution, resolution_source);
    notes.push_back(fmt::format("{}: a bare image (no map_server YAML){} walls darker than {}, free lighter than {} "
                                "(map_server's default thresholds)",
                                name, resolution.empty() ? ":" : resolution,
                                int(std::ceil(255.0 * (1.0 - meta.occupied_thresh))),
                                int(std::floor(255.0 * (1.0 - meta.free_thresh)))));
  }
  if (meta.origin.theta != 0.0) {
    notes.push_back(fmt::format("{}: origin yaw {} rad: coordinates (--from, --start, ...) are turned by it, while pictures "
                                "draw the map in its own cells, unturned",
                                name, meta.origin.theta));
  }
  if (image.depth() == CV_16U) {
    double most = 0.0;
    cv::minMaxLoc(image.reshape(1), nullptr, &most);
    if (most <= 255.0) {
      notes.push_back(fmt::format("{}: a 16-bit image whose samples all lie below 256, read on the 16-bit scale (as black): "
                                  "if they are 8-bit greys, save the image as 8-bit",
                                  name));
    }
    image.convertTo(image, CV_8U, 1.0 / 257.0);
  }
  if (meta.mode == MapMode::Raw) return notes;
  const int channels = image.channels();
  const bool has_alpha = channels == 2 || channels == 4;
  const int colour_channels = has_alpha ? channels - 1 : channels;
  std::int64_t pixels = 0, transparent = 0, coloured = 0, grey_unknown = 0, saver_unknown = 0;
  std::int64_t as[3] = {0, 0, 0}, coloured_as[3] = {0, 0, 0};  // wall, free, unknown
  int darkest = 256, lightest = -1;  // of the grey pixels read as unknown, as they are in the file
  for (int row = 0; row < image.rows; ++row) {
    const std::uint8_t* p = image.ptr<std::uint8_t>(row);
    for (int x = 0; x < image.cols; ++x, p += channels) {
      ++pixels;
      if (has_alpha && p[channels - 1] < kOpaqueAlpha) {
        ++transparent;
        continue;
      }
      int sum = 0, lo = 255, hi = 0;
      for (int k = 0; k < colour_channels; ++k) sum += p[k], lo = std::min<int>(lo, p[k]), hi = std::max<int>(hi, p[k]);
      const double raw = double(sum) / colour_channels;
      const double occ = (255.0 - (meta.negate ? 255.0 - raw : raw)) / 255.0;
      const bool saver = meta.mode == MapMode::Trinary && !meta.negate && sum == kSaverUnknown * colour_channels;
      const int state = saver ? 2 : occ > meta.occupied_thresh ? 0 : occ < meta.free_thresh ? 1 : 2;
      ++as[state];
      // A colour is a pixel whose channels differ by more than an eighth of the scale.
      if (hi - lo > 32) {
        ++coloured, ++coloured_as[state];
      } else if (saver) {
        ++saver_unknown;
      } else if (state == 2 && std::abs(raw - kSaverUnknown) > 2.0) {
        ++grey_unknown;
        darkest = std::min(darkest, int(std::lround(raw)));
        lightest = std::max(lightest, int(std::lround(raw)));
      }
    }
  }
  // occ = (255 - colour) / 255 with colour the grey, or 255 - the grey when negated.
  const double wall_colour = 255.0 * (1.0 - meta.occupied_thresh), free_colour = 255.0 * (1.0 - meta.free_thresh);
  const std::string thresholds = fmt::format("occupied_thresh {}, free_thresh {}{}{}", meta.occupied_thresh,
                                             meta.free_thresh, meta.negate ? ", negate" : "",
                                             bare ? ", map_server's defaults" : "");
  const std::string rule =
      meta.negate ? fmt::format("lighter than {} is a wall, darker than {} free: {}", int(std::floor(255.0 - wall_colour)),
                                int(std::ceil(255.0 - free_colour)), thresholds)
                  : fmt::format("darker than {} is a wall, lighter than {} free: {}", int(std::ceil(wall_colour)),
                                int(std::floor(free_colour)), thresholds);
  if (transparent > 0) {
    notes.push_back(fmt::format("{}: {} are transparent, read as unknown", name, share(transparent, pixels)));
  }
  const double saver_occ = (255.0 - kSaverUnknown) / 255.0;
  if (saver_unknown > 0 && (saver_occ < meta.free_thresh || saver_occ > meta.occupied_thresh)) {
    notes.push_back(fmt::format("{}: {} are map_saver's unknown grey {}, read as unknown as map_saver meant, although the "
                                "thresholds ({}) would read them as {} (nav2's map_saver wrote free_thresh 0.25)",
                                name, share(saver_unknown, pixels), kSaverUnknown, thresholds,
                                saver_occ < meta.free_thresh ? "free" : "walls"));
  }
  if (grey_unknown > 0 && (as[0] == 0 || 100 * grey_unknown >= pixels)) {
    const int wall_grey = meta.negate ? lightest : darkest;
    const double occ = (255.0 - (meta.negate ? 255.0 - wall_grey : wall_grey)) / 255.0;
    notes.push_back(fmt::format("{}: {} are grey from {} to {}, between the thresholds, and read as unknown ({}); to read "
                                "grey {} as walls, give a map_server YAML with occupied_thresh below {:.3f}",
                                name, share(grey_unknown, pixels), darkest, lightest, rule, wall_grey, occ));
  }
  if (coloured > 0) {
    notes.push_back(fmt::format("{}: {} are coloured, each read by the mean of its red, green and blue ({}): {} as walls, "
                                "{} as free, {} as unknown",
                                name, share(coloured, pixels), rule, coloured_as[0], coloured_as[1], coloured_as[2]));
  }
  // A building's map has more floor than wall; the other way round, free space may be drawn dark.
  if (as[0] > as[1]) {
    notes.push_back(fmt::format("{}: {} read as walls and {} as free; if free space is drawn dark, give a map_server YAML "
                                "with negate: {}",
                                name, share(as[0], pixels), share(as[1], pixels), meta.negate ? 0 : 1));
  }
  return notes;
}

std::vector<fs::path> map_files(const fs::path& path) {
  const std::string ext = path.extension().string();
  if (ext != ".yaml" && ext != ".yml") return {path};
  try {
    const MapYaml meta = parse_map_yaml(io::read_file(path, 1 << 20), path.string());
    return {path, meta.image.is_absolute() ? meta.image : path.parent_path() / meta.image};
  } catch (const Error&) {
    return {path};
  }
}

namespace {

// Binary PGM (P5) of an 8- or 16-bit single-channel image, 16-bit samples big-endian, as Netpbm
// (and OpenCV) write it; empty for other images.
std::string encode_pgm(const cv::Mat& image) {
  if (image.empty() || image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U)) return {};
  const bool sixteen = image.depth() == CV_16U;
  std::string out = fmt::format("P5\n{} {}\n{}\n", image.cols, image.rows, sixteen ? 65535 : 255);
  for (int y = 0; y < image.rows; ++y) {
    if (!sixteen) {
      out.append(image.ptr<char>(y), std::size_t(image.cols));
      continue;
    }
    for (const std::uint16_t v : std::span(image.ptr<std::uint16_t>(y), std::size_t(image.cols))) {
      out.push_back(char(v >> 8));
      out.push_back(char(v & 0xff));
    }
  }
  return out;
}

}  // namespace

std::string encode_png(const cv::Mat& image, int compression_level) {
  const int depth = image.depth(), channels = image.channels();
  if (image.empty() || (depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4)) return {};
  // libpng reports errors by longjmp from this handler; warnings are dropped (nothing below cli prints).
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, nullptr, [](png_structp p, png_const_charp) { png_longjmp(p, 1); },
      [](png_structp, png_const_charp) {});
  if (!png) return {};
  png_infop info = png_create_info_struct(png);
  std::string buffer;
  std::vector<png_bytep> rows(std::size_t(image.rows));
  volatile bool ok = false;  // set after setjmp: volatile, so that a longjmp cannot leave a stale copy
  if (info && setjmp(png_jmpbuf(png)) == 0) {
    png_set_write_fn(
        png, &buffer,
        [](png_structp p, png_bytep data, png_size_t n) {
          static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
        },
        [](png_structp) {});
    if (compression_level >= 0) {
      png_set_compression_level(png, std::min(compression_level, Z_BEST_COMPRESSION));
      png_set_compression_strategy(png, Z_DEFAULT_STRATEGY);
    } else {  // fast: OpenCV's default
      png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
      png_set_compression_level(png, Z_BEST_SPEED);
      png_set_compression_strategy(png, Z_RLE);
    }
    png_set_IHDR(png, info, png_uint_32(image.cols), png_uint_32(image.rows), depth == CV_8U ? 8 : 16,
                 channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_set_bgr(png);   // OpenCV's channel order
    png_set_swap(png);  // 16-bit samples are little-endian in memory here, big-endian in a PNG
    for (int y = 0; y < image.rows; ++y) rows[std::size_t(y)] = const_cast<png_bytep>(image.ptr<png_byte>(y));
    png_write_image(png, rows.data());
    png_write_end(png, info);
    ok = true;
  }
  png_destroy_write_struct(&png, &info);
  return ok ? buffer : std::string();
}

std::string encode_image(const std::string& ext, const cv::Mat& image, const std::string& what) {
  if (ext.empty()) throw InputError(what + ": output image needs an extension (.png, .pgm)");
  const std::string bytes = ext == ".png" ? encode_png(image) : ext == ".pgm" ? encode_pgm(image) : std::string();
  if (bytes.empty()) {
    throw InputError(what + ": cannot write " + (image.channels() == 1 ? "a map image" : "a picture") + " as '" + ext +
                     "' (" + (image.channels() == 1 ? "use .png or .pgm" : "use .png") + ")");
  }
  return bytes;
}

void check_picture_path(const fs::path& path, const std::string& what) {
  if (io::is_standard_output(path)) return;
  const std::string ext = path.extension().string();
  if (ext != ".png") {
    throw InputError(what + " " + path.string() + ": pictures are written as PNG; give a .png name (or - for the standard output)");
  }
}

void write_image(const fs::path& path, const cv::Mat& image) {
  io::write_file_atomic(path, encode_image(path.extension().string(), image, path.string()));
}

void save_map_image(const mapping::OccupancyGrid& grid, const fs::path& path) { write_image(path, grid_to_image(grid)); }

namespace {

bool is_yaml_name(const fs::path& path) {
  const std::string ext = path.extension().string();
  return ext == ".yaml" || ext == ".yml";
}

fs::path image_beside(const fs::path& yaml_path) {
  fs::path image_name = yaml_path.stem();
  image_name += ".pgm";
  return image_name;
}

}  // namespace

bool is_map_file_name(const fs::path& path) { return is_yaml_name(path) || path.extension() == ".pgm"; }

std::vector<fs::path> map_output_files(const fs::path& path) {
  if (!is_yaml_name(path)) return {path};
  return {path, path.parent_path() / image_beside(path)};
}

void save_map(const mapping::OccupancyGrid& grid, const fs::path& path) {
  if (is_yaml_name(path)) {
    save_map_yaml(grid, path);
  } else if (path.extension() == ".pgm") {
    save_map_image(grid, path);
  } else {
    throw InputError(path.string() + ": maps are written as map_server YAML (.yaml, with a .pgm beside it) or .pgm");
  }
}

void save_map_yaml(const mapping::OccupancyGrid& grid, const fs::path& yaml_path) {
  const fs::path image_name = image_beside(yaml_path);
  save_map_image(grid, yaml_path.parent_path() / image_name);
  MapYaml meta;
  meta.image = image_name;
  meta.resolution = grid.resolution();
  meta.origin = grid.geometry().origin();
  io::write_file_atomic(yaml_path, format_map_yaml(meta));
}

MapImage map_image(const mapping::OccupancyGrid& grid) {
  const cv::Mat image = grid_to_image(grid);
  return {image.cols, image.rows, std::vector<std::uint8_t>(image.datastart, image.dataend)};
}

mapping::OccupancyGrid grid_from_map_image(const MapImage& image, const MapYaml& meta,
                                           const mapping::OccupancyGridOptions& grid_options) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != std::size_t(image.width) * std::size_t(image.height)) {
    throw InputError("map image: expected width x height pixels, got " + std::to_string(image.pixels.size()) + " for " +
                     std::to_string(image.width) + " x " + std::to_string(image.height));
  }
  // OpenCV reads the pixels in place; grid_from_image only reads them.
  const cv::Mat view(image.height, image.width, CV_8UC1, const_cast<std::uint8_t*>(image.pixels.data()));
  return grid_from_image(view, meta, grid_options);
}

}  // namespace fleetmap::io
