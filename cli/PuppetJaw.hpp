// A puppet's jaw as an audience sees it: pose weights driven through the puppet's actuator
// stage (mapping, limits, slew, deadband, rest at the end: the safety layer counts), recorded
// and read back as the jaw's opening, 0 closed to 1 fully open, one value per frame.
#pragma once

#include <lipsyncd/core.hpp>
#include <lipsyncd/output.hpp>
#include <string>
#include <vector>

namespace lipsyncd::cli {

class PuppetJaw {
  public:
    // `actuator`: the jaw's actuator name; empty: the one named "jaw", else the first.
    PuppetJaw(output::Puppet puppet, const std::string& actuator);
    // Plays `track` (as `lipsync drive` does: then rest) and samples the jaw every 1 / rate s.
    std::vector<float> record(const PoseTrack& track, double rate, std::size_t frames) const;
    const output::Puppet& puppet() const { return puppet_; }
    const std::string& actuatorName() const { return puppet_.actuators[actuator_].name; }

  private:
    output::Puppet puppet_;
    std::size_t actuator_ = 0;
};

}  // namespace lipsyncd::cli
