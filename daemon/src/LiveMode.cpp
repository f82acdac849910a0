#include "LiveMode.hpp"

#include <algorithm>

namespace lipsyncd::daemon {

LiveMode::LiveMode(const DaemonConfig& config, std::shared_ptr<const ClipMaker> clips, double now)
    : clips_(std::move(clips)),
      capture_(openCaptureSource(config.captureDevice, config.captureRate)),
      live_(clips_->startLive(capture_->rate())),
      newest_(clips_->poseNames().size()),
      started_(now) {}

std::span<const float> LiveMode::tick() {
    const auto n = capture_->read(buffer_);
    live_->push(std::span<const float>(buffer_).first(n), frames_);
    if (frames_.frames() == 0) return {};
    const auto last = frames_.frame(frames_.frames() - 1);
    newest_.assign(last.begin(), last.end());  // no allocation after the first
    frames_.times.clear();                     // keep memory flat: only the newest frame matters
    frames_.values.clear();
    return newest_;
}

}  // namespace lipsyncd::daemon
