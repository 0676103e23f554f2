#pragma once
// Running independent jobs on a few threads: written once for sweeps and repeated experiments.
#include <functional>

namespace fleetmap::core {

// Runs job(0) .. job(count - 1) on up to `threads` threads (the calling one among them), each
// thread taking the next index in order. `on_done(index)` is called after each job, one call at a
// time (it may update shared results or a progress bar without locking). The first exception of a
// job stops the hand-out of further indices and is rethrown here once the running jobs are over.
void parallel_for(int count, int threads, const std::function<void(int)>& job,
                  const std::function<void(int)>& on_done = {});

}  // namespace fleetmap::core
