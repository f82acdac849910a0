// Preview of a typed sentence, as `lipsync say --weights` computes it, on the unsaved curves;
// the reply's form, which a recording's preview shares.
#include "SpeechPreview.hpp"

#include <algorithm>
#include <lipsyncd/tts.hpp>

namespace lipsyncd::editor {

namespace {
using nlohmann::ordered_json;

// The pairs the runtime uses: neighbours, and silence before the first and after the last
// phoneme (the runtime brackets a schedule with silence).
ordered_json pairsOf(const PhonemeSchedule& schedule) {
    std::vector<std::string> names{"sil"};
    for (const auto& s : schedule) names.push_back(s.phoneme);
    names.push_back("sil");
    std::vector<std::string> pairs;
    for (std::size_t i = 0; i + 1 < names.size(); ++i) {
        auto pair = names[i] + "-" + names[i + 1];
        if (std::find(pairs.begin(), pairs.end(), pair) == pairs.end())
            pairs.push_back(std::move(pair));
    }
    return pairs;
}

ordered_json weightsJson(const PoseTrack& track, double rate) {
    ordered_json w;
    w["poses"] = track.poses;
    w["rate"] = rate;
    w["times"] = track.times;
    auto& values = w["values"] = ordered_json::array();
    for (std::size_t p = 0; p < track.poses.size(); ++p) {
        auto row = ordered_json::array();
        for (std::size_t f = 0; f < track.frames(); ++f) row.push_back(track.frame(f)[p]);
        values.push_back(std::move(row));
    }
    return w;
}
}  // namespace

bool isVoiceName(const std::string& voice) {
    return !voice.empty() && voice.size() <= 64 &&
           std::all_of(voice.begin(), voice.end(), [](char c) {
               return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '+' || c == '_';
           });
}

Preview makePreview(const std::string& source, const PhonemeSchedule& schedule,
                    std::span<const std::int16_t> samples, int sampleRate,
                    const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime,
                    const std::vector<std::string>& warnings) {
    Preview p;
    p.weights =
        lipsync::animate(schedule, draft.curves(), draft.poses(), runtime, draft.phonemes());
    auto& j = p.reply;
    j["source"] = source;
    auto& segments = j["schedule"] = ordered_json::array();
    for (const auto& s : schedule)
        segments.push_back({{"start", s.start}, {"end", s.end}, {"phoneme", s.phoneme}});
    j["pairs"] = pairsOf(schedule);
    j["weights"] = weightsJson(p.weights, runtime.outputRate);
    j["duration"] = static_cast<double>(samples.size()) / sampleRate;
    j["audio"] = wavDataUri(samples, sampleRate);
    j["warnings"] = warnings;
    return p;
}

Preview renderPreview(EspeakSynthesizer& speech, const std::string& text, const std::string& voice,
                      const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime) {
    const auto spoken = speech.synthesize({text, voice});
    std::vector<std::string> warnings;
    const auto schedule = mapSchedule(spoken.phonemes, espeakMapForVoice(voice), &warnings);
    return makePreview("espeak-ng", schedule, spoken.samples, spoken.sampleRate, draft, runtime,
                       warnings);
}

}  // namespace lipsyncd::editor
