// Resample to the analysis rate and cut a frame every hop. Buffers are sized at construction;
// push() does not allocate.
#include <algorithm>
#include <cstring>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
constexpr std::size_t kMaxInputBlock = 4096;
}

FrameStream::FrameStream(const AnalysisConfig& config, double inputRate, ResamplerQuality quality,
                         ResamplerUse use)
    : resampler_(inputRate, config.analysisRate, quality, kMaxInputBlock, use), analyzer_(config) {
    features_ = analyzer_.makeFeatures();
    const auto window = static_cast<std::size_t>(config.windowSamples());
    const auto maxOut = static_cast<std::size_t>(
        kMaxInputBlock * static_cast<double>(config.analysisRate) / inputRate + 8192);
    buffer_.assign(window + maxOut, 0.0f);
}

double FrameStream::endTime() const {
    return endTime_;
}

void FrameStream::analyzeReadyFrames(const Sink& sink) {
    const auto& c = analyzer_.config();
    const auto window = static_cast<std::int64_t>(c.windowSamples());
    const auto hop = static_cast<std::int64_t>(c.hopSamples());
    while (nextFrameStart_ + window <= produced_) {
        const auto offset = static_cast<std::size_t>(nextFrameStart_ - consumed_);
        features_.time = (static_cast<double>(nextFrameStart_) + window / 2.0) / c.analysisRate;
        analyzer_.analyze(
            std::span<const float>(buffer_.data() + offset, static_cast<std::size_t>(window)),
            features_);
        sink(features_);
        nextFrameStart_ += hop;
    }
    // Drop what no later frame needs.
    const auto keepFrom =
        static_cast<std::size_t>(std::max<std::int64_t>(0, nextFrameStart_ - consumed_));
    const std::size_t drop = std::min(keepFrom, fill_);
    if (drop > 0) {
        std::memmove(buffer_.data(), buffer_.data() + drop, (fill_ - drop) * sizeof(float));
        fill_ -= drop;
        consumed_ += static_cast<std::int64_t>(drop);
    }
}

void FrameStream::append(std::span<const float> resampled, const Sink& sink) {
    while (!resampled.empty()) {
        const std::size_t n = std::min(resampled.size(), buffer_.size() - fill_);
        std::memcpy(buffer_.data() + fill_, resampled.data(), n * sizeof(float));
        fill_ += n;
        produced_ += static_cast<std::int64_t>(n);
        resampled = resampled.subspan(n);
        analyzeReadyFrames(sink);
    }
}

void FrameStream::push(std::span<const float> samples, const Sink& sink) {
    while (!samples.empty()) {
        const auto block = samples.first(std::min(samples.size(), kMaxInputBlock));
        append(resampler_.process(block), sink);
        samples = samples.subspan(block.size());
    }
    endTime_ = static_cast<double>(produced_) / analyzer_.config().analysisRate;
}

void FrameStream::finish(const Sink& sink) {
    for (;;) {
        const auto out = resampler_.process({}, true);
        if (out.empty()) break;
        append(out, sink);
    }
    endTime_ = static_cast<double>(produced_) / analyzer_.config().analysisRate;
    // Half a window of silence lets every frame centred inside the audio be analysed.
    const std::vector<float> padding(
        static_cast<std::size_t>(analyzer_.config().windowSamples() / 2), 0.0f);
    append(padding, sink);
}

std::vector<FrameFeatures> analyzeFrames(const std::filesystem::path& file,
                                         const AnalysisConfig& config, const DecodeOptions& decode,
                                         std::vector<std::string>* warnings) {
    auto decoder = AudioDecoder::open(file, decode);
    FrameStream stream(config, decoder.sampleRate(), ResamplerQuality::Medium,
                       ResamplerUse::WholeFile);
    std::vector<FrameFeatures> frames;
    const FrameStream::Sink keep = [&](const FrameFeatures& f) { frames.push_back(f); };
    std::vector<float> block(kMaxInputBlock);
    while (const auto n = decoder.read(block))
        stream.push(std::span<const float>(block.data(), n), keep);
    stream.finish(keep);
    if (warnings) *warnings = decoder.warnings();
    return frames;
}

}  // namespace lipsyncd::dsp
