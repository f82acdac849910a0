// What subscribers and `status` see. A frame event carries the weights the mouth was given in
// the same tick as the actuator commands sent with them (never a second clock read).
#include "DaemonCore.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

// The weights and the actuator commands of this very tick, and the clock read in it.
std::string_view Daemon::Impl::frameEvent(double t) {
    const auto* clip = player.clip();
    return frameWriter.format(t, clip ? player.frame() : std::span<const float>{},
                              setup->driver->last(),
                              clip ? std::optional(player.clock().heard) : std::nullopt);
}

void Daemon::Impl::setupChanged() {
    std::vector<std::string> actuators;
    for (const auto& a : setup->puppet->actuators) actuators.push_back(a.name);
    frameWriter.setNames(setup->clips->poseNames(), actuators);
}

// The live line being heard: its words and how much of it has been kept.
json Daemon::Impl::lineReply() const {
    const auto* line = live ? live->line() : nullptr;
    if (!line) return nullptr;
    return {{"text", line->text},
            {"seconds", line->seconds()},
            {"full", line->full},
            {"following", live->following()}};
}

json Daemon::Impl::statusReply() const {
    const auto* clip = player.clip();
    const auto* line = live ? live->line() : nullptr;
    const auto& config = setup->config;
    // End to end: a clip's sample handed to the device until it is heard (the mouth is driven
    // `lead` ahead of it, so the servo arrives with it); live, a sound at the microphone until
    // the mouth has moved: the front end's bound, a tick, and the servo's lag. Live sound is
    // heard as it is made, so nothing can be sent ahead of it: the puppet's lead cannot be
    // applied there, it adds to the latency instead ("lead_applied": false).
    const double lead = setup->puppet->leadSeconds;
    const double tickSeconds = 0.01;
    json latency = {
        {"audio_delay", player.clock().delay},
        {"lead", lead},
        {"lead_applied", !live},
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
            {"live_line", lineReply()},
            {"script", scriptReply()},
            {"latency", latency},
            {"loop", loop.reply()},
            {"speaker", speakerReply()},
            // What clips hold: the one playing, and the queue (one made ready ahead at most).
            // (queue_bytes counts the live lines waiting to be learnt too.)
            {"memory",
             {{"playing_bytes", clip ? bytesOf(*clip) : 0},
              {"queue_bytes", queue.bytesHeld()},
              {"live_line_bytes", line ? line->samples.capacity() * sizeof(float) : 0}}}};
}

}  // namespace lipsyncd::daemon
