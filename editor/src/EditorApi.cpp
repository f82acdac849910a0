// The editor's HTTP API as a plain function of a request, so it is tested without sockets.
// Every call needs the token; a request names bigrams by class names only, never a file.
#include <cmath>
#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>

#include "SpeechPreview.hpp"

namespace lipsyncd::editor {

namespace {
using nlohmann::json;
using nlohmann::ordered_json;

// The runtime warps normalised time 0..½ onto the first phoneme and ½..1 onto the second
// (Xu et al. 2013, section 2.2.1), so their centres sit here.
constexpr double kFirstCentre = 0.25, kSecondCentre = 0.75;
constexpr std::size_t kCurveSamples = 101;  // the smooth curve, for drawing
constexpr std::size_t kMaxTextLength = 500;

ApiResponse reply(int status, const ordered_json& body) {
    return {status, body.dump()};
}
ApiResponse error(int status, const std::string& what) {
    return reply(status, ordered_json{{"error", what}});
}

// Equal-time comparison, so the token cannot be found a character at a time.
bool sameToken(const std::string& a, const std::string& b) {
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

std::vector<std::string> splitPath(const std::string& path) {
    std::vector<std::string> parts;
    std::size_t at = 0;
    while (at < path.size()) {
        const auto slash = path.find('/', at);
        const auto end = slash == std::string::npos ? path.size() : slash;
        if (end > at) parts.push_back(path.substr(at, end - at));
        at = end + 1;
    }
    return parts;
}

std::string classList(const PhonemeSet& phonemes) {
    std::string out;
    for (const auto& c : phonemes.classes()) out += (out.empty() ? "" : ", ") + c.name;
    return out;
}

ordered_json points(std::span<const lipsync::ControlPoint> polygon) {
    auto out = ordered_json::array();
    const auto saved = [](float v) { return std::round(static_cast<double>(v) * 1000) / 1000; };
    for (const auto& p : polygon) out.push_back({saved(p.time), saved(p.value)});
    return out;
}

// A request the API cannot even read: 400, where input it reads and refuses is 422.
struct MalformedRequest : InputError {
    using InputError::InputError;
};

json parseBody(const std::string& body) {
    auto j = json::parse(body, nullptr, false);
    if (j.is_discarded() || !j.is_object())
        throw MalformedRequest("request body: expected a JSON object");
    return j;
}
}  // namespace

EditorApi::EditorApi(CharacterDraft draft, MouthDrawing mouth, std::string token,
                     EspeakSynthesizer& speech, PreviewSettings preview)
    : draft_(std::move(draft)),
      mouth_(std::move(mouth)),
      token_(std::move(token)),
      speech_(&speech),
      settings_(std::move(preview)) {}

ApiResponse EditorApi::handle(const ApiRequest& request) {
    if (!sameToken(request.token, token_))
        return error(401, "missing or wrong token: use the address `lipsync edit` printed");
    std::lock_guard lock(mutex_);
    try {
        return route(request);
    } catch (const MalformedRequest& e) {
        return error(400, e.what());
    } catch (const InputError& e) {
        return error(422, e.what());
    } catch (const std::exception& e) {
        return error(500, e.what());
    }
}

ApiResponse EditorApi::route(const ApiRequest& request) {
    const auto parts = splitPath(request.path);
    const auto& m = request.method;
    if (parts.size() < 2 || parts[0] != "api") return error(404, "no such call: " + request.path);
    if (parts[1] == "bigrams" && parts.size() == 2) {
        if (m != "GET") return error(405, "GET /api/bigrams only");
        return listBigrams();
    }
    if (parts[1] == "bigrams" && parts.size() == 4) {
        const auto& set = draft_.phonemes();
        for (const auto* name : {&parts[2], &parts[3]})
            if (!set.find(*name))
                return error(404,
                             "no phoneme class '" + *name + "' (classes: " + classList(set) + ")");
        const auto a = *set.find(parts[2]), b = *set.find(parts[3]);
        if (m == "GET") return bigram(a, b);
        if (m == "PUT") return putBigram(a, b, request);
        return error(405, "GET or PUT /api/bigrams/FIRST/SECOND only");
    }
    if (parts.size() == 2 &&
        (parts[1] == "preview" || parts[1] == "save" || parts[1] == "perform")) {
        if (m != "POST") return error(405, "POST /api/" + parts[1] + " only");
        if (parts[1] == "perform") return perform(request);
        return parts[1] == "preview" ? preview(request) : save();
    }
    return error(404, "no such call: " + request.path);
}

ApiResponse EditorApi::listBigrams() const {
    const auto& set = draft_.phonemes();
    ordered_json j;
    auto& classes = j["phonemes"] = ordered_json::array();
    for (const auto& c : set.classes()) classes.push_back(c.name);
    j["poses"] = draft_.poses().names();
    j["centres"] = {kFirstCentre, kSecondCentre};
    j["character"] = draft_.characterFile().string();
    j["base"] = draft_.baseName();
    j["unsaved"] = draft_.unsaved();
    j["puppet"] =
        settings_.puppet ? ordered_json(settings_.puppet->puppet()) : ordered_json(nullptr);
    auto& mouth = j["mouth"];
    mouth["parameters"] = mouth_.parameters;
    mouth["neutral"] = mouth_.neutral;
    mouth["poses"] = ordered_json::object();
    for (const auto& [pose, amounts] : mouth_.poses) mouth["poses"][pose] = amounts;
    auto& list = j["bigrams"] = ordered_json::array();
    for (std::size_t a = 0; a < set.size(); ++a)
        for (std::size_t b = 0; b < set.size(); ++b)
            list.push_back({{"name", set[a].name + "-" + set[b].name},
                            {"first", set[a].name},
                            {"second", set[b].name},
                            {"state", toString(draft_.state(a, b))}});
    return reply(200, j);
}

ApiResponse EditorApi::bigram(std::size_t first, std::size_t second) const {
    const auto& set = draft_.phonemes();
    const auto polygons = draft_.polygons(first, second);
    ordered_json j;
    j["name"] = set[first].name + "-" + set[second].name;
    j["first"] = set[first].name;
    j["second"] = set[second].name;
    j["state"] = toString(draft_.state(first, second));
    j["unsaved"] = draft_.unsaved();
    auto& poses = j["poses"] = ordered_json::object();
    auto& curves = j["curves"] = ordered_json::object();
    for (std::size_t p = 0; p < draft_.poses().size(); ++p) {
        const auto& name = draft_.poses()[p].name;
        poses[name] = points(polygons[p]);
        const lipsync::ControlCurve curve(polygons[p]);
        auto& samples = curves[name] = ordered_json::array();
        for (std::size_t i = 0; i < kCurveSamples; ++i)
            samples.push_back(curve.at(static_cast<double>(i) / (kCurveSamples - 1)));
    }
    return reply(200, j);
}

ApiResponse EditorApi::putBigram(std::size_t first, std::size_t second, const ApiRequest& request) {
    const auto body = parseBody(request.body);
    if (!body.contains("poses") || !body["poses"].is_object())
        return error(400, "request body: expected {\"poses\": {\"POSE\": [[t, v], ...], ...}}");
    draft_.replace(
        first, second, body["poses"].dump(),
        "PUT /api/bigrams/" + draft_.phonemes()[first].name + "/" + draft_.phonemes()[second].name);
    return bigram(first, second);
}

ApiResponse EditorApi::preview(const ApiRequest& request) {
    const auto body = parseBody(request.body);
    auto voice = settings_.voice;
    if (body.contains("voice")) {
        if (!body["voice"].is_string() || !isVoiceName(body["voice"].get<std::string>()))
            return error(400, "voice: an espeak-ng voice name such as \"en-us+f2\"");
        voice = body["voice"].get<std::string>();
    }
    // The runtime's steps after the stitch can be switched off, as `animate --no-...` does.
    auto runtime = settings_.runtime;
    const std::pair<const char*, bool*> steps[] = {{"smoothing", &runtime.smoothing},
                                                   {"constraints", &runtime.constraints},
                                                   {"speed_limits", &runtime.speedLimits}};
    for (const auto& [key, flag] : steps)
        if (body.contains(key)) {
            if (!body[key].is_boolean())
                return error(400, std::string(key) + ": expected true or false");
            *flag = body[key].get<bool>();
        }
    if (body.contains("wav")) return previewRecording(body, voice, runtime);
    if (!body.contains("text") || !body["text"].is_string() ||
        body["text"].get<std::string>().empty())
        return error(400,
                     "request body: expected {\"text\": \"a sentence\"} or {\"wav\": "
                     "\"data:audio/wav;base64,...\", \"text\": \"its words\"}");
    const auto text = body["text"].get<std::string>();
    if (text.size() > kMaxTextLength)
        return error(400, "text: at most " + std::to_string(kMaxTextLength) + " bytes");
    auto p = renderPreview(*speech_, text, voice, draft_, runtime);
    lastPreview_ = std::move(p.weights);
    return reply(200, p.reply);
}

// {"wav": base64 or a data: URI of the file's bytes, "text": the words (optional)}. The bytes
// come in the request: a path in it would be a file the editor opens for a web page.
ApiResponse EditorApi::previewRecording(const json& body, const std::string& voice,
                                        const lipsync::RuntimeConfig& runtime) {
    if (!body["wav"].is_string())
        return error(400,
                     "wav: expected the file's bytes in base64 (\"data:audio/wav;base64,"
                     "...\"), not a path");
    const auto& encoded = body["wav"].get_ref<const std::string&>();
    // Base64 grows 3 bytes to 4; a data: URI's head is short.
    if (encoded.size() > settings_.maxUploadBytes / 3 * 4 + 64)
        return error(413, "wav: more than " + std::to_string(settings_.maxUploadBytes >> 20) +
                              " MiB; preview a shorter recording");
    const auto bytes = decodeBase64(encoded);
    if (!bytes)
        return error(400,
                     "wav: not base64 (expected \"data:audio/wav;base64,...\" or the "
                     "base64 of the file)");
    if (bytes->empty()) return error(400, "wav: empty");
    std::optional<std::string> text;
    if (body.contains("text")) {
        if (!body["text"].is_string())
            return error(400, "text: the words spoken in the recording, as a string");
        if (body["text"].get<std::string>().size() > kMaxTextLength)
            return error(400, "text: at most " + std::to_string(kMaxTextLength) + " bytes");
        if (!body["text"].get<std::string>().empty()) text = body["text"].get<std::string>();
    }
    espeakMapForVoice(voice);  // an unknown language is the request's error, not a fallback
    if (!templates_)
        templates_ = settings_.templates.empty() ? dsp::TemplateSet::loadDefault()
                                                 : dsp::TemplateSet::load(settings_.templates);
    try {
        auto p = renderRecordingPreview(*speech_, *templates_, *bytes, text, voice,
                                        settings_.maxRecordingSeconds, draft_, runtime);
        lastPreview_ = std::move(p.weights);
        return reply(200, p.reply);
    } catch (const TooLarge& e) {
        return error(413, e.what());
    } catch (const InputError& e) {
        return error(400, e.what());
    }
}

// {"from": seconds} when the page starts playing the preview's audio (from there), {"stop":
// true} when it pauses: the puppet follows the page.
ApiResponse EditorApi::perform(const ApiRequest& request) {
    const auto body = parseBody(request.body);
    auto* puppet = settings_.puppet;
    if (!puppet)
        return error(409, "no puppet: start `lipsync edit --socket PATH` with lipsyncd running");
    if (body.contains("stop") && !body["stop"].is_boolean())
        return error(400, "stop: expected true or false");
    if (body.value("stop", false)) {
        puppet->stop();
        ordered_json j{{"puppet", puppet->puppet()},
                       {"playing", false},
                       {"frames_sent", puppet->framesSent()}};
        // A stream the service stopped (a clip that started, the daemon gone) says why.
        if (const auto why = puppet->lastError(); !why.empty()) j["stopped_early"] = why;
        return reply(200, j);
    }
    const auto from = body.value("from", json(0.0));
    if (!from.is_number() || !(from.get<double>() >= 0) || !std::isfinite(from.get<double>()))
        return error(400, "from: seconds into the preview, a number ≥ 0");
    if (lastPreview_.frames() == 0) return error(409, "nothing to play: preview first");
    if (const auto refused = puppet->play(lastPreview_, from.get<double>()))
        return error(409, "lipsyncd: " + *refused);
    return reply(
        200, ordered_json{
                 {"puppet", puppet->puppet()}, {"playing", true}, {"lead", puppet->leadSeconds()}});
}

ApiResponse EditorApi::save() {
    if (draft_.characterFile().empty())
        return error(409, "no character file to save to: start `lipsync edit --character FILE`");
    const auto n = draft_.save();
    return reply(200, ordered_json{{"saved", n}, {"file", draft_.characterFile().string()}});
}

}  // namespace lipsyncd::editor
