#pragma once
// A fixed set of threads that run one task together: tracking and detection rounds split their work
// over it. The caller's thread is worker 0, so a pool of one thread starts none and runs inline.

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace evldt {

class WorkerPool {
 public:
  /// `threads` >= 1 workers in all, the caller's thread among them.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  [[nodiscard]] int threads() const { return static_cast<int>(threads_.size()) + 1; }

  /// Calls task(0) on the calling thread, and task(worker) on each other worker that wakes before
  /// that call returns; returns when every call has. So the task must share its work out as it goes
  /// (workers claim parts from a counter), never by worker: a worker that wakes late, and a round too
  /// small to wait for it, do not hold the caller up. The task must not throw. Callers on several
  /// threads take turns. Allocation-free: the task is passed by reference.
  template <typename Task>
  void run(Task& task) {
    run_erased([](void* context, int worker) { (*static_cast<Task*>(context))(worker); }, &task);
  }

 private:
  using Erased = void (*)(void*, int);
  void run_erased(Erased function, void* context);
  void work(int worker);

  std::mutex turn_;  // one run() at a time
  std::mutex mutex_;
  std::condition_variable start_, done_;
  Erased function_ = nullptr;   // guarded by mutex_
  void* context_ = nullptr;     // guarded by mutex_
  std::uint64_t generation_ = 0;  // guarded by mutex_: bumped by every run()
  bool open_ = false;           // guarded by mutex_: workers may still join this run
  int running_ = 0;             // guarded by mutex_: workers in this run's task
  bool stopping_ = false;       // guarded by mutex_
  std::vector<std::thread> threads_;
};

/// The default worker count: the machine's cores, less one for the thread that receives and stores
/// events, and at least one.
int default_worker_threads();

}  // namespace evldt
