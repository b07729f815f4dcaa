#pragma once
// Names the calling thread (up to 15 characters show), so `top -H` and `perf report --sort comm`
// tell a service's threads apart; and lowers a thread's CPU priority below storage's.

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

namespace evldt {

inline void name_this_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

/// Nice value of the rounds and the publisher: when the cores are short, the thread that receives
/// and stores events gets them first (a late batch is shed; a late round only covers more event
/// time). 10 gives a nice-0 thread about nine tenths of a core it shares with one of these.
constexpr int kBelowStorageNice = 10;

/// Lowers the calling thread's priority (Linux: nice is per thread). Never fails loudly: a higher
/// nice value is always allowed, and without it the service only loses the preference.
inline void run_this_thread_below_storage() { setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kBelowStorageNice); }

}  // namespace evldt
