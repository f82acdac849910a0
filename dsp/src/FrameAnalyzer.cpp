// One analysis frame, in the order of Lewis's "linear prediction speech model" section and
// codec2's lpc.c: pre-emphasis, window, autocorrelation, regularisation, Levinson–Durbin,
// spectrum. The regularisation constants follow shared/notes/dsp.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <numbers>

#include "LpcSpectrum.hpp"

namespace lipsyncd::dsp {

namespace {
// Below this RMS (dBFS) a frame is digital silence: no spectrum worth computing.
constexpr float kSilentFrameDb = -100.0f;
// A frame with more than this share of samples at full scale is clipped; its spectrum is
// distorted (flattened), so the classifier trusts it less.
constexpr float kClipLevel = 0.999f;
constexpr float kClippedShare = 0.01f;
// Absolute floor on r[0] so digital silence cannot reach the recursion as an exact zero.
constexpr float kAbsoluteNoiseFloor = 1e-9f;
}  // namespace

FrameAnalyzer::FrameAnalyzer(const AnalysisConfig& config) : config_(config) {
    config_.validate();
    const int n = config_.windowSamples();
    window_.resize(n);
    buffer_.assign(static_cast<std::size_t>(n) + kMaxOrder, 0.0f);  // kMaxOrder leading zeros
    for (int i = 0; i < n; ++i)                                     // Hamming
        window_[i] = static_cast<float>(0.54 - 0.46 * std::cos(2 * std::numbers::pi * i / (n - 1)));
    // Gaussian lag window w[i] = exp(−½(2π·f0·i/fs)²): smooths the spectrum by f0 Hz, so
    // pitch harmonics do not pull the formant peaks (Lewis's "pitch contamination").
    lagWindow_.resize(config_.order + 1);
    for (int i = 0; i <= config_.order; ++i) {
        const double x = 2 * std::numbers::pi * config_.lagWindowHz * i / config_.analysisRate;
        lagWindow_[i] = static_cast<float>(std::exp(-0.5 * x * x));
    }
    if (config_.spectrumByFft)
        fft_ = std::make_unique<FftLpcSpectrum>(config_.spectrumBins);
    else
        direct_ = std::make_unique<DirectLpcSpectrum>(config_.order, config_.spectrumBins);
    if (!config_.spectrumMean.empty()) normaliser_.emplace(config_);
}

FrameAnalyzer::FrameAnalyzer(FrameAnalyzer&&) noexcept = default;
FrameAnalyzer& FrameAnalyzer::operator=(FrameAnalyzer&&) noexcept = default;
FrameAnalyzer::~FrameAnalyzer() = default;

FrameFeatures FrameAnalyzer::makeFeatures() const {
    FrameFeatures f;
    f.spectrum.assign(static_cast<std::size_t>(config_.featureCount()), 0.0f);
    return f;
}

// Energy and clipping of the raw frame. Eight partial sums let the compiler vectorise.
void FrameAnalyzer::measureLevel(std::span<const float> frame, FrameFeatures& out) const {
    const std::size_t n = window_.size();
    const std::size_t m = std::min(n, frame.size());
    std::array<float, 8> squares{};
    std::array<int, 8> clipped{};
    for (std::size_t i = 0; i < m; ++i) {
        squares[i % 8] += frame[i] * frame[i];
        clipped[i % 8] += std::abs(frame[i]) >= kClipLevel;
    }
    double sumSquares = 0;
    int clippedSamples = 0;
    for (int j = 0; j < 8; ++j) sumSquares += squares[j], clippedSamples += clipped[j];
    const double rms = std::sqrt(sumSquares / static_cast<double>(n));
    out.energyDb = rms > 0 ? std::max(static_cast<float>(20 * std::log10(rms)), -120.0f) : -120.0f;
    out.clipped = clippedSamples > kClippedShare * static_cast<float>(n);
}

namespace {
// Autocorrelation of x[0..n) at lags 0..Lags-1, all lags at once: each sample is multiplied by
// the Lags samples before it, an inner loop with no dependency between lags and a fixed trip
// count, which the compiler unrolls and vectorises (x[-Lags+1..-1] must be zeros).
// On x86-64 the loop is also built for AVX2/FMA and picked at load time (8 lanes instead of 4);
// other targets (the ARM boards puppets run on) get their own default vectorisation.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define LIPSYNCD_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LIPSYNCD_VECTOR_CLONES
#endif

template <int Lags>
LIPSYNCD_VECTOR_CLONES void autocorrelateLags(const float* x, std::size_t n,
                                              std::array<float, kMaxOrder + 1>& r) {
    std::array<float, Lags> acc{};
    for (std::size_t i = 0; i < n; ++i) {
        const float* past = x + i - (Lags - 1);  // past[Lags - 1 - lag] == x[i - lag]
        for (int k = 0; k < Lags; ++k) acc[k] += x[i] * past[Lags - 1 - k];
    }
    std::copy(acc.begin(), acc.end(), r.begin());
}
}  // namespace

// Autocorrelation r[0..p] with the lag window applied. buffer_ starts with kMaxOrder zeros, so
// the look-back never leaves it.
void FrameAnalyzer::autocorrelate() {
    const int p = config_.order;
    const float* x = buffer_.data() + kMaxOrder;
    if (p < 16)
        autocorrelateLags<16>(x, window_.size(), r_);
    else
        autocorrelateLags<kMaxOrder + 1>(x, window_.size(), r_);
    for (int lag = 0; lag <= p; ++lag) r_[lag] *= lagWindow_[lag];
}

void FrameAnalyzer::analyze(std::span<const float> frame, FrameFeatures& out) {
    const std::size_t n = window_.size();
    const int p = config_.order;
    measureLevel(frame, out);

    // Pre-emphasis and window in one pass (y[0] uses x[0] as its own predecessor).
    const float alpha = static_cast<float>(config_.preEmphasis);
    float* y = buffer_.data() + kMaxOrder;
    const std::size_t m = std::min(n, frame.size());
    float previous = frame.empty() ? 0.0f : frame[0];
    for (std::size_t i = 0; i < m; ++i) {
        y[i] = (frame[i] - alpha * previous) * window_[i];
        previous = frame[i];
    }
    std::fill(y + m, y + n, 0.0f);
    autocorrelate();
    r_[0] = r_[0] * static_cast<float>(1.0 + config_.whiteNoiseCorrection) + kAbsoluteNoiseFloor;

    out.lpc = levinsonDurbin(std::span<const float>(r_.data(), p + 1), p);
    out.normalizedError = out.lpc.normalizedError;
    out.valid =
        out.energyDb > kSilentFrameDb && out.lpc.stable && std::isfinite(out.normalizedError);
    const auto bins = static_cast<std::size_t>(config_.spectrumBins);
    const auto spectrum = std::span<float>(out.spectrum).first(bins);
    if (!out.valid)  // a flat spectrum: the classifier sees "nothing", the gate calls it silence
        std::fill(spectrum.begin(), spectrum.end(), 0.0f);
    else if (fft_)
        fft_->evaluate(std::span<const float>(out.lpc.a.data(), p + 1), spectrum);
    else
        direct_->evaluate(std::span<const float>(out.lpc.a.data(), p + 1), spectrum);
    if (normaliser_) normaliser_->apply(out);
    addExtraFeatures(out);
}

void FrameAnalyzer::addExtraFeatures(FrameFeatures& out) {
    std::size_t at = static_cast<std::size_t>(config_.spectrumBins);
    if (config_.errorFeature)
        out.spectrum[at++] =
            out.valid ? std::max(-40.0f, 10.0f * std::log10(out.normalizedError)) : 0.0f;
    if (config_.levelFeature) {
        // The peak follows loud frames at once and decays slowly through quiet ones.
        const auto decay =
            static_cast<float>(config_.levelPeakDecayDbPerSecond * config_.hopSeconds);
        peakDb_ = std::max(out.energyDb, peakDb_ - decay);
        out.spectrum[at++] = std::max(-60.0f, out.energyDb - peakDb_);
    }
}

}  // namespace lipsyncd::dsp
