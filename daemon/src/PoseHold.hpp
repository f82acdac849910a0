// A pose a client asked for (`pose`), held for a short while: the editor streams its preview
// a frame at a time, and a stream that stops (a paused page, a client gone) must not hold the
// mouth open. After the hold the puppet's own stall rule rests it, as when a clip's input
// stalls.
#pragma once

#include <span>
#include <vector>

namespace lipsyncd::daemon {

class PoseHold {
  public:
    static constexpr double kHoldSeconds = 0.25;

    // `weights` in the clip maker's pose order, held until `now` + kHoldSeconds.
    void hold(std::span<const float> weights, double now) {
        weights_.assign(weights.begin(), weights.end());  // reuses its memory after the first
        until_ = now + kHoldSeconds;
    }
    void release() { until_ = -1; }
    // The held weights at `now`, or empty when none are held (the tick: no allocation).
    std::span<const float> at(double now) const {
        return now < until_ ? std::span<const float>(weights_) : std::span<const float>();
    }

  private:
    std::vector<float> weights_;
    double until_ = -1;
};

}  // namespace lipsyncd::daemon
