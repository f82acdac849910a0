// A speaker's own class means from frames whose classes are known: the MAP estimate of each
// template (Gauvain & Lee 1994, section III), the base template weighted as τ frames.
#include <algorithm>
#include <limits>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
// The distance the classifier uses between a frame and a template: Σ w·(x − t)² under the
// per-feature weights, or ‖W(x − t)‖² under the set's whitening (lower triangular).
double distance(const TemplateSet& set, std::span<const float> x, std::span<const float> t) {
    const std::size_t n = std::min(x.size(), t.size());
    double sum = 0;
    if (set.whitening.empty()) {
        for (std::size_t i = 0; i < n; ++i) {
            const double d = static_cast<double>(x[i]) - t[i];
            sum += set.binWeights[i] * d * d;
        }
        return sum;
    }
    for (std::size_t r = 0; r < n; ++r) {
        double row = 0;
        for (std::size_t c = 0; c <= r; ++c)
            row += set.whitening[r][c] * (static_cast<double>(x[c]) - t[c]);
        sum += row * row;
    }
    return sum;
}
}  // namespace

SpeakerAdaptation::SpeakerAdaptation(TemplateSet base) : base_(std::move(base)) {
    for (std::size_t c = 0; c < base_.classes.size(); ++c)
        classOf_.insert(classOf_.end(), base_.classes[c].spectra.size(), c);
    sums_.assign(classOf_.size() * base_.analysis.featureCount(), 0.0);
    counts_.assign(classOf_.size(), 0.0);
}

void SpeakerAdaptation::add(std::span<const FrameFeatures> frames, const PhonemeSchedule& segments,
                            std::span<const std::uint8_t> silent) {
    const std::size_t features = base_.analysis.featureCount();
    std::size_t f = 0;
    for (const auto& seg : segments) {
        const auto cls = std::find_if(base_.classes.begin(), base_.classes.end(),
                                      [&](const auto& c) { return c.phoneme == seg.phoneme; });
        while (f < frames.size() && frames[f].time < seg.start) ++f;
        std::size_t end = f;
        while (end < frames.size() && frames[end].time < seg.end) ++end;
        if (seg.phoneme == "sil" || cls == base_.classes.end() || end < f + 3) continue;
        // The first template of the class in the flat arrays.
        const auto classIndex = static_cast<std::size_t>(cls - base_.classes.begin());
        const auto first = static_cast<std::size_t>(
            std::find(classOf_.begin(), classOf_.end(), classIndex) - classOf_.begin());
        for (std::size_t i = f + 1; i + 1 < end;
             ++i) {  // the edge frames straddle two sounds  // the edge frames straddle two sounds
            const auto& frame = frames[i];
            if (!frame.valid || frame.spectrum.size() != features) continue;
            if (i < silent.size() && silent[i]) continue;
            std::size_t best = 0;
            double bestDistance = std::numeric_limits<double>::infinity();
            for (std::size_t t = 0; t < cls->spectra.size(); ++t) {
                const double d = distance(base_, frame.spectrum, cls->spectra[t]);
                if (d < bestDistance) bestDistance = d, best = t;
            }
            double* sum = &sums_[(first + best) * features];
            for (std::size_t k = 0; k < features; ++k) sum[k] += frame.spectrum[k];
            counts_[first + best] += 1;
            ++frames_;
        }
    }
}

void SpeakerAdaptation::add(const SpeakerAdaptation& other) {
    if (other.sums_.size() != sums_.size()) return;  // another base set: nothing in common
    for (std::size_t i = 0; i < sums_.size(); ++i) sums_[i] += other.sums_[i];
    for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += other.counts_[i];
    frames_ += other.frames_;
}

TemplateSet SpeakerAdaptation::adapted(float priorFrames) const {
    TemplateSet out = base_;
    const std::size_t features = base_.analysis.featureCount();
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
    return out;
}

}  // namespace lipsyncd::dsp
