// One actuator's pipeline. Safety first (the developers' guide): whatever comes in, NaN
// included, the command stays within [min, max] and moves no faster than the slew limit; a
// non-finite input holds the last good target. Servos at rest relax after an idle time (no
// pulses, no buzzing) until the mouth moves again.
#include <algorithm>
#include <cmath>
#include <lipsyncd/output.hpp>

namespace lipsyncd::output {

SwitchLogic::SwitchLogic(const ActuatorConfig& c)
    : onAbove_(c.threshold + c.hysteresis / 2),
      offBelow_(c.threshold - c.hysteresis / 2),
      minOn_(c.minOnSeconds),
      minOff_(c.minOffSeconds) {}

bool SwitchLogic::update(double time, double value) {
    // A valve must not chatter: a change needs the hysteresis crossed and the minimum time in
    // the current state served.
    const double held = time - since_;
    if (!on_ && value > onAbove_ && held >= minOff_) {
        on_ = true;
        since_ = time;
    } else if (on_ && value < offBelow_ && held >= minOn_) {
        on_ = false;
        since_ = time;
    }
    return on_;
}

ActuatorChannel::ActuatorChannel(const ActuatorConfig& config, std::vector<std::size_t> poseIndex)
    : config_(config),
      poseIndex_(std::move(poseIndex)),
      value_(config.rest),
      lastTarget_(config.rest) {
    if (config_.backend == Backend::Switch) switch_.emplace(config_);
}

ActuatorCommand ActuatorChannel::step(double time, std::span<const float> weights) {
    double target = config_.neutral + config_.trim;
    bool finite = true;
    for (std::size_t k = 0; k < poseIndex_.size(); ++k) {
        const float w = poseIndex_[k] < weights.size() ? weights[poseIndex_[k]] : NAN;
        finite = finite && std::isfinite(w);
        target += config_.gains[k].second * static_cast<double>(w);
    }
    if (config_.invert) target = config_.min + config_.max - target;
    // Non-finite weights (or a sum that overflowed) hold the last good target.
    if (!finite || !std::isfinite(target)) target = lastTarget_;
    lastTarget_ = target;
    return moveToward(time, target);
}

ActuatorCommand ActuatorChannel::stepToRest(double time) {
    return moveToward(time, config_.rest);
}

bool ActuatorChannel::atRest() const {
    return std::abs(value_ - config_.rest) < 1e-9;
}

ActuatorCommand ActuatorChannel::moveToward(double time, double target) {
    target = std::clamp(target, config_.min, config_.max);
    const double dt = lastTime_ < 0 ? 0 : std::max(0.0, time - lastTime_);
    lastTime_ = time;
    const double step = config_.slew * dt;
    if (std::abs(target - value_) >= config_.deadband || target == config_.rest)
        value_ += std::clamp(target - value_, -step, step);
    value_ = std::clamp(value_, config_.min, config_.max);  // (a no-op, kept as the last word)

    ActuatorCommand c;
    c.value = value_;
    if (!atRest()) restingSince_ = time;
    c.active = !(config_.idleAfter > 0 && atRest() && time - restingSince_ >= config_.idleAfter);
    if (switch_) c.on = switch_->update(time, value_);
    return c;
}

}  // namespace lipsyncd::output
