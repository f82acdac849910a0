// Template training: cluster means per class (paper 001, section 4, applied to LPC spectra).
#include <algorithm>
#include <cmath>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <numeric>
#include <random>

#include "Whitening.hpp"

namespace lipsyncd::dsp {

namespace {
using Spectrum = std::vector<float>;

float squaredDistance(const Spectrum& a, const Spectrum& b) {
    float acc = 0;
    for (std::size_t i = 0; i < a.size(); ++i) acc += (a[i] - b[i]) * (a[i] - b[i]);
    return acc;
}

Spectrum mean(const std::vector<const Spectrum*>& members, std::size_t bins) {
    Spectrum m(bins, 0.0f);
    for (const auto* s : members)
        for (std::size_t b = 0; b < bins; ++b) m[b] += (*s)[b];
    for (auto& v : m) v /= static_cast<float>(std::max<std::size_t>(1, members.size()));
    return m;
}

// k-means with k-means++ seeding from a fixed seed: the same frames give the same templates.
std::vector<Spectrum> kMeans(const std::vector<Spectrum>& points, int k, std::uint32_t seed) {
    const std::size_t bins = points.front().size();
    std::mt19937 rng(seed);
    std::vector<Spectrum> centres{
        points[std::uniform_int_distribution<std::size_t>(0, points.size() - 1)(rng)]};
    std::vector<float> nearest(points.size());
    while (static_cast<int>(centres.size()) < k) {
        for (std::size_t i = 0; i < points.size(); ++i) {
            nearest[i] = std::numeric_limits<float>::max();
            for (const auto& c : centres)
                nearest[i] = std::min(nearest[i], squaredDistance(points[i], c));
        }
        std::discrete_distribution<std::size_t> pick(nearest.begin(), nearest.end());
        centres.push_back(points[pick(rng)]);
    }
    std::vector<int> assignment(points.size(), -1);
    for (int iteration = 0; iteration < 30; ++iteration) {
        bool changed = false;
        for (std::size_t i = 0; i < points.size(); ++i) {
            int best = 0;
            for (int c = 1; c < k; ++c)
                if (squaredDistance(points[i], centres[c]) <
                    squaredDistance(points[i], centres[best]))
                    best = c;
            changed |= assignment[i] != best;
            assignment[i] = best;
        }
        if (!changed) break;
        for (int c = 0; c < k; ++c) {
            std::vector<const Spectrum*> members;
            for (std::size_t i = 0; i < points.size(); ++i)
                if (assignment[i] == c) members.push_back(&points[i]);
            if (!members.empty()) centres[c] = mean(members, bins);
        }
    }
    return centres;
}
}  // namespace

TemplateTrainer::TemplateTrainer(const TrainingOptions& options, const PhonemeSet& set)
    : options_(options), set_(&set), spectra_(set.size()) {
    options_.analysis.validate();
}

// A segment labelled with confidence 0 teaches nothing: the labeller marks what it doubts (a
// class its aligner places badly in some recordings), and those frames are left out of the
// templates and the networks alike.
namespace {
bool taught(const PhonemeSegment& label) {
    return label.confidence > 0;
}
}  // namespace

void TemplateTrainer::addFrame(const FrameFeatures& frame, std::size_t phoneme) {
    spectra_[phoneme].push_back(frame.spectrum);
}

void TemplateTrainer::addUtterance(std::span<const FrameFeatures> frames,
                                   const PhonemeSchedule& labels) {
    float peak = -120;
    for (const auto& f : frames) peak = std::max(peak, f.energyDb);
    if (options_.jawHiddenUnits > 0 || options_.classHiddenUnits > 0)
        addNetworkFrames(frames, labels, peak);
    std::size_t seg = 0;
    for (const auto& f : frames) {
        while (seg < labels.size() && labels[seg].end <= f.time) ++seg;
        if (seg >= labels.size()) break;
        const auto& label = labels[seg];
        if (f.time < label.start) continue;
        const double margin = options_.boundaryMarginSeconds;
        // Transitions belong to neither neighbour; keep frames well inside a segment (short
        // segments keep their middle frame).
        const bool inside = f.time - label.start >= margin && label.end - f.time >= margin;
        const bool middle = std::abs(f.time - 0.5 * (label.start + label.end)) <=
                            0.5 * options_.analysis.hopSeconds;
        if (!inside && !middle) continue;
        if (!f.valid || f.energyDb < peak - options_.maxBelowPeakDb || !taught(label)) continue;
        if (const auto cls = set_->find(label.phoneme)) addFrame(f, *cls);
    }
}

// The networks learn from every frame of speech, transitions included (the jaw moves through
// them too, and the aligner weighs every frame). The jaw network's target is what `lipsync
// eval` scores a jaw on: each frame's phoneme jaw height, averaged over the frames within 20 ms
// (lipsync::JawScoreConfig::smoothingSeconds); the class network's is the frame's own class.
void TemplateTrainer::addNetworkFrames(std::span<const FrameFeatures> frames,
                                       const PhonemeSchedule& labels, float peak) {
    std::vector<float> height(frames.size(), 0.0f);
    std::vector<int> cls(frames.size(), static_cast<int>(set_->silence()));
    std::size_t seg = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        while (seg < labels.size() && labels[seg].end <= frames[i].time) ++seg;
        if (seg >= labels.size() || frames[i].time < labels[seg].start) continue;  // silence
        const auto c = set_->find(labels[seg].phoneme);
        if (!c) {
            cls[i] = -1;
            continue;
        }
        cls[i] = taught(labels[seg]) ? static_cast<int>(*c) : -1;  // its height still counts
        if (const auto jaw = (*set_)[*c].jaw)
            height[i] = *jaw;
        else
            jawUsable_ = false;  // a set without jaw heights: no jaw network
    }
    const auto half = static_cast<std::size_t>(std::lround(0.02 / options_.analysis.hopSeconds));
    // Each network's inputs run over every frame in order, as the classifier's do
    // (FrameClassifier); a row is kept per frame the networks learn from.
    const auto features = static_cast<std::size_t>(options_.analysis.featureCount());
    std::map<int, NetworkInput> heard;
    if (options_.jawHiddenUnits > 0) heard.try_emplace(options_.jawSlopeFrames);
    if (options_.classHiddenUnits > 0) heard.try_emplace(options_.classSlopeFrames);
    for (auto& [slopeFrames, input] : heard) input = NetworkInput(slopeFrames, features);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const auto& f = frames[i];
        if (f.spectrum.size() != features)
            throw InputError("training: a frame of " + std::to_string(f.spectrum.size()) +
                             " features where the analysis makes " + std::to_string(features));
        const bool learnt = f.valid && f.energyDb >= peak - options_.maxBelowPeakDb && cls[i] >= 0;
        for (auto& [slopeFrames, input] : heard) {
            const auto row = input.push(f.spectrum);
            auto& rows = inputs_[slopeFrames];
            if (learnt) rows.insert(rows.end(), row.begin(), row.end());
        }
        if (!learnt) continue;
        const std::size_t lo = i > half ? i - half : 0, hi = std::min(frames.size(), i + half + 1);
        float sum = 0;
        for (std::size_t k = lo; k < hi; ++k) sum += height[k];
        jawTargets_.push_back(sum / static_cast<float>(hi - lo));
        classTargets_.push_back(static_cast<std::uint16_t>(cls[i]));
    }
}

