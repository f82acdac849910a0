// What the benchmark programs read about themselves: the CPU time of the calling thread, and
// the resident memory of the process (/proc/self/statm).
#pragma once

#include <time.h>
#include <unistd.h>

#include <fstream>

namespace lipsyncd::bench {

inline double threadCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

inline long residentKiB() {
    std::ifstream statm("/proc/self/statm");
    long pages = 0, resident = 0;
    statm >> pages >> resident;
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace lipsyncd::bench
