// The frame event a subscriber gets every 40 ms, written by the real-time tick. Names are
// quoted once when the setup changes; each event is numbers written with std::to_chars into
// a line reserved for the longest event: formatting it never allocates.
#pragma once

#include <lipsyncd/output.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace lipsyncd::daemon {

class FrameEventWriter {
  public:
    // The poses the weights are in and the puppet's actuators, in order (allocates).
    void setNames(std::span<const std::string> poses, std::span<const std::string> actuators);
    // {"event":"frame","time":T,"weights":{POSE:W,...},"actuators":{NAME:V,...}
    //  [,"position":P]}\n. Weights are empty when nothing plays; a value that is not finite
    // is written null (the line stays JSON). Valid until the next call.
    std::string_view format(double time, std::span<const float> weights,
                            std::span<const output::ActuatorCommand> actuators,
                            std::optional<double> position);

  private:
    std::vector<std::string> poseKeys_, actuatorKeys_;  // "\"jaw\":", JSON-escaped
    std::string line_;
};

}  // namespace lipsyncd::daemon
