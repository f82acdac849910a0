// Whether the 10 ms loop keeps up. Each tick's CPU time on the loop's thread, the CPU time of
// the loop's busiest turn (a tick and the requests, signals and reports served after it), and
// the timer periods the loop missed because it came back late. CPU time, not wall time: on a
// busy machine the loop waits for a core, which it cannot help; what it spends is what a
// slower board would feel. `status` reports it ("loop"), and the log warns, at most once a
// minute, while periods are being missed: the mouth then lags its sound.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace lipsyncd::daemon {

// CPU time of the calling thread, seconds.
double threadCpuSeconds();

class LoopHealth {
  public:
    // One tick: its CPU time, and the periods missed before it (the timer's expirations
    // beyond one).
    void tick(double cpuSeconds, std::uint64_t missedPeriods);
    // One turn of the loop: a tick (if one was due) and all that was served after it.
    void turn(double cpuSeconds);
    nlohmann::json reply() const;
    // A warning for the log when periods were missed since the last one, at most once every
    // `every` seconds (`now`: the daemon's clock); nothing when the loop kept up.
    std::optional<std::string> warning(double now, double every = 60);

  private:
    std::uint64_t ticks_ = 0, missed_ = 0;
    double tickCpuSum_ = 0, tickCpuMax_ = 0, turnCpuMax_ = 0;
    // Since the last warning.
    std::uint64_t missedSinceWarning_ = 0;
    double turnCpuMaxSinceWarning_ = 0, lastWarning_ = -1e300;
};

}  // namespace lipsyncd::daemon
