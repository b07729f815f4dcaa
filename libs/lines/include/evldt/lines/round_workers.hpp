#pragma once
// Threads a tracking or detection round is split over. The method says how a round shares its work
// out; the runtime owns the threads (evldt/pipeline/worker_pool.hpp). A round without workers runs on
// the calling thread.

namespace evldt {

class RoundWorkers {
 public:
  virtual ~RoundWorkers() = default;

  /// Workers in all, the caller's thread among them (>= 1).
  [[nodiscard]] virtual int threads() const = 0;

  /// Calls task(0) on the calling thread, and task(worker) on each other worker that wakes before
  /// that call returns; returns when every call has. So the task must share its work out as it goes
  /// (workers claim parts from a counter), never by worker: a worker that wakes late, and a round too
  /// small to wait for it, do not hold the caller up. The task must not throw. Callers on several
  /// threads take turns. Allocation-free: the task is passed by reference.
  template <typename Task>
  void run(Task& task) {
    run_erased([](void* context, int worker) { (*static_cast<Task*>(context))(worker); }, &task);
  }

 protected:
  using Erased = void (*)(void*, int);

 private:
  virtual void run_erased(Erased function, void* context) = 0;
};

}  // namespace evldt