const std::vector<float>& TemplateTrainer::inputsWith(int slopeFrames) const {
    static const std::vector<float> none;
    const auto found = inputs_.find(slopeFrames);
    return found == inputs_.end() ? none : found->second;
}

void TemplateTrainer::addSustained(std::span<const FrameFeatures> frames,
                                   const std::string& phoneme) {
    const auto cls = set_->find(phoneme);
    if (!cls) throw InputError("'" + phoneme + "' is not a phoneme class");
    float peak = -120;
    for (const auto& f : frames) peak = std::max(peak, f.energyDb);
    for (const auto& f : frames)
        if (f.valid && f.energyDb >= peak - 20) addFrame(f, *cls);  // the held part, not the fades
}

std::size_t TemplateTrainer::frames(const std::string& phoneme) const {
    const auto cls = set_->find(phoneme);
    return cls ? spectra_[*cls].size() : 0;
}

// Over the classes with frames (a class never heard cannot be told apart): their names in set
// order, and every frame's label re-indexed to them.
std::optional<ClassNetwork> TemplateTrainer::trainClasses(std::size_t bins) const {
    std::vector<int> index(set_->size(), -1);
    std::vector<std::string> names;
    for (auto c : classTargets_) index[c] = 0;
    for (std::size_t c = 0; c < set_->size(); ++c)
        if (index[c] == 0) {
            index[c] = static_cast<int>(names.size());
            names.push_back((*set_)[c].name);
        }
    if (names.size() < 2) return std::nullopt;
    std::vector<std::uint16_t> labels;
    labels.reserve(classTargets_.size());
    for (auto c : classTargets_) labels.push_back(static_cast<std::uint16_t>(index[c]));
    const int slopeFrames = options_.classSlopeFrames;
    auto net =
        trainClassNetwork(inputsWith(slopeFrames), labels, names, networkInputs(bins, slopeFrames),
                          options_.classHiddenUnits, options_.classEpochs, options_.seed);
    net.slopeFrames = slopeFrames;
    return net;
}

