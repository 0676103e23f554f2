#include "core/memory.h"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fleetmap::core {

bool keep_freed_memory(std::size_t heap_block_bytes, std::size_t retain_bytes) {
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
  // mallopt takes ints; glibc caps M_MMAP_THRESHOLD at 32 MiB on 64-bit systems (and refuses more).
  if (heap_block_bytes > std::size_t(INT_MAX) || retain_bytes > std::size_t(INT_MAX)) return false;
  return mallopt(M_MMAP_THRESHOLD, int(heap_block_bytes)) == 1 && mallopt(M_TRIM_THRESHOLD, int(retain_bytes)) == 1;
#else
  (void)heap_block_bytes, (void)retain_bytes;
  return false;
#endif
}

}  // namespace fleetmap::core
