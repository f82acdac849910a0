// Whether the 10 ms loop keeps up: see LoopHealth.hpp.
#include "LoopHealth.hpp"

#include <time.h>

#include <algorithm>
#include <cstdio>

namespace lipsyncd::daemon {

double threadCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void LoopHealth::tick(double cpuSeconds, std::uint64_t missedPeriods) {
    ++ticks_;
    missed_ += missedPeriods;
    missedSinceWarning_ += missedPeriods;
    tickCpuSum_ += cpuSeconds;
    tickCpuMax_ = std::max(tickCpuMax_, cpuSeconds);
}

void LoopHealth::turn(double cpuSeconds) {
    turnCpuMax_ = std::max(turnCpuMax_, cpuSeconds);
    turnCpuMaxSinceWarning_ = std::max(turnCpuMaxSinceWarning_, cpuSeconds);
}

nlohmann::json LoopHealth::reply() const {
    const double mean = ticks_ ? tickCpuSum_ / static_cast<double>(ticks_) : 0;
    return {{"ticks", ticks_},
            {"missed", missed_},
            {"tick_cpu_ms_mean", 1e3 * mean},
            {"tick_cpu_ms_max", 1e3 * tickCpuMax_},
            {"busiest_cpu_ms", 1e3 * turnCpuMax_}};
}

std::optional<std::string> LoopHealth::warning(double now, double every) {
    if (missedSinceWarning_ == 0 || now - lastWarning_ < every) return std::nullopt;
    char text[200];
    std::snprintf(text, sizeof text,
                  "the loop fell behind: %llu ticks of 10 ms missed (busiest turn %.0f ms of "
                  "CPU); the mouth may lag its sound",
                  static_cast<unsigned long long>(missedSinceWarning_),
                  1e3 * turnCpuMaxSinceWarning_);
    missedSinceWarning_ = 0;
    turnCpuMaxSinceWarning_ = 0;
    lastWarning_ = now;
    return text;
}

}  // namespace lipsyncd::daemon