TrainingOptions fineTuningOptions(const TemplateSet& set) {
    TrainingOptions training;
    training.analysis = set.analysis;
    training.jawHiddenUnits = set.jawNetwork ? int(set.jawNetwork->hiddenUnits()) : 0;
    training.classHiddenUnits = set.classNetwork ? int(set.classNetwork->hiddenUnits()) : 0;
    training.jawSlopeFrames = set.jawNetwork ? set.jawNetwork->slopeFrames : 0;
    training.classSlopeFrames = set.classNetwork ? set.classNetwork->slopeFrames : 0;
    return training;
}

// The frames kept for `net` (TrainingOptions as fineTuningOptions gives for the base): else the
// trainer was made for other networks.
template <class Network>
const std::vector<float>& TemplateTrainer::tuningInputs(const Network& net,
                                                        std::size_t features) const {
    const auto& rows = inputsWith(net.slopeFrames);
    if (classTargets_.empty() || rows.size() != classTargets_.size() * net.inputsFor(features))
        throw InputError(
            "fine-tuning: no frames of speech, or frames of another analysis or "
            "made for networks of other inputs");
    return rows;
}

TemplateSet TemplateTrainer::fineTuneNetworks(TemplateSet base, int epochs, float rate) const {
    const auto features = static_cast<std::size_t>(base.analysis.featureCount());
    if (base.jawNetwork && jawUsable_)
        base.jawNetwork =
            fineTuneJawNetwork(*base.jawNetwork, tuningInputs(*base.jawNetwork, features),
                               jawTargets_, epochs, rate, options_.seed);
    if (!base.classNetwork) return base;
    const auto& source = tuningInputs(*base.classNetwork, features);
    const std::size_t width = base.classNetwork->inputsFor(features);
    // Per class of the set, its output in the network (-1: none).
    std::vector<int> outputOf(set_->size(), -1);
    const auto indices = base.classNetwork->setIndices(*set_);
    for (std::size_t o = 0; o < indices.size(); ++o)
        if (indices[o] >= 0) outputOf[static_cast<std::size_t>(indices[o])] = int(o);
    std::vector<float> inputs;
    std::vector<std::uint16_t> labels;
    for (std::size_t row = 0; row < classTargets_.size(); ++row) {
        const int output = outputOf[classTargets_[row]];
        if (output < 0) continue;
        labels.push_back(static_cast<std::uint16_t>(output));
        const auto from = source.begin() + static_cast<std::ptrdiff_t>(row * width);
        inputs.insert(inputs.end(), from, from + static_cast<std::ptrdiff_t>(width));
    }
    if (!labels.empty())
        base.classNetwork =
            fineTuneClassNetwork(*base.classNetwork, inputs, labels, epochs, rate, options_.seed);
    return base;
}

