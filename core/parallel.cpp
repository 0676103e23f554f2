#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace fleetmap::core {

void parallel_for(int count, int threads, const std::function<void(int)>& job, const std::function<void(int)>& on_done) {
  std::atomic<int> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;  // guards on_done and `failure`
  std::exception_ptr failure;
  const auto worker = [&]() {
    while (!stop) {
      const int i = next++;
      if (i >= count) return;
      try {
        job(i);
        const std::lock_guard lock(mutex);
        if (on_done) on_done(i);
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
      }
    }
  };
  const int n = std::max(1, std::min(threads, count));
  {
    std::vector<std::jthread> pool;
    for (int t = 1; t < n; ++t) pool.emplace_back(worker);
    worker();
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace fleetmap::core
