// Channel and speaker normalisation by a running spectral mean (cepstral mean subtraction:
// Atal 1974; on the log spectrum it is the same operation, since the cepstrum is its linear
// transform). A microphone, a room or a telephone line multiplies every frame's spectrum by the
// same response, a constant added to the log spectrum, which the mean removes; so does part of a
// speaker's own tilt. The mean starts at the training speech's mean (a MAP estimate with that
// prior), so a one-word clip is barely moved while a long show converges on its own channel.
#include <algorithm>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
// Only speech moves the mean: frames this far below the recent peak are pauses and closures.
constexpr float kSpeechBelowPeakDb = 30;
}  // namespace

SpectrumNormaliser::SpectrumNormaliser(const AnalysisConfig& config)
    : mean_(config.spectrumMean),
      weight_(config.meanPriorSeconds / config.hopSeconds),
      maxWeight_(config.meanMemorySeconds / config.hopSeconds),
      peakDecayDb_(static_cast<float>(config.levelPeakDecayDbPerSecond * config.hopSeconds)) {}

void SpectrumNormaliser::apply(FrameFeatures& frame) {
    const auto bins = mean_.size();
    if (!frame.valid) return;  // a flat spectrum: nothing to normalise, nothing to learn
    peakDb_ = std::max(frame.energyDb, peakDb_ - peakDecayDb_);
    if (frame.energyDb >= peakDb_ - kSpeechBelowPeakDb) {
        weight_ = std::min(weight_ + 1, maxWeight_);
        const auto rate = static_cast<float>(1 / weight_);
        for (std::size_t b = 0; b < bins; ++b) mean_[b] += rate * (frame.spectrum[b] - mean_[b]);
    }
    for (std::size_t b = 0; b < bins; ++b) frame.spectrum[b] -= mean_[b];
}

}  // namespace lipsyncd::dsp