TemplateSet TemplateTrainer::build(const std::string& description) const {
    TemplateSet t;
    t.analysis = options_.analysis;
    t.description = description;
    const auto bins = static_cast<std::size_t>(options_.analysis.featureCount());
    // Pooled within-class covariance (every bin pair, or only the diagonal: the per-bin
    // variances): bins where classes differ more than frames of one class scatter weigh more
    // (inverse variance; notes/dsp.md, Tohkura 1987).
    std::vector<double> covariance(bins * bins, 0.0);
    std::size_t pooled = 0;
    for (std::size_t c = 0; c < spectra_.size(); ++c) {
        const auto& frames = spectra_[c];
        if (frames.size() < options_.minFramesPerCluster) continue;
        std::vector<const Spectrum*> all;
        for (const auto& f : frames) all.push_back(&f);
        const auto m = mean(all, bins);
        for (const auto& f : frames)
            for (std::size_t i = 0; i < bins; ++i)
                for (std::size_t j = options_.fullCovariance ? 0 : i; j <= i; ++j)
                    covariance[i * bins + j] += (f[i] - m[i]) * (f[j] - m[j]);
        pooled += frames.size();

        TemplateSet::ClassTemplates cls;
        cls.phoneme = (*set_)[c].name;
        cls.frames = frames.size();
        const int k = static_cast<int>(
            std::clamp<std::size_t>(frames.size() / options_.minFramesPerCluster, 1,
                                    static_cast<std::size_t>(options_.clustersPerClass)));
        cls.spectra = kMeans(frames, k, options_.seed + static_cast<std::uint32_t>(c));
        t.classes.push_back(std::move(cls));
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, pooled));
    for (std::size_t i = 0; i < bins; ++i)
        for (std::size_t j = 0; j <= i; ++j)
            covariance[j * bins + i] = covariance[i * bins + j] /= n;
    if (t.classes.empty())
        throw InputError("training: no class has " + std::to_string(options_.minFramesPerCluster) +
                         " usable frames; give more (or longer) labelled audio");
    // Every variance at least 1 dB²: a feature that barely moves in training must not dominate.
    for (std::size_t b = 0; b < bins; ++b)
        covariance[b * bins + b] = std::max(covariance[b * bins + b], 1.0);
    double inverseSum = 0;
    for (std::size_t b = 0; b < bins; ++b) inverseSum += 1.0 / covariance[b * bins + b];
    t.binWeights.resize(bins);
    // Enough speech for a network to learn more than one voice's quirks: else none, and the
    // jaw comes from the class distances, the classes from the templates alone.
    constexpr std::size_t kMinNetworkFrames = 2000;
    const bool enough = jawTargets_.size() >= kMinNetworkFrames;
    if (options_.jawHiddenUnits > 0 && jawUsable_ && enough)
        t.jawNetwork = trainJawNetwork(inputsWith(options_.jawSlopeFrames), jawTargets_,
                                       networkInputs(bins, options_.jawSlopeFrames),
                                       options_.jawHiddenUnits, options_.jawEpochs, options_.seed);
    if (t.jawNetwork) t.jawNetwork->slopeFrames = options_.jawSlopeFrames;
    if (options_.classHiddenUnits > 0 && enough) t.classNetwork = trainClasses(bins);
    if (options_.fullCovariance) {
        // Scaled so that a frame's expected distance to its own class's mean is what the
        // per-bin weights give (the harmonic mean of the variances, in dB²): the decoder's and
        // the aligner's costs per dB keep their meaning.
        const double harmonicMean = static_cast<double>(bins) / inverseSum;
        t.whitening = whiteningFromCovariance(covariance, bins, std::sqrt(harmonicMean));
        std::fill(t.binWeights.begin(), t.binWeights.end(), 1.0f);
        return t;
    }
    double sum = 0;
    for (std::size_t b = 0; b < bins; ++b) {
        t.binWeights[b] = static_cast<float>(1.0 / covariance[b * bins + b]);
        sum += t.binWeights[b];
    }
    for (auto& w : t.binWeights) w = static_cast<float>(w * bins / sum);  // mean weight 1
    return t;
}

}  // namespace lipsyncd::dsp
