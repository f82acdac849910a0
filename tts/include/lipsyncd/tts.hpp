// tts: text to speech with an exact phoneme schedule, from espeak-ng's own phoneme events
// (shared/notes/tts.md). No recognition is involved: the synthesiser says which phoneme it is
// producing and when.
#pragma once

#include <cstdint>
#include <functional>
#include <lipsyncd/core.hpp>
#include <lipsyncd/dsp.hpp>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace lipsyncd {

struct SynthesisRequest {
    std::string text;
    std::string voice = "en-us";  // any espeak-ng voice, variants with '+', e.g. "en-us+f2"
    int wordsPerMinute = 0;       // 0: the voice's default (175)
    int pitch = -1;               // 0..100, -1: default
    // 0: no limit. Otherwise speech stops there (`truncated` says so), and no more than this
    // is ever held: the service's max_clip_seconds bounds its memory and the worker's time.
    double maxSeconds = 0;
};

// One word of the text as espeak-ng read it: a number may become several spoken words, all
// under the one written word.
struct SpokenWord {
    std::string text;          // as written in the request
    PhonemeSchedule phonemes;  // its phonemes in espeak-ng's mnemonics, with its timings
};

struct SynthesizedSpeech {
    std::vector<std::int16_t> samples;  // mono
    int sampleRate = 0;                 // espeak-ng's own rate (22050 Hz)
    // Phonemes in the synthesiser's own mnemonics (e.g. espeak-ng's "aI", "tS", "_:"); stress
    // and punctuation marks are kept so the caller's map can decide what to ignore.
    PhonemeSchedule phonemes;
    // The same phonemes by written word (espeak-ng's word events).
    std::vector<SpokenWord> words;
    bool truncated = false;  // the text was longer than the request's maxSeconds
};

// espeak-ng holds global state, so one synthesiser exists at a time (a second throws). The
// engine is initialised by the first and never terminated (terminating and initialising it again
// hangs): one made after another was destroyed goes on with it, on the first one's data folder.
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

// ---------------------------------------------------------------------------------------------
// Known words: the script a forced alignment follows (dsp::ForcedAligner).

// Common reductions of a language (config/reductions/<language>.toml): weak forms of function
// words ("and" as /ən/ or /n/) and rules (a final t or d between consonants unsaid, a schwa
// between consonants unsaid), which the aligner tries beside espeak-ng's careful reading.
class Reductions {
  public:
    // Loads and validates a file: every phoneme must be one `map` knows (InputError names the
    // file, line and key at fault).
    static Reductions load(const std::filesystem::path& file, const PhonemeMap& map);
    // The shipped file for the voice's language; none (no reductions) when there is no file.
    static Reductions forVoice(const std::string& voice, const PhonemeMap& map);
    // The other ways `word` may be said (espeak-ng mnemonics, durations from its reading), given
    // the word after it (nullptr at the end); its own reading is not among them.
    std::vector<PhonemeSchedule> alternatives(const SpokenWord& word, const SpokenWord* next,
                                              const PhonemeMap& map, const PhonemeSet& set) const;

  private:
    std::map<std::string, std::vector<std::vector<std::string>>> words_;
    std::vector<std::string> dropFinal_, dropBetween_;
};

// The words of `text` with their phonemes in `map`'s set and espeak-ng's durations, read by
// espeak-ng itself (numbers, abbreviations and punctuation as it reads them). Words in a script
// the voice cannot read (it would spell them letter by letter) are left out with a warning, so
// the aligner treats them as unexplained speech. Throws InputError for empty text and for text
// with no word left. With `reductions`, each word also gets its other pronunciations.
std::vector<dsp::ScriptWord> scriptForText(EspeakSynthesizer& synth, const std::string& text,
                                           const std::string& voice, const PhonemeMap& map,
                                           std::vector<std::string>* warnings,
                                           const Reductions* reductions = nullptr);

// scriptForText with the voice's phoneme map (espeakMapForVoice, loaded by the caller, who
// needs its phoneme set too) and, with `reductions`, its language's common reductions: what
// alignText, followText and the service's live lines read.
std::vector<dsp::ScriptWord> scriptForVoice(EspeakSynthesizer& synth, const std::string& text,
                                            const std::string& voice, const PhonemeMap& map,
                                            std::vector<std::string>* warnings,
                                            bool reductions = true);

// Aligns `text` on the speech in `audio` with the voice's phoneme map and the given front end;
// the result says which words were placed and where the audio-only analysis stands in.
// `reductions`: try the language's common reductions too (Reductions::forVoice). `speaker`: one
// speaker's voice carried from line to line (dsp::alignFile).
dsp::AlignFileResult alignText(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                               const std::string& text, const std::string& voice,
                               const dsp::TemplateSet& templates,
                               const dsp::FrontEndConfig& frontEnd = {},
                               const dsp::AlignerConfig& aligner = {},
                               const dsp::DecodeOptions& decode = {},
                               const std::optional<dsp::RawFormat>& raw = std::nullopt,
                               bool reductions = true, dsp::SpeakerAdaptation* speaker = nullptr);

// Follows `text` in `audio` as the service follows a live line with its words (dsp::followFile:
// a fixed-lag alignment, `lagSeconds` behind the newest frame).
dsp::AnalysisResult followText(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                               const std::string& text, const std::string& voice,
                               const dsp::TemplateSet& templates, double lagSeconds,
                               const dsp::FrontEndConfig& frontEnd = {},
                               const dsp::AlignerConfig& aligner = {},
                               const dsp::DecodeOptions& decode = {}, bool reductions = true);

// The schedule of an audio file about to be played: aligned on `text` when given, else on the
// words of a `FILE.txt` beside `FILE.wav` when there is one, else the audio-only analysis. Text
// that cannot be aligned (empty, unreadable) falls back to the audio-only analysis. `log` gets
// one line saying which was used, and the alignment's warnings. For the service's clip
// preparation; `levels`, when given, gets the analysis's frame levels (the loudness shaping's
// input, so the caller need not read the audio a second time). `speaker`, when given, is the
// voice of the lines before: an aligned file starts from it and adds to it (alignText), a file
// without words is recognised on its templates once it has learnt any.
PhonemeSchedule scheduleForClip(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                                const std::optional<std::string>& text, const std::string& voice,
                                const dsp::TemplateSet& templates, const dsp::DecodeOptions& decode,
                                const std::function<void(const std::string&)>& log,
                                LevelTrack* levels = nullptr,
                                dsp::SpeakerAdaptation* speaker = nullptr);

// The words file beside an audio file (FILE.wav → FILE.txt), if there is one.
std::optional<std::filesystem::path> wordsBeside(const std::filesystem::path& audio);

}  // namespace lipsyncd
