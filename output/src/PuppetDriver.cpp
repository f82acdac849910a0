// All actuators of a puppet, stepped by the caller's clock (the file's timeline in `drive`,
// the audio device's sample clock in the daemon), with rest on stop and on stalled input.
#include <algorithm>
#include <lipsyncd/output.hpp>

namespace lipsyncd::output {

PuppetDriver::PuppetDriver(const Puppet& puppet, std::span<const std::string> poses)
    : puppet_(&puppet) {
    puppet.checkPoses(poses);
    for (const auto& a : puppet.actuators) {
        std::vector<std::size_t> index;
        for (const auto& [pose, gain] : a.gains)
            index.push_back(static_cast<std::size_t>(std::find(poses.begin(), poses.end(), pose) -
                                                     poses.begin()));
        channels_.emplace_back(a, std::move(index));
    }
    last_.resize(channels_.size());
    lastWeights_.assign(poses.size(), 0.0f);
}

void PuppetDriver::addSink(std::unique_ptr<CommandSink> sink) {
    sinks_.push_back(sink.get());
    owned_.push_back(std::move(sink));
}

void PuppetDriver::addSink(CommandSink& sink) {
    sinks_.push_back(&sink);
}

void PuppetDriver::send(double time) {
    for (auto* s : sinks_) s->write(time, last_);
}

void PuppetDriver::update(double time, std::span<const float> weights) {
    lastInput_ = time;
    resting_ = false;
    std::copy_n(weights.begin(), std::min(weights.size(), lastWeights_.size()),
                lastWeights_.begin());
    for (std::size_t i = 0; i < channels_.size(); ++i) last_[i] = channels_[i].step(time, weights);
    send(time);
}

void PuppetDriver::tick(double time) {
    if (!resting_ && time - lastInput_ > puppet_->stallTimeout) resting_ = true;
    for (std::size_t i = 0; i < channels_.size(); ++i)
        last_[i] = resting_ ? channels_[i].stepToRest(time) : channels_[i].step(time, lastWeights_);
    send(time);
}

double PuppetDriver::rest(double time, double stepHz,
                          const std::function<void(double)>& sleepUntilTime) {
    resting_ = true;
    const double dt = 1.0 / stepHz;
    for (int guard = 0; guard < 1'000'000; ++guard) {
        for (std::size_t i = 0; i < channels_.size(); ++i) last_[i] = channels_[i].stepToRest(time);
        send(time);
        if (atRest()) break;
        time += dt;
        if (sleepUntilTime) sleepUntilTime(time);
    }
    return time;
}

bool PuppetDriver::atRest() const {
    return std::all_of(channels_.begin(), channels_.end(),
                       [](const ActuatorChannel& c) { return c.atRest(); });
}

}  // namespace lipsyncd::output
