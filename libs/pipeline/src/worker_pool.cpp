#include "evldt/pipeline/worker_pool.hpp"

#include <algorithm>
#include <stdexcept>

#include "evldt/pipeline/thread_name.hpp"

namespace evldt {

WorkerPool::WorkerPool(int threads) {
  if (threads < 1) throw std::invalid_argument("a worker pool needs at least one thread");
  threads_.reserve(static_cast<std::size_t>(threads - 1));
  for (int worker = 1; worker < threads; ++worker) threads_.emplace_back([this, worker] { work(worker); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  start_.notify_all();
  for (std::thread& thread : threads_) thread.join();
}

void WorkerPool::run_erased(Erased function, void* context) {
  if (threads_.empty()) {
    function(context, 0);
    return;
  }
  std::lock_guard turn(turn_);
  {
    std::lock_guard lock(mutex_);
    function_ = function;
    context_ = context;
    open_ = true;
    ++generation_;
  }
  start_.notify_all();
  function(context, 0);
  std::unique_lock lock(mutex_);
  open_ = false;
  done_.wait(lock, [this] { return running_ == 0; });
}

void WorkerPool::work(int worker) {
  run_this_thread_as_round();  // a pool started by the storing thread would share its priority
  std::uint64_t seen = 0;
  for (;;) {
    Erased function = nullptr;
    void* context = nullptr;
    {
      std::unique_lock lock(mutex_);
      start_.wait(lock, [&] { return stopping_ || (open_ && generation_ != seen); });
      if (stopping_) return;
      seen = generation_;
      function = function_;
      context = context_;
      ++running_;
    }
    function(context, worker);
    bool last = false;
    {
      std::lock_guard lock(mutex_);
      last = --running_ == 0;
    }
    if (last) done_.notify_one();
  }
}

int default_worker_threads() {
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::max(1, cores - 1);
}

}  // namespace evldt
