// The preview: espeak-ng speaks a sentence, its own phoneme timings become the schedule, the
// draft's curves animate it; the page gets schedule, weights and the audio in one answer.
#pragma once

#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::editor {

// Letters, digits and '-', '+', '_' only: a voice name from a request never becomes a path.
bool isVoiceName(const std::string& voice);

// {"schedule": [{start, end, phoneme}], "pairs": ["sil-f", ...], "weights": {"poses", "rate",
//  "times", "values": [[per frame] per pose]}, "duration", "audio": "data:audio/wav;base64,...",
//  "warnings": [...]}
nlohmann::ordered_json renderPreview(EspeakSynthesizer& speech, const std::string& text,
                                     const std::string& voice, const CharacterDraft& draft,
                                     const lipsync::RuntimeConfig& runtime);

// 16-bit mono PCM as a WAV file in a data: URI, for the page's <audio>.
std::string wavDataUri(std::span<const std::int16_t> samples, int sampleRate);

}  // namespace lipsyncd::editor
