#include <cmath>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

int AnalysisConfig::hopSamples() const {
    return static_cast<int>(std::lround(hopSeconds * analysisRate));
}

int AnalysisConfig::windowSamples() const {
    return static_cast<int>(std::lround(windowSeconds * analysisRate));
}

void AnalysisConfig::validate() const {
    auto bad = [](const std::string& field, const std::string& what) {
        throw InputError("analysis." + field + ": " + what);
    };
    if (analysisRate < 4000 || analysisRate > 48000) bad("rate", "must be 4000..48000 Hz");
    if (!(hopSeconds >= 0.002 && hopSeconds <= 0.05)) bad("hop", "must be 0.002..0.05 s");
    if (!(windowSeconds >= hopSeconds && windowSeconds <= 0.1))
        bad("window", "must be at least the hop and at most 0.1 s");
    if (order < 2 || order > kMaxOrder) bad("order", "must be 2.." + std::to_string(kMaxOrder));
    if (windowSamples() <= order) bad("window", "must hold more samples than the LPC order");
    if (!(preEmphasis >= 0 && preEmphasis < 1)) bad("pre_emphasis", "must be in [0, 1)");
    if (!(lagWindowHz >= 0 && lagWindowHz < analysisRate / 4.0))
        bad("lag_window_hz", "must be in [0, rate/4)");
    if (!(whiteNoiseCorrection >= 0 && whiteNoiseCorrection < 0.1))
        bad("white_noise_correction", "must be in [0, 0.1)");
    if (spectrumBins < 4 || spectrumBins > 512) bad("bins", "must be 4..512");
    if (spectrumByFft && (spectrumBins & (spectrumBins - 1)) != 0)
        bad("bins", "must be a power of two for FFT evaluation");
    if (!spectrumMean.empty()) {
        if (spectrumMean.size() != static_cast<std::size_t>(spectrumBins))
            bad("spectrum_mean", "must have one value per bin (" + std::to_string(spectrumBins) +
                                     "), has " + std::to_string(spectrumMean.size()));
        for (const float v : spectrumMean)
            if (!std::isfinite(v)) bad("spectrum_mean", "must be finite numbers");
        if (!(meanPriorSeconds > 0 && meanPriorSeconds <= 600))
            bad("mean_prior_seconds", "must be in (0, 600] s");
        if (!(meanMemorySeconds >= meanPriorSeconds && meanMemorySeconds <= 3600))
            bad("mean_memory_seconds", "must be at least mean_prior_seconds and at most 3600 s");
    }
    if (!(levelPeakDecayDbPerSecond > 0)) bad("level_peak_decay", "must be > 0 dB/s");
    static_assert(kMinWarp == 0.7 && kMaxWarp == 1.4, "the message names the bounds");
    if (!(warp >= kMinWarp && warp <= kMaxWarp)) bad("warp", "must be 0.7..1.4");
    if (spectrumByFft && warp != 1.0)
        bad("warp", "needs direct evaluation (an FFT's bins lie at fixed frequencies)");
}

}  // namespace lipsyncd::dsp
