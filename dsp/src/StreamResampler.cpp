// Streaming sample-rate conversion with libsoxr (the fastest resampler in Debian 12 by a wide
// margin: shared/notes/dsp.md). Allocates only here at setup; process() reuses its buffer.
#include <lipsyncd/dsp.hpp>

#include <soxr.h>

#include <cmath>

namespace lipsyncd::dsp {

struct StreamResampler::State {
    soxr_t soxr = nullptr;
    std::vector<float> out;
    std::size_t maxBlock = 0;
    ~State() {
        if (soxr) soxr_delete(soxr);
    }
};

namespace {
unsigned long soxrRecipe(ResamplerQuality q) {
    switch (q) {
        case ResamplerQuality::Low: return SOXR_LQ;
        case ResamplerQuality::Medium: return SOXR_MQ;
        case ResamplerQuality::High: return SOXR_HQ;
        case ResamplerQuality::VeryHigh: return SOXR_VHQ;
    }
    return SOXR_MQ;
}
}  // namespace

StreamResampler::StreamResampler(double inputRate, double outputRate, ResamplerQuality quality,
                                 std::size_t maxBlock)
    : state_(std::make_unique<State>()), inputRate_(inputRate), outputRate_(outputRate) {
    if (!(inputRate > 0) || !(outputRate > 0))
        throw InputError("resampler: rates must be positive");
    soxr_error_t err = nullptr;
    const auto io = soxr_io_spec(SOXR_FLOAT32_I, SOXR_FLOAT32_I);
    const auto q = soxr_quality_spec(soxrRecipe(quality), 0);
    state_->soxr = soxr_create(inputRate, outputRate, 1, &err, &io, &q, nullptr);
    if (err) throw std::runtime_error(std::string("libsoxr: ") + err);
    state_->maxBlock = maxBlock;
    // Room for one block's worth of output plus what the filter may release on flush.
    const auto room = static_cast<std::size_t>(std::ceil(maxBlock * outputRate / inputRate)) + 4096;
    state_->out.resize(room);
}

StreamResampler::StreamResampler(StreamResampler&&) noexcept = default;
StreamResampler& StreamResampler::operator=(StreamResampler&&) noexcept = default;
StreamResampler::~StreamResampler() = default;

std::span<const float> StreamResampler::process(std::span<const float> input, bool flush) {
    auto& s = *state_;
    if (input.size() > s.maxBlock) throw std::logic_error("resampler: block larger than maxBlock");
    size_t used = 0, made = 0;
    // soxr takes a null input pointer as "end of input": it then drains its filter.
    const float* in = flush && input.empty() ? nullptr : input.data();
    const auto err = soxr_process(s.soxr, in, input.size(), &used, s.out.data(), s.out.size(), &made);
    if (err) throw std::runtime_error(std::string("libsoxr: ") + err);
    return {s.out.data(), made};
}

double StreamResampler::delaySeconds() const { return soxr_delay(state_->soxr) / outputRate_; }

}  // namespace lipsyncd::dsp
