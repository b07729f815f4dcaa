#pragma once
// Names the calling thread (up to 15 characters show), so `top -H` and `perf report --sort comm`
// tell a service's threads apart; and sets a thread's CPU priority, storage's above the rounds'.

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

namespace evldt {

inline void name_this_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

/// How much higher than the rounds and the publisher the thread that receives and stores events
/// runs, in nice steps: when the cores are short it gets them first (a late batch is shed; a late
/// round only covers more event time). 10 steps give it about nine tenths of a core it shares with
/// one of them.
constexpr int kStoragePriorityBoost = 10;

/// The nice value the process started with (the first call reads the calling thread's: make it
/// before any thread changes its own).
inline int process_nice() {
  static const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  return nice;
}

/// Raises the calling thread above the process's nice value by kStoragePriorityBoost (Linux: nice
/// is per thread, and threads it starts inherit it). Needs CAP_SYS_NICE (root) or an RLIMIT_NICE
/// that allows it; false where it was not allowed (the thread then keeps its priority).
inline bool raise_this_thread_above_rounds() {
  const int base = process_nice();
  return setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), base - kStoragePriorityBoost) == 0;
}

/// Puts the calling thread back at the process's nice value (the rounds, the publisher and the
/// round workers, which a raised thread starts, do not inherit its priority) and marks it as batch
/// work (SCHED_BATCH): waking, it never preempts a running thread. As a normal thread, a round that
/// woke after a sleep could take the storing thread's core for a few milliseconds (the sleeper's
/// credit of the fair scheduler) whatever their nice values; storage then fell behind by that much
/// at every wake-up. Both calls are always allowed.
inline void run_this_thread_as_round() {
  const sched_param batch{};
  sched_setscheduler(0, SCHED_BATCH, &batch);
  setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), process_nice());
}

}  // namespace evldt
