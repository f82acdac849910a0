// Live: capture → streaming front end → causal runtime → the mouth, with the least delay.
#pragma once

#include <lipsyncd/daemon.hpp>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace lipsyncd::daemon {

class LiveMode {
  public:
    // Opens the capture device; InputError naming it when it cannot.
    LiveMode(const DaemonConfig& config, std::shared_ptr<const ClipMaker> clips, double now);
    // What arrived since the last tick; the newest final weights frame, or an empty span when
    // none came (the mouth takes the newest: the slew limit smooths).
    std::span<const float> tick();
    double started() const { return started_; }
    double frontEndLatency() const { return live_->latencySeconds(); }

  private:
    std::shared_ptr<const ClipMaker> clips_;  // what live_ was made from lives as long as it
    std::unique_ptr<CaptureSource> capture_;
    std::unique_ptr<ClipMaker::Live> live_;
    PoseTrack frames_;
    std::vector<float> buffer_ = std::vector<float>(96000);
    std::vector<float> newest_;
    double started_;
};

}  // namespace lipsyncd::daemon
