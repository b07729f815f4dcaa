#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "evldt/pipeline/worker_pool.hpp"

namespace evldt {
namespace {

// What every round of the tracker and detector does: workers claim parts from a counter.
struct ClaimedParts {
  explicit ClaimedParts(std::size_t parts) : done(parts) {}
  std::atomic<std::size_t> next{0};
  std::vector<std::atomic<int>> done;
  std::atomic<int> calls_off_the_caller{0};
  std::thread::id caller = std::this_thread::get_id();
  void operator()(int worker) {
    if (std::this_thread::get_id() != caller) {
      EXPECT_NE(worker, 0);
      ++calls_off_the_caller;
    } else {
      EXPECT_EQ(worker, 0);
    }
    for (std::size_t part = next++; part < done.size(); part = next++) {
      ++done[part];
      std::this_thread::yield();  // gives the other workers time to wake and claim parts too
    }
  }
};

TEST(WorkerPool, EveryPartIsDoneOnceInEveryRun) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.threads(), 3);
  int helped = 0;
  for (int run = 0; run < 200; ++run) {
    ClaimedParts task(500);
    pool.run(task);
    for (const auto& count : task.done) ASSERT_EQ(count.load(), 1) << "run " << run;
    helped += task.calls_off_the_caller > 0;
  }
  EXPECT_GT(helped, 0);  // the other threads do take part
}

TEST(WorkerPool, OneThreadRunsOnTheCaller) {
  WorkerPool pool(1);
  ClaimedParts task(10);
  pool.run(task);
  EXPECT_EQ(task.calls_off_the_caller.load(), 0);
  for (const auto& count : task.done) EXPECT_EQ(count.load(), 1);
  EXPECT_THROW(WorkerPool(0), std::invalid_argument);
}

TEST(WorkerPool, CallersOnTwoThreadsTakeTurns) {
  // The real-time engine's detection and tracking loops share one pool.
  WorkerPool pool(2);
  std::atomic<int> inside{0}, overlaps{0};
  auto caller = [&] {
    for (int run = 0; run < 300; ++run) {
      ClaimedParts task(50);
      task.caller = std::this_thread::get_id();
      auto guarded = [&](int worker) {
        if (worker == 0 && inside++ != 0) ++overlaps;
        task(worker);
        if (worker == 0) --inside;
      };
      pool.run(guarded);
      for (const auto& count : task.done) ASSERT_EQ(count.load(), 1);
    }
  };
  std::thread a(caller), b(caller);
  a.join();
  b.join();
  EXPECT_EQ(overlaps.load(), 0);
}

}  // namespace
}  // namespace evldt
