#include "merging/hamming.h"

#include <bit>
#include <climits>
#include <cstdint>
#include <cstring>

#include "core/error.h"

namespace fleetmap::merging {

namespace {

// Rows as 64-bit words, the last one padded with zero bytes (which add nothing to a distance).
std::vector<std::uint64_t> as_words(const cv::Mat& m, int words) {
  std::vector<std::uint64_t> out(std::size_t(m.rows) * std::size_t(words), 0);
  for (int r = 0; r < m.rows; ++r) std::memcpy(&out[std::size_t(r) * std::size_t(words)], m.ptr(r), std::size_t(m.cols));
  return out;
}

[[gnu::always_inline]] inline void nearest_two_words(const std::uint64_t* query, int queries, const std::uint64_t* train,
                                                     int trains, int words, NearestTwo* out) {
  for (int i = 0; i < queries; ++i) {
    const std::uint64_t* q = query + std::size_t(i) * std::size_t(words);
    int best = INT_MAX, second = INT_MAX, index = -1;
    for (int j = 0; j < trains; ++j) {
      const std::uint64_t* t = train + std::size_t(j) * std::size_t(words);
      int d = 0;
      for (int w = 0; w < words; ++w) d += std::popcount(q[w] ^ t[w]);
      // As OpenCV's batchDistance keeps its k nearest: an equal distance goes after the ones kept.
      if (d < second) {
        if (d < best) {
          second = best, best = d, index = j;
        } else {
          second = d;
        }
      }
    }
    out[i] = {index, best, second};
  }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
// The same loop with the processor's popcount instruction (x86-64 from 2008 on; the portable build
// counts bits in a library call, eight times slower).
__attribute__((target("popcnt"))) void nearest_two_popcnt(const std::uint64_t* query, int queries, const std::uint64_t* train,
                                                          int trains, int words, NearestTwo* out) {
  nearest_two_words(query, queries, train, trains, words, out);
}
#endif

}  // namespace

std::vector<NearestTwo> nearest_two_hamming(const cv::Mat& query, const cv::Mat& train) {
  if (query.type() != CV_8U || train.type() != CV_8U || query.cols != train.cols)
    throw InputError("nearest_two_hamming: the descriptors must be CV_8U rows of one width");
  if (train.rows < 2) throw InputError("nearest_two_hamming: the train set needs at least two descriptors");
  const int words = (query.cols + 7) / 8;
  const auto q = as_words(query, words), t = as_words(train, words);
  std::vector<NearestTwo> out(std::size_t(query.rows));
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (__builtin_cpu_supports("popcnt")) {
    nearest_two_popcnt(q.data(), query.rows, t.data(), train.rows, words, out.data());
    return out;
  }
#endif
  nearest_two_words(q.data(), query.rows, t.data(), train.rows, words, out.data());
  return out;
}

}  // namespace fleetmap::merging
