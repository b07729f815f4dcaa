#pragma once
// A fixed set of threads that run one task together: the workers tracking and detection rounds split
// their work over. The caller's thread is worker 0, so a pool of one thread starts none and runs inline.

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "evldt/lines/round_workers.hpp"

namespace evldt {

class WorkerPool final : public RoundWorkers {
 public:
  /// `threads` >= 1 workers in all, the caller's thread among them.
  explicit WorkerPool(int threads);
  ~WorkerPool() override;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  [[nodiscard]] int threads() const override { return static_cast<int>(threads_.size()) + 1; }

 private:
  void run_erased(Erased function, void* context) override;
  void work(int worker);

  std::mutex turn_;  // one run() at a time
  std::mutex mutex_;
  std::condition_variable start_, done_;
  Erased function_ = nullptr;     // guarded by mutex_
  void* context_ = nullptr;       // guarded by mutex_
  std::uint64_t generation_ = 0;  // guarded by mutex_: bumped by every run()
  bool open_ = false;             // guarded by mutex_: workers may still join this run
  int running_ = 0;               // guarded by mutex_: workers in this run's task
  bool stopping_ = false;         // guarded by mutex_
  std::vector<std::thread> threads_;
};

/// The default worker count: the machine's cores, less one for the thread that receives and stores
/// events, and at least one.
int default_worker_threads();

}  // namespace evldt
