// The front end over a stream: frames (FrameStream), classification, segmentation.
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
constexpr std::size_t kReadBlock = 4096;

FrontEndConfig withTemplateAnalysis(FrontEndConfig config, const TemplateSet& templates) {
    // Templates are only comparable with spectra made exactly as theirs were.
    const bool fft = config.analysis.spectrumByFft;
    const int bins = templates.analysis.spectrumBins;
    config.analysis = templates.analysis;
    config.analysis.spectrumByFft = fft && (bins & (bins - 1)) == 0;
    return config;
}
}  // namespace

StreamingAnalyzer::StreamingAnalyzer(const TemplateSet& templates, const PhonemeSet& set,
                                     double inputRate, const FrontEndConfig& config)
    : templates_(templates),
      config_(withTemplateAnalysis(config, templates)),
      frames_(config_.analysis, inputRate, config_.resamplerQuality),
      classifier_(templates_, set, config_.classifier),
      segmenter_(set, config_.analysis.hopSeconds, config_.segmenter) {
    frame_.features = FrameAnalyzer(config_.analysis).makeFeatures();
    featureSink_ = [this](const FrameFeatures& f) { onFeatures(f); };
}

double StreamingAnalyzer::latencySeconds() const {
    return frames_.resamplerDelaySeconds() + config_.analysis.windowSeconds +
           segmenter_.delaySeconds();
}

void StreamingAnalyzer::onFeatures(const FrameFeatures& features) {
    frame_.label = classifier_.classify(features);
    if (frameSink_) {
        frame_.features = features;
        frameSink_(frame_);
    }
    for (const auto& seg : segmenter_.push(frame_.label))
        if (segmentSink_) segmentSink_(seg);
}

void StreamingAnalyzer::push(std::span<const float> samples) {
    frames_.push(samples, featureSink_);
}

void StreamingAnalyzer::finish() {
    frames_.finish(featureSink_);
    for (const auto& seg : segmenter_.finish(frames_.endTime()))
        if (segmentSink_) segmentSink_(seg);
}

AnalysisResult analyzeFile(const std::filesystem::path& file, const TemplateSet& templates,
                           const PhonemeSet& set, const FrontEndConfig& config,
                           const DecodeOptions& decode, const std::optional<RawFormat>& raw,
                           bool keepFrames) {
    auto decoder = AudioDecoder::open(file, decode, raw);
    AnalysisResult result;
    result.inputRate = decoder.sampleRate();
    StreamingAnalyzer analyzer(templates, set, decoder.sampleRate(), config);
    analyzer.onSegment([&](const PhonemeSegment& s) { result.schedule.push_back(s); });
    double lastFrameTime = 0;
    analyzer.onFrame([&](const StreamingAnalyzer::Frame& f) {
        if (result.levels.db.empty()) result.levels.start = f.label.time;
        result.levels.db.push_back(f.label.energyDb);
        lastFrameTime = f.label.time;
        if (keepFrames) result.frames.push_back(f);
    });
    std::vector<float> block(kReadBlock);
    std::int64_t total = 0;
    while (const auto n = decoder.read(block)) {
        analyzer.push(std::span<const float>(block.data(), n));
        total += static_cast<std::int64_t>(n);
    }
    result.resamplerDelaySeconds = analyzer.resamplerDelaySeconds();
    analyzer.finish();
    result.durationSeconds = static_cast<double>(total) / decoder.sampleRate();
    result.nonFiniteSamples = decoder.nonFiniteSamples();
    if (!result.schedule.empty()) result.schedule.back().end = result.durationSeconds;
    if (result.levels.db.size() > 1)  // frames are a hop apart, whatever the templates chose
        result.levels.rate = static_cast<double>(result.levels.db.size() - 1) /
                             (lastFrameTime - result.levels.start);
    return result;
}

}  // namespace lipsyncd::dsp
