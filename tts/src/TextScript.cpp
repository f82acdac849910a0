// Text → the script of a forced alignment, by espeak-ng's own reading of it (its word events
// and phoneme events with their durations), through the same phoneme maps as `lipsync say`.
#include <algorithm>
#include <array>
#include <cctype>
#include <lipsyncd/tts.hpp>
#include <string_view>

#include "Utf8.hpp"

namespace lipsyncd {

namespace {
// Languages written in Latin script. espeak-ng voices for them spell a word in another script
// letter by letter (or name its characters), which is not what a speaker says.
constexpr std::array<std::string_view, 38> kLatinScriptLanguages = {
    "en", "de", "fr", "es", "it", "nl", "pt", "pl", "cs", "sv", "da", "nb", "fi",
    "hu", "ro", "sk", "sl", "hr", "tr", "id", "ms", "vi", "ca", "eu", "et", "lv",
    "lt", "af", "sw", "cy", "ga", "gd", "an", "is", "sq", "eo", "la", "mt"};

std::string languageOf(const std::string& voice) {
    const auto base = voice.substr(0, voice.find('+'));
    return base.substr(0, base.find('-'));
}

// A letter outside Latin (Basic Latin to Latin Extended-B, and Latin Extended Additional);
// general punctuation and symbols (U+2000..U+2BFF) are not letters, and nor are combining
// diacritical marks (U+0300..U+036F): text written decomposed (NFD, as macOS files and many
// Vietnamese texts are) carries its accents as such marks after the Latin letter.
bool foreignToLatin(char32_t c) {
    return c >= 0x250 && !(c >= 0x300 && c <= 0x36F) && !(c >= 0x1E00 && c <= 0x1EFF) &&
           !(c >= 0x2000 && c <= 0x2BFF);
}

bool readable(const std::string& word, const std::string& language) {
    if (std::find(kLatinScriptLanguages.begin(), kLatinScriptLanguages.end(), language) ==
        kLatinScriptLanguages.end())
        return true;  // no rule for this language: trust espeak-ng
    const auto cps = utf8::codePoints(word);
    return std::none_of(cps.begin(), cps.end(), foreignToLatin);
}

void warn(std::vector<std::string>* warnings, std::string message) {
    if (warnings) warnings->push_back(std::move(message));
}

PhonemeSchedule mapPhonemes(const SpokenWord& spoken, const PhonemeSchedule& phonemes,
                            const PhonemeMap& map, std::vector<std::string>* warnings) {
    PhonemeSchedule out;
    for (const auto& p : phonemes) {
        if (map.isIgnored(p.phoneme)) continue;
        const auto r = map.map(p.phoneme);
        if (!r) {
            warn(warnings, "word '" + spoken.text + "': unknown phoneme '" + p.phoneme +
                               "' (not in map " + map.name() + "); left out");
            continue;
        }
        out.push_back({p.start, p.end, r->phoneme, 1.0f});
    }
    return out;
}

// Text as an error message quotes it: on one line, and no longer than a line of a terminal (a
// words file can hold a paragraph).
std::string quotedInMessage(const std::string& text) {
    constexpr std::size_t kMostCodePoints = 60;
    std::string out;
    std::size_t shown = 0;
    bool space = false;
    for (const char32_t c : utf8::codePoints(text)) {
        if (c < 0x80 && std::isspace(static_cast<int>(c))) {
            space = !out.empty();
            continue;
        }
        if (shown + (space ? 1 : 0) >= kMostCodePoints) return "'" + out + "…'";
        if (space) out += ' ', ++shown;
        space = false;
        utf8::append(out, c);
        ++shown;
    }
    return "'" + out + "'";
}

bool hasSound(const dsp::ScriptWord& w) {
    return std::any_of(w.phonemes.begin(), w.phonemes.end(),
                       [](const PhonemeSegment& p) { return p.phoneme != "sil"; });
}
}  // namespace

std::vector<dsp::ScriptWord> scriptForText(EspeakSynthesizer& synth, const std::string& text,
                                           const std::string& voice, const PhonemeMap& map,
                                           std::vector<std::string>* warnings,
                                           const Reductions* reductions) {
    if (std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isspace(c) != 0; }))
        throw InputError("the text to align is empty");
    const auto speech = synth.synthesize({text, voice, 0, -1});
    const auto language = languageOf(voice);
    const auto& set = PhonemeSet::named(map.phonemeSet());
    std::vector<dsp::ScriptWord> script;
    for (std::size_t i = 0; i < speech.words.size(); ++i) {
        const auto& spoken = speech.words[i];
        if (!readable(spoken.text, language)) {
            warn(warnings, "word '" + spoken.text + "' is in a script voice '" + voice +
                               "' cannot read (espeak-ng would spell it): left to audio-only "
                               "analysis");
            continue;
        }
        dsp::ScriptWord word{spoken.text, mapPhonemes(spoken, spoken.phonemes, map, warnings)};
        if (!hasSound(word)) continue;
        if (reductions) {
            const auto* next = i + 1 < speech.words.size() ? &speech.words[i + 1] : nullptr;
            for (const auto& form : reductions->alternatives(spoken, next, map, set))
                word.alternatives.push_back(mapPhonemes(spoken, form, map, nullptr));
        }
        script.push_back(std::move(word));
    }
    if (script.empty())
        throw InputError("espeak-ng (voice '" + voice + "') found no words it can read in " +
                         quotedInMessage(text));
    return script;
}

std::vector<dsp::ScriptWord> scriptForVoice(EspeakSynthesizer& synth, const std::string& text,
                                            const std::string& voice, const PhonemeMap& map,
                                            std::vector<std::string>* warnings, bool reductions) {
    const auto weakForms = reductions ? Reductions::forVoice(voice, map) : Reductions{};
    return scriptForText(synth, text, voice, map, warnings, &weakForms);
}

dsp::AlignFileResult alignText(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                               const std::string& text, const std::string& voice,
                               const dsp::TemplateSet& templates,
                               const dsp::FrontEndConfig& frontEnd,
                               const dsp::AlignerConfig& aligner, const dsp::DecodeOptions& decode,
                               const std::optional<dsp::RawFormat>& raw, bool reductions,
                               dsp::SpeakerAdaptation* speaker) {
    std::vector<std::string> warnings;
    const auto map = espeakMapForVoice(voice);
    const auto script = scriptForVoice(synth, text, voice, map, &warnings, reductions);
    const auto& set = PhonemeSet::named(map.phonemeSet());
    auto result =
        dsp::alignFile(audio, script, templates, set, frontEnd, aligner, decode, raw, speaker);
    result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
    return result;
}

dsp::AnalysisResult followText(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                               const std::string& text, const std::string& voice,
                               const dsp::TemplateSet& templates, double lagSeconds,
                               const dsp::FrontEndConfig& frontEnd,
                               const dsp::AlignerConfig& aligner, const dsp::DecodeOptions& decode,
                               bool reductions) {
    std::vector<std::string> warnings;
    const auto map = espeakMapForVoice(voice);
    const auto script = scriptForVoice(synth, text, voice, map, &warnings, reductions);
    const auto& set = PhonemeSet::named(map.phonemeSet());
    auto result =
        dsp::followFile(audio, script, templates, set, lagSeconds, frontEnd, aligner, decode);
    result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
    return result;
}

}  // namespace lipsyncd
