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

#include "TemplateMatrix.hpp"

namespace lipsyncd::dsp {

namespace {
// The floor never rises above this: loud steady noise must not gate out speech entirely.
constexpr float kMaxNoiseFloorDb = -35.0f;
constexpr float kInitialNoiseFloorDb = -70.0f;
}  // namespace

FrameClassifier::FrameClassifier(const TemplateSet& templates, const PhonemeSet& set,
                                 const ClassifierConfig& config)
    : set_(&set), config_(config), jawNetwork_(templates.jawNetwork) {
    const auto features = static_cast<std::size_t>(templates.analysis.featureCount());
    if (templates.classNetwork && config.classNetworkDb > 0) {
        classNetwork_ = templates.classNetwork;
        networkClass_ = classNetwork_->setIndices(set);
        likelihoods_.assign(networkClass_.size(), 0.0f);
        hiddenUnits_.assign(classNetwork_->hiddenUnits(), 0.0f);
        classInput_ = NetworkInput(classNetwork_->slopeFrames, features);
    }
    if (jawNetwork_) {
        jawHearsClassInput_ =
            classNetwork_ && classNetwork_->slopeFrames == jawNetwork_->slopeFrames;
        if (!jawHearsClassInput_) jawInput_ = NetworkInput(jawNetwork_->slopeFrames, features);
    }
    if (!templates.classBiasDb.empty()) {
        classBias_.assign(set.size(), 0.0f);
        for (const auto& [name, db] : templates.classBiasDb)
            if (const auto i = set.find(name)) classBias_[*i] = db;
    }
    // Terms added to the distances: the templates' own are kept apart for the aligner.
    if (classNetwork_ || !classBias_.empty())
        templateDistances_.assign(set.size(), std::numeric_limits<float>::infinity());
    matrix_ = std::make_shared<const TemplateMatrix>(templates, set);
    scaledFrame_.assign(matrix_->features(), 0.0f);
    distances_.assign(set.size(), std::numeric_limits<float>::infinity());
    sil_ = static_cast<int>(set.silence());
    for (std::size_t c = 0; c < set.size(); ++c) jawOf_.push_back(set[c].jaw.value_or(0.0f));
    reset();
}

void FrameClassifier::recordBlockDistances() {
    blockDistances_.assign(matrix_->blocks(), std::numeric_limits<float>::infinity());
}

void FrameClassifier::reset() {
    noiseFloorDb_ = kInitialNoiseFloorDb;
    peakDb_ = -120;
    floorInitialised_ = false;
    lastTime_ = 0;
    classInput_.reset();
    jawInput_.reset();
}

// Σ w_c·jaw_c / Σ w_c over the classes, w_c = exp(−(d_c − best) / spread): a soft decision,
// whose errors between classes of like height cost the jaw nothing (a posterior-weighted
// estimate instead of the arg-min; Bourlard & Morgan 1994 on distances as scores). Classes more
// than 12 spreads away weigh under 1e-5 and are skipped.
float FrameClassifier::expectedJaw(float best) const {
    const float spread = std::max(config_.jawSpreadDb, 1e-3f);
    float sum = 0, weighted = 0;
    for (std::size_t c = 0; c < distances_.size(); ++c) {
        const float z = (distances_[c] - best) / spread;
        if (!(z < 12)) continue;  // also +inf: a class without templates
        const float w = std::exp(-z);
        sum += w;
        weighted += w * jawOf_[c];
    }
    return sum > 0 ? weighted / sum : 0.0f;
}

// The hybrid's scaled likelihoods (Bourlard & Morgan 1994) as distance. Classes the network does
// not know keep their template distance.
void FrameClassifier::addClassNetwork(std::span<const float> input) {
    classNetwork_->addToDistances(input, networkClass_, config_.classNetworkDb,
                                  config_.classPriorScale, distances_, likelihoods_, hiddenUnits_);
}

// The set's per-class correction (TemplateSet::classBiasDb), after the network's term.
void FrameClassifier::addClassBias() {
    for (std::size_t c = 0; c < distances_.size(); ++c) distances_[c] += classBias_[c];
}

FrameLabel FrameClassifier::classify(const FrameFeatures& frame) {
    FrameLabel label;
    label.time = frame.time;
    label.energyDb = frame.energyDb;
    label.voiced = frame.valid && frame.normalizedError < config_.voicingThreshold;
    // Every frame, silent or not, moves the slopes on: as in training (TemplateTrainer).
    const auto classInput = classInput_.push(frame.spectrum);
    const auto jawInput = jawHearsClassInput_ ? classInput : jawInput_.push(frame.spectrum);

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
        // The templates' own distances (templateDistances()) too, not the last frame's.
        std::fill(templateDistances_.begin(), templateDistances_.end(),
                  std::numeric_limits<float>::infinity());
        std::fill(blockDistances_.begin(), blockDistances_.end(),
                  std::numeric_limits<float>::infinity());
        label.phoneme = label.runnerUp = sil_;
        label.distance = label.runnerUpDistance = 0;
        label.confidence = 1;
        label.silent = true;
        return label;
    }
    matrix_->transform(frame.spectrum, scaledFrame_);
    if (blockDistances_.empty())
        matrix_->nearest(scaledFrame_, distances_);
    else
        matrix_->nearest(scaledFrame_, distances_, blockDistances_);
    matrix_->toRms(distances_);  // weighted RMS difference, in dB

    if (!templateDistances_.empty())  // before the terms below: what the aligner weighs
        std::copy(distances_.begin(), distances_.end(), templateDistances_.begin());
    if (classNetwork_) addClassNetwork(classInput);
    if (!classBias_.empty()) addClassBias();

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
    if (!label.silent) {
        label.jaw = jawNetwork_ ? (*jawNetwork_)(jawInput) : expectedJaw(label.distance);
        return label;
    }
    label.runnerUp = label.phoneme;
    label.runnerUpDistance = label.distance;
    label.phoneme = sil;
    // Sure when far below the gate, unsure near it.
    label.confidence = std::clamp((gate - frame.energyDb) / config_.silenceMarginDb, 0.0f, 1.0f);
    return label;
}

}  // namespace lipsyncd::dsp
