// The front end over a stream: resample to the analysis rate, cut frames every hop, analyse,
// classify, segment. Buffers are sized at construction; push() does not allocate.
#include <lipsyncd/dsp.hpp>

#include <algorithm>
#include <cstring>

namespace lipsyncd::dsp {

namespace {
constexpr std::size_t kMaxInputBlock = 4096;

FrontEndConfig withTemplateAnalysis(FrontEndConfig config, const TemplateSet& templates) {
    // Templates are only comparable with spectra made exactly as theirs were.
    const bool fft = config.analysis.spectrumByFft;
    config.analysis = templates.analysis;
    config.analysis.spectrumByFft = fft && (templates.analysis.spectrumBins & (templates.analysis.spectrumBins - 1)) == 0;
    return config;
}
}  // namespace

StreamingAnalyzer::StreamingAnalyzer(const TemplateSet& templates, const PhonemeSet& set,
                                     double inputRate, const FrontEndConfig& config)
    : templates_(templates),
      set_(&set),
      config_(withTemplateAnalysis(config, templates)),
      resampler_(inputRate, config_.analysis.analysisRate, config_.resamplerQuality, kMaxInputBlock),
      analyzer_(config_.analysis),
      classifier_(templates_, set, config_.classifier),
      segmenter_(set, config_.analysis.hopSeconds, config_.segmenter) {
    const auto window = static_cast<std::size_t>(config_.analysis.windowSamples());
    const auto maxOut = static_cast<std::size_t>(
        kMaxInputBlock * static_cast<double>(config_.analysis.analysisRate) / inputRate + 8192);
    ring_.assign(window + maxOut, 0.0f);
    frame_.features = analyzer_.makeFeatures();
}

double StreamingAnalyzer::resamplerDelaySeconds() const { return resampler_.delaySeconds(); }

double StreamingAnalyzer::latencySeconds() const {
    return resampler_.delaySeconds() + config_.analysis.windowSeconds +
           segmenter_.delaySeconds();
}

void StreamingAnalyzer::analyzeReadyFrames() {
    const auto window = static_cast<std::int64_t>(config_.analysis.windowSamples());
    const auto hop = static_cast<std::int64_t>(config_.analysis.hopSamples());
    const double rate = config_.analysis.analysisRate;
    while (nextFrameStart_ + window <= produced_) {
        const auto offset = static_cast<std::size_t>(nextFrameStart_ - consumed_);
        frame_.features.time = (static_cast<double>(nextFrameStart_) + window / 2.0) / rate;
        analyzer_.analyze(std::span<const float>(ring_.data() + offset, static_cast<std::size_t>(window)),
                          frame_.features);
        frame_.label = classifier_.classify(frame_.features);
        if (frameSink_) frameSink_(frame_);
        for (const auto& seg : segmenter_.push(frame_.label))
            if (segmentSink_) segmentSink_(seg);
        nextFrameStart_ += hop;
    }
    // Drop what no later frame needs.
    const auto keepFrom = static_cast<std::size_t>(std::max<std::int64_t>(0, nextFrameStart_ - consumed_));
    const std::size_t drop = std::min(keepFrom, ringFill_);
    if (drop > 0) {
        std::memmove(ring_.data(), ring_.data() + drop, (ringFill_ - drop) * sizeof(float));
        ringFill_ -= drop;
        consumed_ += static_cast<std::int64_t>(drop);
    }
}

void StreamingAnalyzer::appendResampled(std::span<const float> out) {
    std::size_t done = 0;
    while (done < out.size()) {
        const std::size_t n = std::min(out.size() - done, ring_.size() - ringFill_);
        std::memcpy(ring_.data() + ringFill_, out.data() + done, n * sizeof(float));
        ringFill_ += n;
        produced_ += static_cast<std::int64_t>(n);
        done += n;
        analyzeReadyFrames();
    }
}

void StreamingAnalyzer::push(std::span<const float> samples) {
    while (!samples.empty()) {
        const auto block = samples.first(std::min(samples.size(), kMaxInputBlock));
        appendResampled(resampler_.process(block));
        samples = samples.subspan(block.size());
    }
}

void StreamingAnalyzer::finish() {
    // Drain the resampler, then pad with silence so the last partial window is analysed.
    for (;;) {
        const auto out = resampler_.process({}, true);
        if (out.empty()) break;
        appendResampled(out);
    }
    const double endTime = static_cast<double>(produced_) / config_.analysis.analysisRate;
    // Half a window of silence lets every frame centred inside the audio be analysed.
    const std::vector<float> padding(static_cast<std::size_t>(config_.analysis.windowSamples() / 2), 0.0f);
    appendResampled(padding);
    for (const auto& seg : segmenter_.finish(endTime))
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
    if (keepFrames)
        analyzer.onFrame([&](const StreamingAnalyzer::Frame& f) { result.frames.push_back(f); });
    std::vector<float> block(kMaxInputBlock);
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
    return result;
}

}  // namespace lipsyncd::dsp
