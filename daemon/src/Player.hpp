// The clip that plays: it feeds the audio device, reads the device's clock once per tick
// (position heard, delay still queued, rate; as PipeWire hands every cycle its clock) and
// picks the pose-weight frame the mouth shows at that clock plus the puppet's lead.
#pragma once

#include <array>
#include <cstdint>
#include <lipsyncd/daemon.hpp>
#include <optional>
#include <span>
#include <vector>

namespace lipsyncd::daemon {

// The audio clock as read once in a tick.
struct AudioClock {
    double heard = 0;  // seconds of the clip that have reached the speaker
    double delay = 0;  // seconds handed to the device and not heard yet
};

class Player {
  public:
    void start(Clip clip, AudioSink& audio);
    // Feeds the device and reads its clock. The weights frame for the mouth now, or an empty
    // span when nothing plays; `leadSeconds` drives the mouth that much ahead of the sound.
    std::span<const float> tick(AudioSink& audio, double leadSeconds, double outputRateHz);
    bool finished() const;  // everything written has been heard
    void stop(AudioSink& audio);
    // The device changed (reload): the clip goes on from what was heard, on `audio`.
    void moveTo(AudioSink& audio);
    std::optional<Clip> take();  // the clip (finished, or dropped), leaving nothing playing

    const Clip* clip() const { return clip_ ? &*clip_ : nullptr; }
    const AudioClock& clock() const { return clock_; }       // as of the last tick
    std::span<const float> frame() const { return frame_; }  // the frame last shown

  private:
    void write(AudioSink& audio);

    std::optional<Clip> clip_;
    std::array<float, 2048> block_{};
    std::size_t written_ = 0;  // samples handed to the device
    std::int64_t base_ = 0;    // the device's position when the clip started
    AudioClock clock_;
    std::vector<float> frame_;
};

}  // namespace lipsyncd::daemon
