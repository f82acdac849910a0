#include "AlignmentPath.hpp"

#include <algorithm>
#include <cmath>

namespace lipsyncd::dsp {

namespace {
// Word confidence: the mean distance (dB) its frames lay above the nearest class's falls off
// over one scale, and a duration far from the expected one (log ratio) over another. On the
// espeak-ng training corpus, words aligned with their own text lay 0.3 dB (median) above, words
// forced onto another sentence's audio 1.5 dB; with these scales and a minimum confidence of
// 0.3, 2 % of right words and 12 % of wrong ones fall on the wrong side.
constexpr double kExcessScaleDb = 1.2;
constexpr double kLogDurationScale = 0.6;
}  // namespace

AlignmentPath::AlignmentPath(std::span<const ScriptWord> script, const AlignmentGraph& graph,
                             const PhonemeSet& set, double hopSeconds, const AlignerConfig& config)
    : graph_(&graph), set_(&set), hop_(hopSeconds), config_(config), words_(script.size()) {
    for (const auto& w : script) texts_.push_back(w.text);
}

void AlignmentPath::add(double time, int node, std::span<const float> excessDb) {
    const auto& n = graph_->nodes[node];
    const double start = std::max(0.0, time - hop_ / 2), end = time + hop_ / 2;
    const auto& current = run_.node >= 0 ? graph_->nodes[run_.node] : n;
    const bool same = run_.node >= 0 && current.kind == n.kind && current.word == n.word &&
                      current.phone == n.phone;
    if (!same) {
        // A run starts where the one before ended, to the bit: written with rounding, the two
        // times computed apart could overlap by a millisecond and not read back.
        const double from = run_.node >= 0 ? run_.end : start;
        closeRun();
        run_ = {node, from, end};
    }
    run_.end = end;
    if (n.kind == AlignmentNode::Kind::Phoneme) {
        auto& w = words_[n.word];
        if (w.frames == 0) w.start = start;
        w.end = end;
        w.excessDb += excessDb[n.phoneme];
        ++w.frames;
    }
}

void AlignmentPath::closeRun() {
    if (run_.node < 0) return;
    const auto& n = graph_->nodes[run_.node];
    const bool phoneme = n.kind == AlignmentNode::Kind::Phoneme;
    const std::string name = phoneme ? (*set_)[n.phoneme].name : (*set_)[set_->silence()].name;
    if (n.kind == AlignmentNode::Kind::Filler) out_.unexplained.emplace_back(run_.start, run_.end);
    out_.schedule.push_back({run_.start, run_.end, name, 1.0f});
    segmentWord_.push_back(phoneme ? n.word : -1);
    run_ = {};
}

float AlignmentPath::confidence(std::size_t word) const {
    const auto& w = words_[word];
    if (w.frames == 0) return 0;
    const double excess = w.excessDb / w.frames;
    const double ratio = (w.end - w.start) / std::max(hop_, graph_->wordExpectedSeconds[word]);
    const double logRatio = std::log(ratio) / kLogDurationScale;
    return static_cast<float>(std::exp(-excess / kExcessScaleDb - 0.5 * logRatio * logRatio));
}

// A word's confidence alone tells a right word from a wrong one poorly on real voices (the
// templates fit them less well than espeak-ng's); the line's median tells a script that fits
// the audio from one that does not far better. In a line that fits, a word is judged against
// the line: it needs a share of the line's median. A line of one word has no median to go by.
float AlignmentPath::wordConfidenceFloor(std::vector<float> confidences) const {
    const float strict = config_.minWordConfidence;
    if (confidences.size() <= 1) return std::min(strict, config_.minSingleWordConfidence);
    std::nth_element(confidences.begin(), confidences.begin() + confidences.size() / 2,
                     confidences.end());
    const float median = confidences[confidences.size() / 2];
    return median >= strict ? std::min(strict, config_.fittingLineShare * median) : strict;
}

Alignment AlignmentPath::finish(bool complete) {
    closeRun();
    out_.complete = complete;
    std::vector<float> confidences(words_.size());
    for (std::size_t i = 0; i < words_.size(); ++i) confidences[i] = confidence(i);
    const float minConfidence = wordConfidenceFloor(confidences);
    for (std::size_t i = 0; i < words_.size(); ++i) {
        AlignedWord w{texts_[i]};
        if (words_[i].frames > 0) {
            w.start = words_[i].start;
            w.end = words_[i].end;
            w.excessDb = static_cast<float>(words_[i].excessDb / words_[i].frames);
            w.durationRatio = static_cast<float>((w.end - w.start) /
                                                 std::max(hop_, graph_->wordExpectedSeconds[i]));
        }
        w.confidence = confidences[i];
        w.placed = words_[i].frames > 0 && w.confidence >= minConfidence;
        out_.words.push_back(w);
    }
    // Segments carry their word's confidence; neighbours of one class merge (the classes
    // cannot tell them apart).
    PhonemeSchedule merged;
    for (std::size_t i = 0; i < out_.schedule.size(); ++i) {
        auto seg = out_.schedule[i];
        if (segmentWord_[i] >= 0) seg.confidence = out_.words[segmentWord_[i]].confidence;
        if (!merged.empty() && merged.back().phoneme == seg.phoneme) {
            merged.back().end = seg.end;
            merged.back().confidence = std::min(merged.back().confidence, seg.confidence);
        } else {
            merged.push_back(seg);
        }
    }
    out_.schedule = std::move(merged);
    return std::move(out_);
}

}  // namespace lipsyncd::dsp
