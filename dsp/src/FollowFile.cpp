// A file followed as the service follows a live line with its words: the streaming front end
// (its whole-file resampler, as analyzeFile reads files) feeding a LineFollower, for `lipsync
// eval --follow-lag`. The levels are the front end's, with the heard jaw at the audio-only
// share: live, the heard jaw is blended as for audio-only input.
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

AnalysisResult followFile(const std::filesystem::path& file, std::span<const ScriptWord> script,
                          const TemplateSet& templates, const PhonemeSet& set, double lagSeconds,
                          const FrontEndConfig& config, const AlignerConfig& aligner,
                          const DecodeOptions& decode) {
    auto decoder = AudioDecoder::open(file, decode);
    AnalysisResult result;
    result.inputRate = decoder.sampleRate();
    auto wholeFile = config;
    wholeFile.resamplerUse = ResamplerUse::WholeFile;
    StreamingAnalyzer analyzer(templates, set, decoder.sampleRate(), wholeFile);
    LineFollower follower(script, set, templates.analysis.hopSeconds, lagSeconds, aligner);
    follower.onSegment([&](const PhonemeSegment& s) { result.schedule.push_back(s); });
    analyzer.onFrame([&](const StreamingAnalyzer::Frame& f) {
        follower.push(f.label, analyzer.templateDistances(), analyzer.distances());
        result.levels.add(f.label.time, f.label.energyDb);
        result.levels.jaw.push_back(f.label.jaw);
    });
    const auto total = analyzer.pushAll(decoder);
    result.resamplerDelaySeconds = analyzer.resamplerDelaySeconds();
    analyzer.finish();
    follower.finish();
    result.durationSeconds = static_cast<double>(total) / decoder.sampleRate();
    result.nonFiniteSamples = decoder.nonFiniteSamples();
    result.warnings = decoder.warnings();
    // Before the first frame's hop nothing was heard; the last segment runs to the end.
    auto& s = result.schedule;
    if (!s.empty() && s.front().start > 0) {
        if (s.front().phoneme == "sil")
            s.front().start = 0;
        else
            s.insert(s.begin(), {0.0, s.front().start, "sil", 1.0f});
    }
    if (!s.empty()) s.back().end = std::max(s.back().end, result.durationSeconds);
    result.levels.rate = 1 / templates.analysis.hopSeconds;
    return result;
}

}  // namespace lipsyncd::dsp
