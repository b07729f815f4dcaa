#pragma once
// Names the calling thread (up to 15 characters show), so `top -H` and `perf report --sort comm`
// tell a service's threads apart.

#include <pthread.h>

namespace evldt {

inline void name_this_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

}  // namespace evldt
