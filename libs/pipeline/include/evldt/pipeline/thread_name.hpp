#pragma once
// Names the calling thread (up to 15 characters show), so `top -H` and `perf report --sort comm`
// tell a service's threads apart; and sets threads' CPU priorities: the threads that take events in
// above the rounds, and a socket reader above everything.

#include <dirent.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

namespace evldt {

inline void name_this_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

/// How much higher than the rounds and the publisher the threads that take events in run, in nice
/// steps (evldt-camera's reading and publishing; evldt-lines' receiving and storing): when the
/// cores are short they get them first (a late batch is shed; a late round only covers more event
/// time; a camera that falls behind catches up in a burst that overflows its subscribers' socket
/// buffers). 10 steps give such a thread about nine tenths of a core it shares with a round.
constexpr int kIngestPriorityBoost = 10;

/// The nice value the process started with (the first call reads the calling thread's: make it
/// before any thread changes its own).
inline int process_nice() {
  static const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  return nice;
}

/// Raises the calling thread above the process's nice value by kIngestPriorityBoost (Linux: nice
/// is per thread, and threads it starts inherit it). Needs CAP_SYS_NICE (root) or an RLIMIT_NICE
/// that allows it; false where it was not allowed (the thread then keeps its priority).
inline bool raise_this_thread_for_ingest() {
  const int base = process_nice();
  return setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), base - kIngestPriorityBoost) == 0;
}

/// The ids of the process's threads now (from /proc/self/task; empty where there is no /proc).
inline std::vector<pid_t> process_thread_ids() {
  std::vector<pid_t> ids;
  DIR* const tasks = opendir("/proc/self/task");
  if (tasks == nullptr) return ids;
  while (const dirent* entry = readdir(tasks)) {
    if (entry->d_name[0] != '.') ids.push_back(static_cast<pid_t>(std::atoll(entry->d_name)));
  }
  closedir(tasks);
  return ids;
}

/// Makes thread `tid` of this process real-time (SCHED_FIFO at the lowest priority): it runs as
/// soon as it wakes, before every normal thread. For a thread that only moves datagrams from a
/// socket into memory, whose work is bounded by what arrives: left to the fair scheduler among busy
/// threads it fell behind by more than the socket buffer holds. Needs CAP_SYS_NICE (root) or an
/// RLIMIT_RTPRIO of 1; false where it was not allowed.
inline bool run_thread_realtime(pid_t tid) {
  const sched_param lowest{.sched_priority = sched_get_priority_min(SCHED_FIFO)};
  return sched_setscheduler(tid, SCHED_FIFO, &lowest) == 0;
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
