// The preview: a typed sentence (espeak-ng speaks it, its own phoneme timings become the
// schedule) or an uploaded recording (its words aligned, or the audio-only analysis); the
// draft's curves animate the schedule; the page gets schedule, weights and the audio in one
// answer.
#pragma once

#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>
#include <optional>

namespace lipsyncd::editor {

// A request over the editor's limits (upload bytes, recording length): HTTP 413.
struct TooLarge : InputError {
    using InputError::InputError;
};

// The reply, and the weights in it as a track (what the puppet plays).
struct Preview {
    nlohmann::ordered_json reply;
    PoseTrack weights;
};

// Letters, digits and '-', '+', '_' only: a voice name from a request never becomes a path.
bool isVoiceName(const std::string& voice);

// {"source": "espeak-ng", "schedule": [{start, end, phoneme}], "pairs": ["sil-f", ...],
//  "weights": {"poses", "rate", "times", "values": [[per frame] per pose]}, "duration",
//  "audio": "data:audio/wav;base64,...", "warnings": [...]}
Preview renderPreview(EspeakSynthesizer& speech, const std::string& text, const std::string& voice,
                      const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime);

// The same for a recording (WAV, FLAC or OGG bytes): "source" is "aligned" when its words
// (`text`) were placed by the known-script aligner, "audio-only" when no words were given or
// they could not be aligned (the warnings say why); "words" lists where each word went. The
// audio sent back is the recording as analysed (mono, 16-bit). InputError for audio that does
// not decode or is truncated, TooLarge for one longer than `maxSeconds`.
Preview renderRecordingPreview(EspeakSynthesizer& speech, const dsp::TemplateSet& templates,
                               const std::string& bytes, const std::optional<std::string>& text,
                               const std::string& voice, double maxSeconds,
                               const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime);

// Schedule, pairs, weights, duration and audio of any preview; `source` and `warnings` lead
// and close the reply.
Preview makePreview(const std::string& source, const PhonemeSchedule& schedule,
                    std::span<const std::int16_t> samples, int sampleRate,
                    const CharacterDraft& draft, const lipsync::RuntimeConfig& runtime,
                    const std::vector<std::string>& warnings);

// 16-bit mono PCM as a WAV file in a data: URI, for the page's <audio>.
std::string wavDataUri(std::span<const std::int16_t> samples, int sampleRate);
// Base64 (RFC 4648, section 4).
std::string encodeBase64(std::string_view bytes);
// Base64, bare or in a data: URI ("data:audio/wav;base64,...");
// nullopt when it is not.
std::optional<std::string> decodeBase64(std::string_view text);

}  // namespace lipsyncd::editor
