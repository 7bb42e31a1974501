#pragma once
// The one parallel loop of artcal (optimizer starts, Monte-Carlo trials): indices handed out in
// order to `threads` workers, each result written by index so that the outcome does not depend
// on the thread count.

#include <functional>
#include <thread>

namespace artcal {

/// Most worker threads of one loop: more would only cost memory and thread creation (which fails
/// somewhere in the thousands; `confirm --threads 100000` aborted).
inline constexpr int kMaxThreads = 256;

/// Threads to use for `requested` (0 or less: the hardware's), never more than `count` or
/// kMaxThreads and never fewer than 1.
int threadCount(int requested, int count);

/// Runs work(i, worker) for i = 0 .. count-1 on `threads` workers (worker = 0 .. threads-1 is the
/// calling thread and the ones it starts; state per worker can be kept in a vector indexed by
/// it). When the system refuses to start a thread, the workers started so far do the work. The
/// first exception stops the hand-out of further indices and is rethrown here once
/// every worker has returned.
void parallelFor(int count, int threads, const std::function<void(int index, int worker)>& work);

}  // namespace artcal
