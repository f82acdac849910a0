// One clock read per tick: the audio position decides both the mouth's frame and whether the
// clip has ended, so the two can never disagree within a tick.
#include "Player.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lipsyncd::daemon {

void Player::start(Clip clip, AudioSink& audio) {
    clip_ = std::move(clip);
    audio.open(clip_->rate);
    written_ = 0;
    base_ = audio.played();
    clock_ = {};
    frame_.assign(clip_->weights.poses.size(), 0.0f);
}

// The device takes floats: 16-bit samples are converted a block at a time into a fixed
// buffer (no allocation in the tick), until the device takes less than it is offered.
void Player::write(AudioSink& audio) {
    const auto& s = clip_->samples;
    while (written_ < s.size()) {
        const auto n = std::min(block_.size(), s.size() - written_);
        for (std::size_t i = 0; i < n; ++i)
            block_[i] = static_cast<float>(s[written_ + i]) / 32768.0f;
        const auto taken = audio.write(std::span<const float>(block_).first(n));
        written_ += taken;
        if (taken < n) return;
    }
}

std::span<const float> Player::tick(AudioSink& audio, double leadSeconds, double outputRateHz) {
    if (!clip_) return {};
    write(audio);
    const auto heardSamples = audio.played() - base_;  // the one clock read of this tick
    const double rate = clip_->rate;
    clock_ = {static_cast<double>(heardSamples) / rate,
              static_cast<double>(static_cast<std::int64_t>(written_) - heardSamples) / rate};
    const auto& w = clip_->weights;
    if (w.frames() == 0) return {};
    const double at = std::round((clock_.heard + leadSeconds) * outputRateHz);
    const auto f =
        static_cast<std::size_t>(std::clamp(at, 0.0, static_cast<double>(w.frames() - 1)));
    const auto src = w.frame(f);
    std::copy(src.begin(), src.end(), frame_.begin());
    return frame_;
}

bool Player::finished() const {
    return clip_ && written_ >= clip_->samples.size() &&
           clock_.heard >= static_cast<double>(clip_->samples.size()) / clip_->rate;
}

void Player::stop(AudioSink& audio) {
    if (clip_) audio.stop();
    clip_.reset();
}

void Player::moveTo(AudioSink& audio) {
    if (!clip_) return;
    written_ = std::min(clip_->samples.size(),
                        static_cast<std::size_t>(std::max(0.0, clock_.heard) * clip_->rate));
    audio.open(clip_->rate);
    base_ = audio.played() - static_cast<std::int64_t>(written_);
}

std::optional<Clip> Player::take() {
    return std::exchange(clip_, std::nullopt);
}

}  // namespace lipsyncd::daemon
