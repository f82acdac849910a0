// Per-frame classification (Lewis: "classifying each speech frame by minimum Euclidean distance
// of its short-term spectrum to the spectra of a set of phonemes"), with the distance weighted
// per bin by inverse variance (Tohkura 1987; shared/notes/dsp.md), an energy gate over an
// adaptive noise floor for silence, and voicing from the normalised prediction error (Lewis:
// "normalized errors greater than about 0.1 typically reflect consonants").
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <lipsyncd/dsp.hpp>

namespace lipsyncd::dsp {

namespace {
// The floor never rises above this: loud steady noise must not gate out speech entirely.
constexpr float kMaxNoiseFloorDb = -35.0f;
constexpr float kInitialNoiseFloorDb = -70.0f;
}  // namespace

FrameClassifier::FrameClassifier(const TemplateSet& templates, const PhonemeSet& set,
                                 const ClassifierConfig& config)
    : set_(&set), config_(config) {
    // Σ w·(x−t)² = Σ (√w·x − √w·t)²: templates are stored scaled by √w, in one flat matrix
    // with rows padded to a multiple of 8, so a frame costs one scaling and one pass.
    features_ = templates.binWeights.size();
    width_ = (features_ + 7) / 8 * 8;
    scale_.assign(width_, 0.0f);
    for (std::size_t b = 0; b < features_; ++b) scale_[b] = std::sqrt(templates.binWeights[b]);
    for (const auto& c : templates.classes) {
        const auto idx = set.find(c.phoneme);
        if (!idx)
            throw InputError("templates: class '" + c.phoneme + "' is not in the phoneme set");
        for (const auto& t : c.spectra) {
            rowClass_.push_back(static_cast<int>(*idx));
            for (std::size_t b = 0; b < width_; ++b)
                matrix_.push_back(b < features_ ? t[b] * scale_[b] : 0.0f);
        }
    }
    scaledFrame_.assign(width_, 0.0f);
    rowDistances_.assign(rowClass_.size(), 0.0f);
    distances_.assign(set.size(), std::numeric_limits<float>::infinity());
    sil_ = static_cast<int>(set.silence());
    reset();
}

void FrameClassifier::reset() {
    noiseFloorDb_ = kInitialNoiseFloorDb;
    peakDb_ = -120;
    floorInitialised_ = false;
    lastTime_ = 0;
}

namespace {
// Squared distance from x to every row of a matrix (rows of `width` floats, a multiple of 8),
// in eight interleaved partial sums so the loop vectorises; on x86-64 also built for AVX2 and
// picked at load time (the whole loop, so the per-row work stays inlined).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void squaredDistances(const float* x, const float* matrix, std::size_t rows, std::size_t width,
                      float* out) {
    for (std::size_t row = 0; row < rows; ++row, matrix += width) {
        std::array<float, 8> acc{};
        for (std::size_t i = 0; i < width; i += 8)
            for (std::size_t k = 0; k < 8; ++k) {
                const float d = x[i + k] - matrix[i + k];
                acc[k] += d * d;
            }
        out[row] =
            ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
    }
}
}  // namespace

FrameLabel FrameClassifier::classify(const FrameFeatures& frame) {
    FrameLabel label;
    label.time = frame.time;
    label.energyDb = frame.energyDb;
    label.voiced = frame.valid && frame.normalizedError < config_.voicingThreshold;

    // Noise floor: follows quiet frames down at once, creeps up slowly during sound.
    const double dt = floorInitialised_ ? std::max(0.0, frame.time - lastTime_) : 0.0;
    lastTime_ = frame.time;
    // A first frame quiet enough to be the room starts the floor; a loud one is speech already
    // and leaves the floor where it starts.
    if (!floorInitialised_ && frame.energyDb <= config_.maxStartFloorDb)
        noiseFloorDb_ = frame.energyDb;
    floorInitialised_ = true;
    if (frame.energyDb < noiseFloorDb_)
        noiseFloorDb_ = frame.energyDb;
    else
        noiseFloorDb_ =
            std::min(kMaxNoiseFloorDb,
                     noiseFloorDb_ + config_.noiseFloorRiseDbPerSecond * static_cast<float>(dt));
    label.noiseFloorDb = noiseFloorDb_;
    float gate = std::max(config_.absoluteSilenceDb, noiseFloorDb_ + config_.silenceMarginDb);
    if (config_.silenceBelowPeakDb > 0) {
        peakDb_ = std::max(frame.energyDb,
                           peakDb_ - config_.peakDecayDbPerSecond * static_cast<float>(dt));
        gate = std::max(gate, peakDb_ - config_.silenceBelowPeakDb);
    }

    // Distances: weighted RMS difference in dB to the nearest template of each class.
    std::fill(distances_.begin(), distances_.end(), std::numeric_limits<float>::infinity());
    if (!frame.valid) {  // digital silence or a degenerate frame: nothing to compare
        label.phoneme = label.runnerUp = sil_;
        label.distance = label.runnerUpDistance = 0;
        label.confidence = 1;
        label.silent = true;
        return label;
    }
    for (std::size_t b = 0; b < features_; ++b) scaledFrame_[b] = frame.spectrum[b] * scale_[b];
    squaredDistances(scaledFrame_.data(), matrix_.data(), rowClass_.size(), width_,
                     rowDistances_.data());
    for (std::size_t row = 0; row < rowClass_.size(); ++row) {
        float& slot = distances_[static_cast<std::size_t>(rowClass_[row])];
        slot = std::min(slot, rowDistances_[row]);
    }
    for (auto& d : distances_)  // weighted RMS difference, in dB
        if (std::isfinite(d)) d = std::sqrt(d / static_cast<float>(features_));

    const int sil = sil_;
    int first = -1, second = -1;
    for (int i = 0; i < static_cast<int>(distances_.size()); ++i) {
        if (!std::isfinite(distances_[i])) continue;
        if (first < 0 || distances_[i] < distances_[first]) {
            second = first;
            first = i;
        } else if (second < 0 || distances_[i] < distances_[second]) {
            second = i;
        }
    }
    if (first < 0) first = sil;
    if (second < 0) second = first;
    label.phoneme = first;
    label.runnerUp = second;
    label.distance = distances_[first];
    label.runnerUpDistance = distances_[second];
    const float margin = label.runnerUpDistance - label.distance;
    label.confidence = std::isfinite(margin) && label.runnerUpDistance > 0
                           ? std::clamp(margin / label.runnerUpDistance, 0.0f, 1.0f)
                           : 0.0f;

    label.silent = !frame.valid || frame.energyDb < gate;
    if (label.silent) {
        label.runnerUp = label.phoneme;
        label.runnerUpDistance = label.distance;
        label.phoneme = sil;
        // Sure when far below the gate, unsure near it.
        label.confidence =
            std::clamp((gate - frame.energyDb) / config_.silenceMarginDb, 0.0f, 1.0f);
    }
    return label;
}

}  // namespace lipsyncd::dsp
