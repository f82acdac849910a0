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
      frames_(config_.analysis, inputRate, config_.resamplerQuality, config_.resamplerUse),
      classifier_(templates_, set, config_.classifier),
      segmenter_(set, config_.analysis.hopSeconds, config_.segmenter) {
    if (config_.decoder.enabled)
        decoder_.emplace(
            config_.transitions ? *config_.transitions : TransitionModel::loadDefault(), set,
            config_.analysis.hopSeconds, config_.decoder);
    frame_.features = FrameAnalyzer(config_.analysis).makeFeatures();
    featureSink_ = [this](const FrameFeatures& f) { onFeatures(f); };
}

double StreamingAnalyzer::latencySeconds() const {
    return frames_.resamplerDelaySeconds() + config_.analysis.windowSeconds +
           (decoder_ ? decoder_->delaySeconds() : 0.0) + segmenter_.delaySeconds();
}

void StreamingAnalyzer::segment(const FrameLabel& label) {
    for (const auto& seg : segmenter_.push(label))
        if (segmentSink_) segmentSink_(seg);
}

void StreamingAnalyzer::onFeatures(const FrameFeatures& features) {
    frame_.label = classifier_.classify(features);
    if (frameSink_) {
        frame_.features = features;
        frameSink_(frame_);
    }
    if (!decoder_) return segment(frame_.label);
    for (const auto& label : decoder_->push(frame_.label, classifier_.distances())) segment(label);
}

void StreamingAnalyzer::push(std::span<const float> samples) {
    frames_.push(samples, featureSink_);
}

void StreamingAnalyzer::finish() {
    frames_.finish(featureSink_);
    if (decoder_)
        for (const auto& label : decoder_->finish()) segment(label);
    for (const auto& seg : segmenter_.finish(frames_.endTime()))
        if (segmentSink_) segmentSink_(seg);
}

std::int64_t StreamingAnalyzer::pushAll(AudioDecoder& decoder) {
    std::vector<float> block(kReadBlock);
    std::int64_t total = 0;
    while (const auto n = decoder.read(block)) {
        push(std::span<const float>(block.data(), n));
        total += static_cast<std::int64_t>(n);
    }
    return total;
}

AnalysisResult analyzeFile(const std::filesystem::path& file, const TemplateSet& templates,
                           const PhonemeSet& set, const FrontEndConfig& config,
                           const DecodeOptions& decode, const std::optional<RawFormat>& raw,
                           bool keepFrames) {
    auto decoder = AudioDecoder::open(file, decode, raw);
    AnalysisResult result;
    result.inputRate = decoder.sampleRate();
    auto wholeFile = config;
    wholeFile.resamplerUse = ResamplerUse::WholeFile;
    StreamingAnalyzer analyzer(templates, set, decoder.sampleRate(), wholeFile);
    // One level a frame is all that grows with the input (besides the schedule): reserved at
    // once when the length is known, so an hour does not pass through doubling copies.
    if (const auto frames = decoder.frames()) {
        const auto count = static_cast<std::size_t>(
            static_cast<double>(*frames) / decoder.sampleRate() / templates.analysis.hopSeconds +
            2);
        result.levels.db.reserve(count);
        result.levels.jaw.reserve(count);
    }
    analyzer.onSegment([&](const PhonemeSegment& s) { result.schedule.push_back(s); });
    analyzer.onFrame([&](const StreamingAnalyzer::Frame& f) {
        result.levels.add(f.label.time, f.label.energyDb);
        result.levels.jaw.push_back(f.label.jaw);
        if (keepFrames) result.frames.push_back(f);
    });
    const auto total = analyzer.pushAll(decoder);
    result.resamplerDelaySeconds = analyzer.resamplerDelaySeconds();
    analyzer.finish();
    result.durationSeconds = static_cast<double>(total) / decoder.sampleRate();
    result.nonFiniteSamples = decoder.nonFiniteSamples();
    result.warnings = decoder.warnings();
    if (!result.schedule.empty()) result.schedule.back().end = result.durationSeconds;
    result.levels.rate = 1 / templates.analysis.hopSeconds;  // the templates' hop rules
    return result;
}

}  // namespace lipsyncd::dsp
