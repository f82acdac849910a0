#include "PuppetJaw.hpp"

#include <algorithm>
#include <cmath>

namespace lipsyncd::cli {

namespace {
// Keeps one actuator's commanded values with their times.
class JawRecorder : public output::CommandSink {
  public:
    explicit JawRecorder(std::size_t actuator) : actuator_(actuator) {}
    void write(double time, std::span<const output::ActuatorCommand> commands) override {
        times.push_back(time);
        values.push_back(commands[actuator_].value);
    }
    std::vector<double> times, values;

  private:
    std::size_t actuator_;
};
}  // namespace

PuppetJaw::PuppetJaw(output::Puppet puppet, const std::string& actuator)
    : puppet_(std::move(puppet)) {
    const auto& a = puppet_.actuators;
    const std::string wanted = actuator.empty() ? "jaw" : actuator;
    const auto it =
        std::find_if(a.begin(), a.end(), [&](const auto& c) { return c.name == wanted; });
    if (it == a.end() && !actuator.empty())
        throw InputError(puppet_.source.string() + ": no actuator named '" + actuator + "'");
    if (a.empty()) throw InputError(puppet_.source.string() + ": no actuators");
    actuator_ = it == a.end() ? 0 : static_cast<std::size_t>(it - a.begin());
}

std::vector<float> PuppetJaw::record(const PoseTrack& track, double rate,
                                     std::size_t frames) const {
    output::PuppetDriver driver(puppet_, track.poses);
    JawRecorder recorder(actuator_);
    driver.addSink(recorder);
    double t = 0;
    for (std::size_t f = 0; f < track.frames(); ++f)
        driver.update(t = track.times[f], track.frame(f));
    driver.rest(t);
    const auto& c = puppet_.actuators[actuator_];
    std::vector<float> jaw(frames, 0.0f);
    std::size_t k = 0;
    double value = c.rest;
    for (std::size_t f = 0; f < frames; ++f) {
        const double at = static_cast<double>(f) / rate + 1e-9;
        while (k < recorder.times.size() && recorder.times[k] <= at) value = recorder.values[k++];
        const double opening = c.invert ? c.min + c.max - value : value;
        jaw[f] = static_cast<float>(std::clamp((opening - c.min) / (c.max - c.min), 0.0, 1.0));
    }
    return jaw;
}

}  // namespace lipsyncd::cli
