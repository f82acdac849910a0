// A played file's schedule: its known words aligned when the request or a FILE.txt beside it
// gives them (issue 11), the audio-only analysis otherwise.
#include <fstream>
#include <lipsyncd/tts.hpp>
#include <sstream>

namespace lipsyncd {

std::optional<std::filesystem::path> wordsBeside(const std::filesystem::path& audio) {
    auto words = audio;
    words.replace_extension(".txt");
    std::error_code ec;
    if (words == audio || !std::filesystem::is_regular_file(words, ec)) return std::nullopt;
    return words;
}

namespace {
// A warning as the log shows it: with the file's name in front, once (the decoder's and the
// aligner's file-wide ones have it already).
std::string namingTheFile(const std::filesystem::path& audio, const std::string& warning) {
    const auto name = audio.string() + ": ";
    return warning.starts_with(name) ? warning : name + warning;
}

std::optional<std::string> readWords(const std::filesystem::path& file,
                                     const std::function<void(const std::string&)>& log) {
    std::ifstream in(file);
    if (!in) {
        log(file.string() + ": cannot read the words file; audio-only analysis");
        return std::nullopt;
    }
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}
}  // namespace

PhonemeSchedule scheduleForClip(EspeakSynthesizer& synth, const std::filesystem::path& audio,
                                const std::optional<std::string>& text, const std::string& voice,
                                const dsp::TemplateSet& templates, const dsp::DecodeOptions& decode,
                                const std::function<void(const std::string&)>& log,
                                LevelTrack* levels, dsp::SpeakerAdaptation* speaker) {
    std::optional<std::string> words = text;
    std::string source = "the request";
    if (!words)
        if (const auto beside = wordsBeside(audio)) {
            words = readWords(*beside, log);
            source = beside->string();
        }
    if (words) {
        try {
            const auto r = alignText(synth, audio, *words, voice, templates, {}, {}, decode,
                                     std::nullopt, true, speaker);
            log(audio.string() + ": words from " + source + " aligned" +
                (r.fellBack ? " (fell back to audio-only analysis)" : ""));
            for (const auto& w : r.warnings) log(namingTheFile(audio, w));
            if (levels) *levels = r.levels;
            return r.schedule;
        } catch (const InputError& e) {
            log(audio.string() + ": words from " + source + " not used: " + e.what() +
                "; audio-only analysis");
        }
    }
    // Recognised on the speaker's voice as heard so far, when lines with words have taught it.
    const auto own =
        speaker ? speaker->adaptedIfHeard(dsp::AlignerConfig{}.speakerAdaptationPriorFrames)
                : std::nullopt;
    auto r = dsp::analyzeFile(audio, own ? *own : templates, PhonemeSet::common(), {}, decode);
    for (const auto& w : r.warnings) log(w);
    if (levels) *levels = std::move(r.levels);
    return std::move(r.schedule);
}

}  // namespace lipsyncd
