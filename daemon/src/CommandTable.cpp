// The control protocol's one command table: the daemon validates every request against it,
// `lipsync ctl` builds its requests and usage from it, the tests read their cases from it.
// (MPD keeps its commands the same way: one sorted table with argument counts checked in one
// place.) A refused request names the command and the argument.
#include <algorithm>
#include <cmath>
#include <lipsyncd/daemon.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::daemon {

namespace {
using Type = ControlArg::Type;
// Limits of the protocol itself; the config may set tighter ones (max_text_chars).
constexpr std::size_t kMaxPath = 4096;
constexpr std::size_t kMaxText = 16384;
constexpr std::size_t kMaxScript = 60000;  // within a request line's 64 KiB
constexpr std::size_t kMaxVoice = 64;
constexpr std::size_t kMaxPoses = 64;

constexpr ControlArg kPlayArgs[] = {
    {"file", Type::Path, true, kMaxPath, 0, 0, "the audio file (WAV, FLAC, OGG), a regular file"},
    {"channel", Type::Integer, false, 0, -1, 63, "analyse only this channel (-1: the mix)"},
    {"text", Type::String, false, kMaxText, 0, 0,
     "the words spoken in the file: aligned instead of recognised (default: FILE.txt beside it)"},
};
constexpr ControlArg kSayArgs[] = {
    {"text", Type::String, true, kMaxText, 0, 0, "what to say"},
    {"voice", Type::String, false, kMaxVoice, 0, 0, "an espeak-ng voice"},
};
constexpr ControlArg kPoseArgs[] = {
    {"weights", Type::Weights, true, kMaxPoses, 0, 1,
     "pose weights, NAME=VALUE each within 0..1 (poses not named: 0)"},
};
constexpr ControlArg kSpeakerArgs[] = {
    {"action", Type::String, false, 16, 0, 0, "show (default) or reset (forget the voice)"},
};
constexpr ControlArg kLineArgs[] = {
    {"text", Type::String, false, kMaxText, 0, 0,
     "the words the performer says next, live (none: the line being heard is over)"},
    {"next", Type::Boolean, false, 0, 0, 0, "the script's next line (`script`) instead of text"},
};
constexpr ControlArg kScriptArgs[] = {
    {"text", Type::String, false, kMaxScript, 0, 0,
     "the show's lines, one a line (blank lines left out); none: where the script stands"},
};
constexpr ControlArg kOnArg[] = {
    {"on", Type::Boolean, false, 0, 0, 0, "on or off (default on)"},
};

constexpr ControlCommand kCommands[] = {
    {"line",
     "line [TEXT]: the performer says TEXT live next: the mouth follows its words while it is "
     "said, and once it is over (the next line, `line` alone, live off) they teach the show's "
     "voice",
     "text", kLineArgs},
    {"live", "live on|off: follow the microphone", "on", kOnArg},
    {"play", "play FILE: queue an audio file", "file", kPlayArgs},
    {"pose", "pose NAME=WEIGHT...: hold the mouth in a pose for 0.25 s (not while a clip plays)",
     "weights", kPoseArgs},
    {"queue", "queue: what plays and what waits (as status)", "", {}},
    {"reload", "reload: read the configuration again (as SIGHUP)", "", {}},
    {"say", "say TEXT: queue speech", "text", kSayArgs},
    {"script",
     "script [TEXT]: the show's lines, one a line, for `line --next` (a pedal's cue); none: where "
     "it stands",
     "text", kScriptArgs},
    {"speaker", "speaker [reset]: the show's voice learnt from lines with words, or forget it",
     "action", kSpeakerArgs},
    {"status", "status: what plays, the queue, latency, the mouth", "", {}},
    {"stop", "stop: drop what plays and what waits", "", {}},
    {"subscribe", "subscribe: a frame event per 40 ms on this connection", "on", kOnArg},
};

std::string typeName(Type t) {
    switch (t) {
        case Type::Boolean:
            return "true or false";
        case Type::Integer:
            return "an integer";
        case Type::Weights:
            return "an object of pose weights";
        default:
            return "a string";
    }
}

// {"jaw": 0.4, ...}: JSON has no NaN, but a number too large for a double parses as infinity.
std::optional<std::string> checkWeights(const std::string& where, const ControlArg& a,
                                        const nlohmann::json& v) {
    if (!v.is_object()) return where + "must be an object of pose weights, {\"NAME\": 0.5}";
    if (v.size() > a.maxLength)
        return where + "has more than " + std::to_string(a.maxLength) + " poses";
    for (const auto& [name, w] : v.items()) {
        if (name.empty() || name.size() > 64) return where + "has a pose name of 0 or > 64 bytes";
        const auto at = where.substr(0, where.size() - 1) + ".\"" + name + "\" ";
        if (!w.is_number() || !std::isfinite(w.get<double>()) || w.get<double>() < a.min ||
            w.get<double>() > a.max)
            return at + "must be a number within " + std::to_string(a.min) + " .. " +
                   std::to_string(a.max);
    }
    return std::nullopt;
}

std::optional<std::string> checkArg(const ControlCommand& c, const ControlArg& a,
                                    const nlohmann::json& v) {
    const auto where = std::string(c.name) + ": \"" + std::string(a.name) + "\" ";
    switch (a.type) {
        case Type::Boolean:
            if (!v.is_boolean()) return where + "must be " + typeName(a.type);
            return std::nullopt;
        case Type::Integer:
            if (!v.is_number_integer() || v.get<long long>() < a.min || v.get<long long>() > a.max)
                return where + "must be an integer within " + std::to_string(a.min) + " .. " +
                       std::to_string(a.max);
            return std::nullopt;
        case Type::String:
        case Type::Path:
            if (!v.is_string()) return where + "must be " + typeName(a.type);
            if (v.get_ref<const std::string&>().size() > a.maxLength)
                return where + "is longer than " + std::to_string(a.maxLength) + " bytes";
            if (a.required && v.get_ref<const std::string&>().empty())
                return where + "must not be empty";
            return std::nullopt;
        case Type::Weights:
            return checkWeights(where, a, v);
    }
    return std::nullopt;
}
}  // namespace

