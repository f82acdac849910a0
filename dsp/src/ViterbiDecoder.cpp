// Viterbi decoding over phoneme classes (notes/dsp.md: "HMM/Viterbi decoding over template
// classes with duration penalties is the principled version" of a minimum hold). Each class is
// a left-to-right chain of minFrames states, the last with a self loop, so no run is shorter
// than the class's minimum; class changes cost −log P(to | from) from the transition model plus
// a switch penalty (a phone loop's insertion penalty). Fixed lag: frame t − L is decided at
// frame t by tracing back from the best state at t; offline: one trace back at the end.
#include <algorithm>
#include <cmath>
#include <limits>
#include <lipsyncd/dsp.hpp>
#include <string_view>

#include "ClassEntry.hpp"

namespace lipsyncd::dsp {

namespace {
constexpr float kUnreachable = 1e9f;
}

ViterbiDecoder::ViterbiDecoder(const TransitionModel& model, const PhonemeSet& set,
                               double hopSeconds, const DecoderConfig& config)
    : classes_(set.size()), config_(config), hop_(hopSeconds) {
    model.validate("transition model");
    sil_ = static_cast<int>(set.silence());
    lag_ =
        config.lagSeconds < 0 ? -1 : static_cast<int>(std::lround(config.lagSeconds / hopSeconds));
    // Model rows and columns by phoneme set index; classes the model lacks are reachable from
    // everywhere with the uniform probability and last one frame.
    std::vector<int> modelIndex(classes_, -1);
    for (std::size_t m = 0; m < model.classes.size(); ++m)
        if (const auto idx = set.find(model.classes[m])) modelIndex[*idx] = static_cast<int>(m);
    const float uniform = -std::log(static_cast<float>(std::max<std::size_t>(classes_ - 1, 1)));
    stride_ = (classes_ + 7) / 8 * 8;
    transition_.assign(classes_ * stride_, kUnreachable);
    for (std::size_t from = 0; from < classes_; ++from)
        for (std::size_t to = 0; to < classes_; ++to) {
            if (from == to) continue;
            const int mf = modelIndex[from], mt = modelIndex[to];
            const float logP = mf >= 0 && mt >= 0 ? model.logProb[mf][mt] : uniform;
            transition_[from * stride_ + to] =
                -config.transitionWeight * logP + config.switchPenalty;
        }
    for (std::size_t c = 0; c < classes_; ++c) {
        const int n = modelIndex[c] >= 0 ? std::max(1, model.minFrames[modelIndex[c]]) : 1;
        firstState_.push_back(static_cast<int>(stateClass_.size()));
        for (int k = 0; k < n; ++k) stateClass_.push_back(static_cast<int>(c));
        lastState_.push_back(static_cast<int>(stateClass_.size()) - 1);
    }
    states_ = stateClass_.size();
    if (!(config.groupSpreadDb > 0))
        throw InputError("decoder: the group spread must be above 0 dB");
    std::vector<std::string_view> groups;  // speech groups, in first-seen order
    classGroup_.assign(classes_, -1);
    for (std::size_t c = 0; c < classes_; ++c) {
        if (static_cast<int>(c) == sil_) continue;
        auto at = std::find(groups.begin(), groups.end(), set[c].group);
        if (at == groups.end()) at = groups.insert(groups.end(), set[c].group);
        classGroup_[c] = static_cast<int>(at - groups.begin());
    }
    groupMass_.assign(groups.size(), 0.0f);
    score_.assign(states_, kUnreachable);
    next_.assign(states_, kUnreachable);
    emission_.assign(classes_, 0.0f);
    exitScore_.assign(classes_, kUnreachable);
    enter_.assign(stride_, kUnreachable);
    entryFrom_.assign(stride_, -1);
    if (lag_ >= 0) {
        back_.assign(static_cast<std::size_t>(lag_ + 1) * states_, 0);
        pending_.reserve(static_cast<std::size_t>(lag_) + 2);
        out_.reserve(static_cast<std::size_t>(lag_) + 2);
    }
}

double ViterbiDecoder::delaySeconds() const {
    return lag_ > 0 ? lag_ * hop_ : 0.0;
}

void ViterbiDecoder::step(const FrameLabel& label, std::span<const float> distances) {
    // Emission costs: distance above the best class, in scaled dB; the energy gate is a strong
    // but not absolute vote for silence.
    float best = std::numeric_limits<float>::infinity();
    for (std::size_t c = 0; c < classes_; ++c)
        if (static_cast<int>(c) != sil_ && c < distances.size())
            best = std::min(best, distances[c]);
    for (std::size_t c = 0; c < classes_; ++c) {
        const float d =
            c < distances.size() ? distances[c] : std::numeric_limits<float>::infinity();
        const float above =
            std::isfinite(d) && std::isfinite(best) ? (d - best) * config_.distanceScale : 0.0f;
        if (static_cast<int>(c) == sil_)
            emission_[c] = label.silent ? 0.0f : config_.silenceCost + std::max(0.0f, above);
        else if (!std::isfinite(d) && std::isfinite(best))
            emission_[c] = kUnreachable;
        else
            emission_[c] = above + (label.silent ? config_.gatedSpeechPenalty : 0.0f);
    }

    addGroupCosts(distances, best);

    const std::size_t slot = lag_ >= 0 ? frames_ % static_cast<std::size_t>(lag_ + 1) : frames_;
    if (lag_ < 0) back_.resize((frames_ + 1) * states_);
    std::uint16_t* back = back_.data() + slot * states_;
    if (frames_ == 0) {
        std::fill(next_.begin(), next_.end(), kUnreachable);
        for (std::size_t c = 0; c < classes_; ++c) next_[firstState_[c]] = emission_[c];
        std::fill(back, back + states_, std::uint16_t{0});
    } else {
        for (std::size_t j = 0; j < classes_; ++j) exitScore_[j] = score_[lastState_[j]];
        // Entering each class: from the last state of the best other class.
        bestEntries(exitScore_.data(), transition_.data(), classes_, stride_, kUnreachable,
                    enter_.data(), entryFrom_.data());
        for (std::size_t c = 0; c < classes_; ++c) {
            const float enter = enter_[c];
            const int from = entryFrom_[c] >= 0 ? lastState_[entryFrom_[c]] : lastState_[c];
            const int first = firstState_[c], last = lastState_[c];
            for (int s = last; s > first; --s) {  // along the chain
                float stay = score_[s - 1];
                int before = s - 1;
                if (s == last && score_[s] < stay) stay = score_[s], before = s;
                next_[s] = stay + emission_[c];
                back[s] = static_cast<std::uint16_t>(before);
            }
            float firstScore = enter;
            int before = from;
            if (first == last && score_[first] < firstScore)
                firstScore = score_[first], before = first;
            next_[first] = firstScore + emission_[c];
            back[first] = static_cast<std::uint16_t>(before);
        }
    }
    // Keep the numbers small over hours of input.
    const float low = *std::min_element(next_.begin(), next_.end());
    for (std::size_t s = 0; s < states_; ++s) score_[s] = std::min(next_[s] - low, kUnreachable);
    ++frames_;
}

// Robust decisions before fine ones: the visual group a frame most likely shows is decided by
// all of its classes together, not by its single nearest class. A group's share of the frame is
// Σ exp(−(d − d_best) / spread) over its classes (d in dB; the class network's nats count 1 dB
// each, ClassifierConfig::classNetworkDb), and every speech class pays share · spread ·
// ln(top share / its group's share): nothing in the likeliest group. Silence keeps the energy
// gate's vote alone.
void ViterbiDecoder::addGroupCosts(std::span<const float> distances, float best) {
    if (!(config_.groupShare > 0) || groupMass_.empty() || !std::isfinite(best)) return;
    std::fill(groupMass_.begin(), groupMass_.end(), 0.0f);
    for (std::size_t c = 0; c < classes_ && c < distances.size(); ++c)
        if (classGroup_[c] >= 0 && std::isfinite(distances[c]))
            groupMass_[classGroup_[c]] += std::exp(-(distances[c] - best) / config_.groupSpreadDb);
    const float top = *std::max_element(groupMass_.begin(), groupMass_.end());
    const float scale = config_.groupShare * config_.groupSpreadDb * config_.distanceScale;
    for (float& m : groupMass_)  // now each group's cost: a logarithm per group, not per class
        m = m > 0 ? scale * std::log(top / m) : 0.0f;
    for (std::size_t c = 0; c < classes_; ++c)
        if (classGroup_[c] >= 0 && emission_[c] < kUnreachable)
            emission_[c] += groupMass_[classGroup_[c]];
}

// The state at frame (frames_ − 1 − frameOffset) on the best path ending now.
int ViterbiDecoder::backtrack(std::size_t frameOffset) const {
    int s = static_cast<int>(std::min_element(score_.begin(), score_.end()) - score_.begin());
    const std::size_t ring = lag_ >= 0 ? static_cast<std::size_t>(lag_ + 1) : 0;
    for (std::size_t k = 0; k < frameOffset; ++k) {
        const std::size_t frame = frames_ - 1 - k;
        const std::size_t slot = ring ? frame % ring : frame;
        s = back_[slot * states_ + static_cast<std::size_t>(s)];
    }
    return s;
}

namespace {
FrameLabel decided(FrameLabel label, int phoneme, int sil) {
    if (label.phoneme != phoneme) {
        label.runnerUp = label.phoneme;
        label.confidence *= 0.5f;
        label.phoneme = phoneme;
    }
    label.silent = phoneme == sil;
    return label;
}
}  // namespace

std::span<const FrameLabel> ViterbiDecoder::push(const FrameLabel& label,
                                                 std::span<const float> distances) {
    out_.clear();
    step(label, distances);
    pending_.push_back(label);
    if (lag_ >= 0 && frames_ > static_cast<std::size_t>(lag_)) {
        const int s = backtrack(static_cast<std::size_t>(lag_));
        out_.push_back(decided(pending_.front(), stateClass_[s], sil_));
        pending_.erase(pending_.begin());
        ++decided_;
    }
    return out_;
}

void ViterbiDecoder::decideUpTo(std::size_t end, int lastState) {
    // Trace back from lastState at frame end − 1 over every pending frame.
    const std::size_t n = end - decided_;
    const std::size_t ring = lag_ >= 0 ? static_cast<std::size_t>(lag_ + 1) : 0;
    out_.resize(n);
    int s = lastState;
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t frame = end - 1 - k;
        out_[n - 1 - k] = decided(pending_[n - 1 - k], stateClass_[s], sil_);
        const std::size_t slot = ring ? frame % ring : frame;
        s = back_[slot * states_ + static_cast<std::size_t>(s)];
    }
    pending_.clear();
    decided_ = end;
}

std::span<const FrameLabel> ViterbiDecoder::finish() {
    out_.clear();
    if (frames_ > decided_)
        decideUpTo(frames_, static_cast<int>(std::min_element(score_.begin(), score_.end()) -
                                             score_.begin()));
    return out_;
}

}  // namespace lipsyncd::dsp
