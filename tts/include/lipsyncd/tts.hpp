// tts: text to speech with an exact phoneme schedule, from espeak-ng's own phoneme events
// (shared/notes/tts.md). No recognition is involved: the synthesiser says which phoneme it is
// producing and when.
#pragma once

#include <lipsyncd/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace lipsyncd {

struct SynthesisRequest {
    std::string text;
    std::string voice = "en-us";  // any espeak-ng voice, variants with '+', e.g. "en-us+f2"
    int wordsPerMinute = 0;       // 0: the voice's default (175)
    int pitch = -1;               // 0..100, -1: default
};

struct SynthesizedSpeech {
    std::vector<std::int16_t> samples;  // mono
    int sampleRate = 0;                 // espeak-ng's own rate (22050 Hz)
    // Phonemes in the synthesiser's own mnemonics (e.g. espeak-ng's "aI", "tS", "_:"); stress
    // and punctuation marks are kept so the caller's map can decide what to ignore.
    PhonemeSchedule phonemes;
};

// espeak-ng holds global state, so one synthesiser exists at a time (a second throws).
class EspeakSynthesizer {
public:
    // dataPath: espeak-ng-data folder, empty for the system default.
    explicit EspeakSynthesizer(const std::string& dataPath = "");
    ~EspeakSynthesizer();
    EspeakSynthesizer(const EspeakSynthesizer&) = delete;
    EspeakSynthesizer& operator=(const EspeakSynthesizer&) = delete;

    // Throws InputError for an unknown voice.
    SynthesizedSpeech synthesize(const SynthesisRequest& request);
    int sampleRate() const { return sampleRate_; }

private:
    int sampleRate_ = 0;
};

// Maps synthesiser mnemonics onto a phoneme set through `map`: ignored marks vanish, unknown
// symbols are warned about (naming the symbol) and become silence, neighbours of the same class
// merge.
PhonemeSchedule mapSchedule(const PhonemeSchedule& raw, const PhonemeMap& map,
                            std::vector<std::string>* warnings);

// The map for a voice: config/phonemes/espeak-<language>.toml, e.g. "en-us+f2" -> espeak-en.
// Throws InputError naming the voice when no map covers its language.
PhonemeMap espeakMapForVoice(const std::string& voice);

}  // namespace lipsyncd