std::span<const ControlCommand> controlCommands() {
    return kCommands;
}

const ControlCommand* findControlCommand(std::string_view name) {
    const auto it = std::find_if(std::begin(kCommands), std::end(kCommands),
                                 [&](const ControlCommand& c) { return c.name == name; });
    return it == std::end(kCommands) ? nullptr : &*it;
}

std::string controlCommandNames() {
    std::string names;
    for (const auto& c : kCommands) names += (names.empty() ? "" : ", ") + std::string(c.name);
    return names;
}

std::optional<std::string> checkControlRequest(const nlohmann::json& request) {
    if (!request.is_object() || !request.contains("cmd") || !request["cmd"].is_string())
        return "expected an object with \"cmd\" (" + controlCommandNames() + ")";
    const auto& name = request["cmd"].get_ref<const std::string&>();
    const auto* command = findControlCommand(name);
    if (!command) return "unknown cmd '" + name + "' (" + controlCommandNames() + ")";
    for (const auto& item : request.items()) {
        const auto& key = item.key();
        const auto& value = item.value();
        if (key == "cmd") continue;
        const auto arg = std::find_if(command->args.begin(), command->args.end(),
                                      [&](const ControlArg& a) { return a.name == key; });
        if (arg == command->args.end()) return name + ": unknown argument \"" + key + "\"";
        if (auto bad = checkArg(*command, *arg, value)) return bad;
    }
    for (const auto& a : command->args)
        if (a.required && !request.contains(a.name))
            return name + " needs \"" + std::string(a.name) + "\"";
    return std::nullopt;
}

}  // namespace lipsyncd::daemon
