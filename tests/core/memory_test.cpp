#include "core/memory.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <vector>

namespace fleetmap::core {
namespace {

long page_faults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

constexpr std::size_t kPage = 4096;

// What a merge of two large maps does to the allocator: blocks of 1 to 16 MB alive at once, written,
// then all freed. Returns the sum of one byte a page (so that nothing is optimized away).
long merge_like_round(std::size_t& bytes) {
  const std::size_t mb = std::size_t(1) << 20;
  const std::size_t sizes[] = {1 * mb, 4 * mb, 1 * mb, 2 * mb, 4 * mb, 1 * mb, 16 * mb, 1 * mb, 4 * mb, 1 * mb};
  std::vector<unsigned char*> blocks;
  bytes = 0;
  for (int k = 0; k < 2; ++k) {
    for (const std::size_t size : sizes) {
      auto* block = static_cast<unsigned char*>(std::malloc(size));
      EXPECT_NE(block, nullptr);
      std::memset(block, k + 1, size);
      blocks.push_back(block);
      bytes += size;
    }
  }
  long sum = 0;
  for (unsigned char* block : blocks) {
    sum += block[kPage];
    std::free(block);
  }
  return sum;
}

TEST(KeepFreedMemory, RepeatedLargeAllocationsNoLongerFaultTheirPagesInAgain) {
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's allocator replaces glibc's and has no such setting: the call says so.
  EXPECT_FALSE(keep_freed_memory());
  return;
#endif
  ASSERT_TRUE(keep_freed_memory());  // glibc, as on every machine fleetmap is built for (Debian 12)
  std::size_t bytes = 0;
  EXPECT_GT(merge_like_round(bytes), 0);  // the first round maps its pages
  // Later rounds reuse them. With glibc's defaults every round faults nearly all of its 17920 pages
  // in again (measured with the setting left out: 16864 to 17920 faults a round).
  for (int round = 0; round < 3; ++round) {
    const long before = page_faults();
    EXPECT_GT(merge_like_round(bytes), 0);
    const long faults = page_faults() - before;
    EXPECT_LT(faults, long(bytes / kPage / 10)) << "round " << round << ": " << faults << " page faults for "
                                                << bytes / kPage << " pages";
  }
}

TEST(KeepFreedMemory, RefusesSizesTheCLibraryCannotTake) {
  EXPECT_FALSE(keep_freed_memory(std::size_t(1) << 40, std::size_t(128) << 20));
  EXPECT_FALSE(keep_freed_memory(std::size_t(32) << 20, std::size_t(1) << 40));
}

}  // namespace
}  // namespace fleetmap::core
