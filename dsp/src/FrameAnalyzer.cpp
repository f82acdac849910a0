// One analysis frame, in the order of Lewis's "linear prediction speech model" section and
// codec2's lpc.c: pre-emphasis, window, autocorrelation, regularisation, Levinson–Durbin,
// spectrum. The regularisation constants follow shared/notes/dsp.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <numbers>

#include "FrameKernels.hpp"
#include "LpcSpectrum.hpp"

namespace lipsyncd::dsp {

namespace {
// Below this RMS (dBFS) a frame is digital silence: no spectrum worth computing.
constexpr float kSilentFrameDb = -100.0f;
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
        direct_ =
            std::make_unique<DirectLpcSpectrum>(config_.order, config_.spectrumBins, config_.warp);
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

void FrameAnalyzer::measureLevel(std::span<const float> frame, FrameFeatures& out) const {
    const auto level = kernels::measureLevel(frame, window_.size());
    out.energyDb = level.energyDb;
    out.clipped = level.clipped;
}

// Autocorrelation r[0..p] with the lag window applied. buffer_ starts with kMaxOrder zeros, so
// the look-back never leaves it.
void FrameAnalyzer::autocorrelate() {
    kernels::autocorrelate(buffer_.data() + kMaxOrder, window_.size(), config_.order, lagWindow_,
                           r_);
}

void FrameAnalyzer::analyze(std::span<const float> frame, FrameFeatures& out) {
    const int p = config_.order;
    measureLevel(frame, out);

    // Pre-emphasis and window in one pass (y[0] uses x[0] as its own predecessor).
    kernels::preEmphasizeAndWindow(frame, window_, static_cast<float>(config_.preEmphasis),
                                   buffer_.data() + kMaxOrder);
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
