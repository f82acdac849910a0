// Preview of a recording the page uploaded: its words aligned on it by the known-script
// aligner (`lipsync align`, as the service aligns a played file's words), or, without words or
// when they cannot be placed, the audio-only analysis (`lipsync analyze`). The same runtime as
// a typed sentence's preview animates the schedule.
#include <algorithm>
#include <cmath>
#include <lipsyncd/tts.hpp>

#include "SpeechPreview.hpp"
#include "UploadedAudio.hpp"

namespace lipsyncd::editor {

namespace {
using nlohmann::ordered_json;

// The recording as the page plays it back: mono 16-bit, what the analysis heard.
std::vector<std::int16_t> toPcm16(std::span<const float> samples) {
    std::vector<std::int16_t> out(samples.size());
    std::transform(samples.begin(), samples.end(), out.begin(), [](float v) {
        return static_cast<std::int16_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * 32767.0f));
    });
    return out;
}

dsp::MonoAudio decode(const UploadedAudio& upload, double maxSeconds) {
    try {
        const auto header = dsp::AudioDecoder::open(upload.path());
        const auto frames = header.frames().value_or(0);
        if (static_cast<double>(frames) > maxSeconds * header.sampleRate())
            throw TooLarge("wav: " + std::to_string(frames / header.sampleRate()) +
                           " s long; the editor previews at most " +
                           std::to_string(static_cast<int>(maxSeconds)) + " s");
        auto audio = dsp::readAudioFile(upload.path());
        if (audio.samples.empty()) throw InputError("wav: the recording holds no samples");
        return audio;
    } catch (const TooLarge&) {
        throw;
    } catch (const InputError& e) {
        // The decoder's hint about --raw is for the command line, not for an upload.
        auto message = upload.named(e.what());
        message = message.substr(0, message.find("; for headerless PCM"));
        throw InputError(message.starts_with("wav: ") ? message : "wav: " + message);
    }
}

ordered_json wordsJson(const dsp::Alignment& alignment) {
    auto out = ordered_json::array();
    for (const auto& w : alignment.words)
        out.push_back({{"text", w.text},
                       {"start", w.start},
                       {"end", w.end},
                       {"confidence", w.confidence},
                       {"placed", w.placed}});
    return out;
}
}  // namespace

Preview renderRecordingPreview(EspeakSynthesizer& speech, const dsp::TemplateSet& templates,
                               const std::string& bytes, const std::optional<std::string>& text,
                               const std::string& voice, double maxSeconds,
                               const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime) {
    const UploadedAudio upload(bytes);
    const auto audio = decode(upload, maxSeconds);
    std::vector<std::string> warnings;
    for (const auto& w : audio.warnings) warnings.push_back(upload.named(w));
    std::optional<dsp::AlignFileResult> aligned;
    if (!text) {
        warnings.push_back(
            "no words given: audio-only analysis (give the words spoken in the "
            "recording to align them)");
    } else {
        try {
            aligned = alignText(speech, upload.path(), *text, voice, templates);
            for (const auto& w : aligned->warnings)  // (the decoder's are there already)
                if (std::find(warnings.begin(), warnings.end(), upload.named(w)) == warnings.end())
                    warnings.push_back(upload.named(w));
        } catch (const InputError& e) {
            warnings.push_back("words not used: " + upload.named(e.what()) +
                               "; audio-only analysis");
        }
    }
    const bool used = aligned && !aligned->fellBack;
    const auto schedule =
        aligned ? aligned->schedule
                : dsp::analyzeFile(upload.path(), templates, PhonemeSet::common()).schedule;
    auto preview = makePreview(used ? "aligned" : "audio-only", schedule, toPcm16(audio.samples),
                               audio.sampleRate, draft, runtime, warnings);
    if (aligned) preview.reply["words"] = wordsJson(aligned->alignment);
    return preview;
}

}  // namespace lipsyncd::editor
