// One analysis frame, in the order of Lewis's "linear prediction speech model" section and
// codec2's lpc.c: pre-emphasis, window, autocorrelation, regularisation, Levinson–Durbin,
// spectrum. The regularisation constants follow shared/notes/dsp.md.
#include <lipsyncd/dsp.hpp>

#include "LpcSpectrum.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

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
    buffer_.resize(n);
    for (int i = 0; i < n; ++i)  // Hamming
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
}

FrameAnalyzer::FrameAnalyzer(FrameAnalyzer&&) noexcept = default;
FrameAnalyzer& FrameAnalyzer::operator=(FrameAnalyzer&&) noexcept = default;
FrameAnalyzer::~FrameAnalyzer() = default;

FrameFeatures FrameAnalyzer::makeFeatures() const {
    FrameFeatures f;
    f.spectrum.assign(config_.spectrumBins, 0.0f);
    return f;
}

void FrameAnalyzer::analyze(std::span<const float> frame, FrameFeatures& out) {
    const int n = static_cast<int>(window_.size());
    const int p = config_.order;
    double sumSquares = 0;
    int clippedSamples = 0;
    for (int i = 0; i < n; ++i) {
        const float x = i < static_cast<int>(frame.size()) ? frame[i] : 0.0f;
        sumSquares += static_cast<double>(x) * x;
        clippedSamples += std::abs(x) >= kClipLevel;
    }
    const double rms = std::sqrt(sumSquares / n);
    out.energyDb = rms > 0 ? static_cast<float>(20 * std::log10(rms)) : -120.0f;
    out.energyDb = std::max(out.energyDb, -120.0f);
    out.clipped = clippedSamples > kClippedShare * n;

    // Pre-emphasis and window in one pass (y[0] uses x[0] as its own predecessor).
    const float alpha = static_cast<float>(config_.preEmphasis);
    float previous = frame.empty() ? 0.0f : frame[0];
    for (int i = 0; i < n; ++i) {
        const float x = i < static_cast<int>(frame.size()) ? frame[i] : 0.0f;
        buffer_[i] = (x - alpha * previous) * window_[i];
        previous = x;
    }
    for (int lag = 0; lag <= p; ++lag) {
        float acc = 0;
        for (int i = lag; i < n; ++i) acc += buffer_[i] * buffer_[i - lag];
        r_[lag] = acc * lagWindow_[lag];
    }
    r_[0] = r_[0] * static_cast<float>(1.0 + config_.whiteNoiseCorrection) + kAbsoluteNoiseFloor;

    out.lpc = levinsonDurbin(std::span<const float>(r_.data(), p + 1), p);
    out.normalizedError = out.lpc.normalizedError;
    out.valid = out.energyDb > kSilentFrameDb && out.lpc.stable && std::isfinite(out.normalizedError);
    if (!out.valid) {
        // A flat spectrum: the classifier sees "nothing", the energy gate calls it silence.
        std::fill(out.spectrum.begin(), out.spectrum.end(), 0.0f);
        return;
    }
    if (fft_)
        fft_->evaluate(std::span<const float>(out.lpc.a.data(), p + 1), out.spectrum);
    else
        direct_->evaluate(std::span<const float>(out.lpc.a.data(), p + 1), out.spectrum);
}

}  // namespace lipsyncd::dsp
