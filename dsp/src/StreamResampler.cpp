// Streaming sample-rate conversion with libsoxr (the fastest resampler in Debian 12 by a wide
// margin: shared/notes/dsp.md). Allocates only here at setup; process() reuses its buffer.
#include <soxr.h>

#include <algorithm>
#include <cmath>
#include <lipsyncd/dsp.hpp>

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
soxr_t createSoxr(double inputRate, double outputRate, ResamplerQuality quality, ResamplerUse use);

// Feeds silence in 10 ms blocks through a fresh resampler and returns the longest any sample
// waited: when a call releases output, its first new sample went in at input time `made` and
// comes out once `fed` seconds of input are in. Steady state only (after a warm-up second: the
// start-up fill happens once, before any sound a live path waits for). Run once at setup, so
// process() stays allocation-free.
double measureHeldBack(double inputRate, double outputRate, ResamplerQuality quality,
                       ResamplerUse use) {
    soxr_t probe = createSoxr(inputRate, outputRate, quality, use);
    const auto block = static_cast<std::size_t>(std::max(1.0, std::round(inputRate / 100)));
    std::vector<float> in(block, 0.0f);
    std::vector<float> out(static_cast<std::size_t>(std::ceil(block * outputRate / inputRate)) +
                           4096);
    double fed = 0, made = 0, worst = 0;
    for (int i = 0; i < 200; ++i) {
        size_t used = 0, produced = 0;
        soxr_process(probe, in.data(), in.size(), &used, out.data(), out.size(), &produced);
        fed += static_cast<double>(used) / inputRate;
        if (i >= 100 && produced > 0) worst = std::max(worst, fed - made);
        made += static_cast<double>(produced) / outputRate;
    }
    soxr_delete(probe);
    return worst;
}

unsigned long soxrRecipe(ResamplerQuality q) {
    switch (q) {
        // The live preset: phase does not matter to an LPC magnitude spectrum, and minimum
        // phase releases the impulse response's energy sooner.
        case ResamplerQuality::Low:
            return SOXR_LQ | SOXR_MINIMUM_PHASE;
        case ResamplerQuality::Medium:
            return SOXR_MQ;
        case ResamplerQuality::High:
            return SOXR_HQ;
        case ResamplerQuality::VeryHigh:
            return SOXR_VHQ;
    }
    return SOXR_MQ;
}

soxr_t createSoxr(double inputRate, double outputRate, ResamplerQuality quality, ResamplerUse use) {
    soxr_error_t err = nullptr;
    const auto io = soxr_io_spec(SOXR_FLOAT32_I, SOXR_FLOAT32_I);
    const auto q = soxr_quality_spec(soxrRecipe(quality), 0);
    auto runtime = soxr_runtime_spec(1);
    // Live: smaller DFT blocks. libsoxr's defaults (2^10 .. 2^17) hold back up to 94 ms of
    // 16 kHz input at MQ; 2^8 .. 2^10 hold back 43 ms (MQ) or 22 ms (LQ, minimum phase), at the
    // same speed in 10 ms blocks (bench/frontend_bench Resample10ms reports delay_ms). A whole
    // file keeps the defaults: in 4096-sample blocks they are about 1.35 times faster (0.97
    // against 1.30 µs per 10 ms frame at 16 kHz; bench/frontend_bench ResampleFile).
    if (use == ResamplerUse::Live) {
        runtime.log2_min_dft_size = 8;
        runtime.log2_large_dft_size = 10;
    }
    soxr_t soxr = soxr_create(inputRate, outputRate, 1, &err, &io, &q, &runtime);
    if (err) throw std::runtime_error(std::string("libsoxr: ") + err);
    return soxr;
}
}  // namespace

StreamResampler::StreamResampler(double inputRate, double outputRate, ResamplerQuality quality,
                                 std::size_t maxBlock, ResamplerUse use)
    : state_(std::make_unique<State>()), inputRate_(inputRate), outputRate_(outputRate) {
    if (!(inputRate > 0) || !(outputRate > 0))
        throw InputError("resampler: rates must be positive");
    state_->soxr = createSoxr(inputRate, outputRate, quality, use);
    delaySeconds_ = measureHeldBack(inputRate, outputRate, quality, use);
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
    const auto err =
        soxr_process(s.soxr, in, input.size(), &used, s.out.data(), s.out.size(), &made);
    if (err) throw std::runtime_error(std::string("libsoxr: ") + err);
    return {s.out.data(), made};
}

}  // namespace lipsyncd::dsp
