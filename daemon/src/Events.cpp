// What subscribers and `status` see. A frame event carries the weights the mouth was given in
// the same tick as the actuator commands sent with them (never a second clock read).
#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

json Daemon::Impl::frameEvent(double t) const {
    json weights = json::object(), actuators = json::object();
    const auto commands = setup->driver->last();
    for (std::size_t i = 0; i < commands.size(); ++i)
        actuators[setup->puppet->actuators[i].name] = commands[i].value;
    if (const auto* clip = player.clip()) {
        const auto frame = player.frame();
        for (std::size_t p = 0; p < clip->weights.poses.size() && p < frame.size(); ++p)
            weights[clip->weights.poses[p]] = frame[p];
    }
    json event = {{"event", "frame"}, {"time", t}, {"weights", weights}, {"actuators", actuators}};
    if (player.clip()) event["position"] = player.clock().heard;
    return event;
}

json Daemon::Impl::statusReply() const {
    const auto* clip = player.clip();
    const auto& config = setup->config;
    // End to end: a clip's sample handed to the device until it is heard (the mouth is driven
    // `lead` ahead of it, so the servo arrives with it); live, a sound at the microphone until
    // the mouth has moved: the front end's bound, a tick, and the servo's lag.
    const double lead = setup->puppet->leadSeconds;
    const double tickSeconds = 0.01;
    json latency = {
        {"audio_delay", player.clock().delay},
        {"lead", lead},
        {"sync_offset", config.syncOffsetSeconds},
        {"end_to_end", live ? live->frontEndLatency() + tickSeconds + lead : player.clock().delay}};
    return {{"ok", true},
            {"playing", clip ? json(clip->name) : json(nullptr)},
            {"position", player.clock().heard},
            {"queue", queue.names()},
            {"played", clipsPlayed},
            {"puppet", setup->puppet->name},
            {"at_rest", setup->driver->atRest()},
            {"live", live.has_value()},
            {"live_started", live ? live->started() : -1.0},
            {"latency", latency}};
}

}  // namespace lipsyncd::daemon
