// Streaming sample-rate conversion. Ratios of whole rates with few phases (8, 16, 22.05, 44.1,
// 48 kHz → 10 kHz and most others) go through a polyphase FIR (PolyphaseResampler): a few ms of
// delay where libsoxr holds back tens, and up to 16 kHz input, less time per frame. Other
// ratios, the High and VeryHigh qualities and whole files above 16 kHz use libsoxr (the fastest
// resampler in Debian 12 by a wide margin: shared/notes/dsp.md). Allocates only at setup;
// process() reuses its buffers.
#include <soxr.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <lipsyncd/dsp.hpp>
#include <optional>

#include "PolyphaseResampler.hpp"

namespace lipsyncd::dsp {

struct StreamResampler::State {
    std::optional<PolyphaseResampler> fir;
    soxr_t soxr = nullptr;
    std::vector<float> out;
    std::size_t maxBlock = 0;
    ~State() {
        if (soxr) soxr_delete(soxr);
    }
};

namespace {
soxr_t createSoxr(double inputRate, double outputRate, ResamplerQuality quality, ResamplerUse use);

// Feeds silence in 10 ms blocks through a fresh twin of the resampler (`process` takes a block
// and returns how many samples came out) and returns the longest any sample waited: when a call
// releases output, its first new sample went in at input time `made` and comes out once `fed`
// seconds of input are in. Steady state only (after a warm-up second: the start-up fill happens
// once, before any sound a live path waits for). Run once at setup, so process() stays
// allocation-free.
double measureHeldBack(double inputRate, double outputRate,
                       const std::function<std::size_t(std::span<const float>)>& process) {
    const auto block = static_cast<std::size_t>(std::max(1.0, std::round(inputRate / 100)));
    const std::vector<float> in(block, 0.0f);
    double fed = 0, made = 0, worst = 0;
    for (int i = 0; i < 200; ++i) {
        const std::size_t produced = process(in);
        fed += static_cast<double>(block) / inputRate;
        if (i >= 100 && produced > 0) worst = std::max(worst, fed - made);
        made += static_cast<double>(produced) / outputRate;
    }
    return worst;
}

double soxrHeldBack(double inputRate, double outputRate, ResamplerQuality quality,
                    ResamplerUse use) {
    soxr_t probe = createSoxr(inputRate, outputRate, quality, use);
    std::vector<float> out(static_cast<std::size_t>(std::ceil(outputRate / 100)) + 4096);
    const double held = measureHeldBack(inputRate, outputRate, [&](std::span<const float> in) {
        size_t used = 0, produced = 0;
        soxr_process(probe, in.data(), in.size(), &used, out.data(), out.size(), &produced);
        return produced;
    });
    soxr_delete(probe);
    return held;
}

// The FIR's filters. Medium matches libsoxr's medium quality, which the shipped templates were
// trained through: flat to 91.6 % of the new Nyquist frequency and 70 dB down from it on, so
// nothing folds back (a filter that let the band's top 5 % alias a little moved the bilabial
// closures heard on the fillets-ng voices). Low is shorter and looser.
std::optional<LowPassSpec> firSpec(ResamplerQuality q) {
    switch (q) {
        case ResamplerQuality::Low:
            return LowPassSpec{50, 0.9, 1.0};
        case ResamplerQuality::Medium:
            return LowPassSpec{70, 0.916, 1.0};
        case ResamplerQuality::High:
        case ResamplerQuality::VeryHigh:
            return std::nullopt;
    }
    return std::nullopt;
}

// A whole file above 16 kHz goes through libsoxr: one long FIR at the input rate costs more per
// frame there than libsoxr's two stages (bench/frontend_bench ResampleFile: 0.95 against 1.30 µs
// a frame at 16 kHz, 168 taps a phase; 1.43 against 1.06 µs at 22.05 kHz, 232 taps). Live input
// takes the FIR at any rate, for its shorter delay.
constexpr std::size_t kMostWholeFileTaps = 192;

unsigned long soxrRecipe(ResamplerQuality q) {
    switch (q) {
        // The live preset where the FIR does not serve: phase does not matter to an LPC
        // magnitude spectrum, and minimum phase releases the impulse response's energy sooner.
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
    state_->maxBlock = maxBlock;
    if (const auto spec = firSpec(quality))
        state_->fir = PolyphaseResampler::create(inputRate, outputRate, *spec, maxBlock);
    if (state_->fir && use == ResamplerUse::WholeFile &&
        state_->fir->tapsPerPhase() > kMostWholeFileTaps)
        state_->fir.reset();
    if (state_->fir) {
        // A twin by copy (designing the filter again costs more than copying it).
        auto probe = *state_->fir;
        delaySeconds_ = measureHeldBack(inputRate, outputRate, [&](std::span<const float> in) {
            std::size_t made = 0;  // in pieces of at most maxBlock, as process() takes them
            for (std::size_t at = 0; at < in.size(); at += maxBlock)
                made +=
                    probe.process(in.subspan(at, std::min(maxBlock, in.size() - at)), false).size();
            return made;
        });
        return;
    }
    state_->soxr = createSoxr(inputRate, outputRate, quality, use);
    delaySeconds_ = soxrHeldBack(inputRate, outputRate, quality, use);
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
    if (s.fir) return s.fir->process(input, flush);
    size_t used = 0, made = 0;
    // soxr takes a null input pointer as "end of input": it then drains its filter.
    const float* in = flush && input.empty() ? nullptr : input.data();
    const auto err =
        soxr_process(s.soxr, in, input.size(), &used, s.out.data(), s.out.size(), &made);
    if (err) throw std::runtime_error(std::string("libsoxr: ") + err);
    return {s.out.data(), made};
}

}  // namespace lipsyncd::dsp
