// The control commands. Every request has been checked against the command table before it
// gets here (types, limits); what is left is what only the daemon can know: files, the queue.
#include <lipsyncd/tts.hpp>

#include "DaemonCore.hpp"
#include "ShowSpeaker.hpp"

namespace lipsyncd::daemon {

using nlohmann::json;

json Daemon::Impl::handle(const json& r) {
    if (const auto bad = checkControlRequest(r)) return {{"ok", false}, {"error", *bad}};
    const auto& cmd = r["cmd"].get_ref<const std::string&>();
    try {
        if (cmd == "play") return play(r);
        if (cmd == "say") return say(r);
        if (cmd == "stop") return stop();
        if (cmd == "status" || cmd == "queue") return statusReply();
        if (cmd == "reload") {
            reload();
            return {{"ok", true}, {"config", configFile.string()}};
        }
        if (cmd == "live") return setLive(r.value("on", true));
        if (cmd == "line") return line(r);
        if (cmd == "script") return loadScript(r);
        if (cmd == "pose") return holdPose(r);
        if (cmd == "speaker") return speaker(r.value("action", std::string("show")));
        return {{"ok", false}, {"error", cmd + ": only on a connection (subscribe)"}};
    } catch (const std::exception& e) {
        return {{"ok", false}, {"error", e.what()}};
    }
}

namespace {
json queueFull(std::size_t capacity) {
    return {{"ok", false},
            {"error", "queue full (" + std::to_string(capacity) +
                          " waiting; max_queue in the config): try again after one has played"}};
}
}  // namespace

json Daemon::Impl::play(const json& r) {
    ClipRequest request;
    request.file = r["file"].get<std::string>();
    request.channel = r.value("channel", -1);
    if (r.contains("text")) {
        request.knownText = r["text"].get<std::string>();
        checkText(*request.knownText, setup->config.maxTextBytes, "play");
    }
    request.name = request.file.string();
    request.maxSeconds = setup->config.maxClipSeconds;
    request.maker = setup->clips;
    const double seconds = checkAudioFile(request.file, request.maxSeconds);
    if (!queue.push(std::move(request))) return queueFull(queue.capacity());
    return {{"ok", true}, {"queued", r["file"]}, {"duration", seconds}};
}

json Daemon::Impl::say(const json& r) {
    ClipRequest request;
    request.text = r["text"].get<std::string>();
    checkText(request.text, setup->config.maxTextBytes, "say");
    request.voice = r.value("voice", setup->config.voice);
    request.name = "say: " + request.text;
    request.maxSeconds = setup->config.maxClipSeconds;
    request.maker = setup->clips;
    if (!queue.push(std::move(request))) return queueFull(queue.capacity());
    return {{"ok", true}, {"queued", "say: " + r["text"].get<std::string>()}};
}

json Daemon::Impl::stop() {
    queue.clear();
    player.stop(*setup->audio);
    heldPose.release();
    status("stopped; idle");
    return {{"ok", true}};
}

json Daemon::Impl::setLive(bool on) {
    if (!on) {
        const auto learning = live ? learnLine(live->endLine()) : json(nullptr);
        live.reset();
        status("live off");
        return {{"ok", true}, {"live", false}, {"learning", learning}};
    }
    if (!live) {
        live.emplace(setup->config, setup->clips, now());
        status("live from " + setup->config.captureDevice);
    }
    return {{"ok", true},
            {"live", true},
            {"started", live->started()},
            {"front_end_latency", live->frontEndLatency()}};
}

json Daemon::Impl::speakerReply() const {
    const auto* voice = setup->clips->speaker();
    if (!voice) return {{"adapting", false}};
    const auto heard = voice->heard();
    return {{"adapting", true},
            {"lines", heard.lines},
            {"frames", heard.frames},
            {"networks_trained", heard.networks}};
}

json Daemon::Impl::speaker(const std::string& action) {
    if (action != "show" && action != "reset")
        return {{"ok", false},
                {"error", "speaker: \"action\" must be show or reset, not '" + action + "'"}};
    auto* voice = setup->clips->speaker();
    if (!voice) return {{"ok", false}, {"error", "speaker: adapt_speaker is off in the config"}};
    if (action == "reset") {
        voice->reset();
        status("the show's voice forgotten");
    }
    json reply = {{"ok", true}};
    reply["speaker"] = speakerReply();
    return reply;
}

}  // namespace lipsyncd::daemon
