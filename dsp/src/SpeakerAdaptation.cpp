// A speaker's own class means from frames whose classes are known: the MAP estimate of each
// template (Gauvain & Lee 1994, section III), the base template weighted as τ frames.
#include <algorithm>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <utility>

#include "TemplateMatrix.hpp"

namespace lipsyncd::dsp {

SpeakerAdaptation::SpeakerAdaptation(TemplateSet base)
    : base_(std::move(base)), weighting_(std::make_shared<const FeatureWeighting>(base_)) {
    const std::size_t features = weighting_->features();
    std::vector<float> x(features);
    for (const auto& cls : base_.classes) {
        classStart_.push_back(counts_.size());
        const std::size_t at = weighted_.size(), count = cls.spectra.size();
        weighted_.resize(at + count * features);
        for (std::size_t t = 0; t < count; ++t) {
            weighting_->transform(cls.spectra[t], x);
            for (std::size_t k = 0; k < features; ++k) weighted_[at + k * count + t] = x[k];
            counts_.push_back(0.0);
        }
    }
    classStart_.push_back(counts_.size());
    sums_.assign(counts_.size() * features, 0.0);
}

// The template of class `cls` nearest to the weighted frame x (the first of equal distances).
// Each template's sum is formed in double, feature after feature, as one template at a time
// would form it; the loop over the class's templates is the one that runs side by side.
std::size_t SpeakerAdaptation::nearestOfClass(std::span<const float> x, std::size_t cls,
                                              std::vector<double>& distances) const {
    const std::size_t first = classStart_[cls], count = classStart_[cls + 1] - first;
    const float* w = &weighted_[first * x.size()];
    distances.assign(count, 0.0);
    double* d = distances.data();
    for (std::size_t k = 0; k < x.size(); ++k) {
        const double xk = x[k];
        const float* row = w + k * count;
        for (std::size_t t = 0; t < count; ++t) {
            const double e = xk - row[t];
            d[t] += e * e;
        }
    }
    std::size_t best = first;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < count; ++t)
        if (d[t] < bestDistance) bestDistance = d[t], best = first + t;
    return best;
}

void SpeakerAdaptation::add(std::span<const FrameFeatures> frames, const PhonemeSchedule& segments,
                            std::span<const std::uint8_t> silent) {
    const std::size_t features = weighting_->features();
    std::vector<float> x(features);
    std::vector<double> distances;
    std::size_t f = 0;
    for (const auto& seg : segments) {
        const auto cls = std::find_if(base_.classes.begin(), base_.classes.end(),
                                      [&](const auto& c) { return c.phoneme == seg.phoneme; });
        while (f < frames.size() && frames[f].time < seg.start) ++f;
        std::size_t end = f;
        while (end < frames.size() && frames[end].time < seg.end) ++end;
        if (seg.phoneme == "sil" || cls == base_.classes.end() || end < f + 3) continue;
        const auto c = static_cast<std::size_t>(cls - base_.classes.begin());
        // The edge frames straddle two sounds.
        for (std::size_t i = f + 1; i + 1 < end; ++i) {
            const auto& frame = frames[i];
            if (!frame.valid || frame.spectrum.size() != features) continue;
            if (i < silent.size() && silent[i]) continue;
            weighting_->transform(frame.spectrum, x);
            const std::size_t best = nearestOfClass(x, c, distances);
            double* sum = &sums_[best * features];
            for (std::size_t k = 0; k < features; ++k) sum[k] += frame.spectrum[k];
            counts_[best] += 1;
            ++frames_;
        }
    }
    trainNetworks(frames, segments);
}

SpeakerAdaptation carriedVoice(TemplateSet base, const AlignerConfig& config) {
    SpeakerAdaptation voice(std::move(base));
    voice.learnNetworks(config.speakerNetworkEpochs, config.speakerNetworkRate);
    return voice;
}

void SpeakerAdaptation::learnNetworks(int epochs, float rate) {
    networkEpochs_ = std::max(0, epochs);
    networkRate_ = rate;
}

void SpeakerAdaptation::trainNetworks(std::span<const FrameFeatures> frames,
                                      const PhonemeSchedule& segments) {
    if (networkEpochs_ == 0 || (!base_.jawNetwork && !base_.classNetwork)) return;
    TemplateTrainer trainer(fineTuningOptions(base_), PhonemeSet::common());
    trainer.addUtterance(frames, segments);
    if (trainer.networkFrames() == 0) return;
    TemplateSet current;
    current.analysis = base_.analysis;
    current.jawNetwork = jawNetwork_ ? jawNetwork_ : base_.jawNetwork;
    current.classNetwork = classNetwork_ ? classNetwork_ : base_.classNetwork;
    auto tuned = trainer.fineTuneNetworks(std::move(current), networkEpochs_, networkRate_);
    jawNetwork_ = std::move(tuned.jawNetwork);
    classNetwork_ = std::move(tuned.classNetwork);
}

void SpeakerAdaptation::add(const SpeakerAdaptation& other) {
    if (other.sums_.size() != sums_.size()) return;  // another base set: nothing in common
    for (std::size_t i = 0; i < sums_.size(); ++i) sums_[i] += other.sums_[i];
    for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
    frames_ += other.frames_;
    // Networks cannot be summed: a set that has trained none takes the other's.
    if (!classNetwork_ && !jawNetwork_) {
        classNetwork_ = other.classNetwork_;
        jawNetwork_ = other.jawNetwork_;
    }
}

TemplateSet SpeakerAdaptation::adapted(float priorFrames) const {
    TemplateSet out = base_;
    const std::size_t features = weighting_->features();
    const double tau = std::max(0.0f, priorFrames);
    std::size_t t = 0;
    for (auto& cls : out.classes)
        for (auto& spectrum : cls.spectra) {
            const double n = counts_[t];
            if (n > 0)
                for (std::size_t k = 0; k < spectrum.size() && k < features; ++k)
                    spectrum[k] = static_cast<float>((tau * spectrum[k] + sums_[t * features + k]) /
                                                     (tau + n));
            ++t;
        }
    if (classNetwork_) out.classNetwork = classNetwork_;
    if (jawNetwork_) out.jawNetwork = jawNetwork_;
    return out;
}

std::optional<TemplateSet> SpeakerAdaptation::adaptedIfHeard(float priorFrames) const {
    if (frames_ == 0) return std::nullopt;
    return adapted(priorFrames);
}

}  // namespace lipsyncd::dsp
