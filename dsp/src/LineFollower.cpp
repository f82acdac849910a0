// A line followed as it is said: the forced aligner in its following form (no path kept, its
// room reserved), read a fixed lag behind the newest frame. The Viterbi path is traced back
// from the last frame once the input is over (Rabiner 1989, section III.B); a live mouth cannot
// wait for that, so each frame takes the state the best partial path held `lag` frames after it.
// Later frames may still move the best path there, but less often the longer the lag: the lag
// trades delay for sureness (docs/measurements.md, "Live lines followed on their words"). The
// frames the lag holds back wait in a ring with the front end's own class, which stands where
// no word explains the sound.
#include <algorithm>
#include <cmath>
#include <lipsyncd/dsp.hpp>
#include <string>

#include "AlignerInput.hpp"

namespace lipsyncd::dsp {

namespace {
// The aligner's config for following, once the lag is known to fit its lookahead.
AlignerConfig following(AlignerConfig config, double lagSeconds) {
    if (!(lagSeconds >= 0) || lagSeconds > config.lookaheadSeconds)
        throw InputError("the lag of a followed line must lie in 0.." +
                         std::to_string(config.lookaheadSeconds) + " s (the aligner's lookahead)");
    config.commitSeconds = LineFollower::kCommitSeconds;
    return config;
}
}  // namespace

LineFollower::LineFollower(std::span<const ScriptWord> script, const PhonemeSet& set,
                           double hopSeconds, double lagSeconds, const AlignerConfig& config)
    : set_(&set),
      aligner_(script, set, hopSeconds, 1.0, following(config, lagSeconds)),
      hop_(hopSeconds),
      lag_(static_cast<int>(std::lround(lagSeconds / hopSeconds))),
      share_(config.classNetworkShare),
      term_(set.size()),
      mixed_(set.size()) {
    aligner_.followOnly();
    held_.resize(static_cast<std::size_t>(lag_) + 1);
}

void LineFollower::push(const FrameLabel& label, std::span<const float> templateDistances,
                        std::span<const float> distances) {
    if (share_ > 0) networkTerm(templateDistances, distances, term_);
    pushFrame(aligner_, label.time, templateDistances, term_, share_, label.silent, mixed_);
    held_[static_cast<std::size_t>(frames_ % std::ssize(held_))] = {label.time, label.phoneme};
    ++frames_;
    if (frames_ <= lag_) return;
    const auto& frame = held_[static_cast<std::size_t>((frames_ - 1 - lag_) % std::ssize(held_))];
    place(frame, aligner_.phonemeBack(lag_));
}

void LineFollower::finish() {
    // The newest frames, on the best path as it stands at the end (the oldest lag back).
    for (int back = static_cast<int>(std::min<std::int64_t>(lag_, frames_)) - 1; back >= 0;
         --back) {
        const auto& frame =
            held_[static_cast<std::size_t>((frames_ - 1 - back) % std::ssize(held_))];
        place(frame, aligner_.phonemeBack(back));
    }
    if (open_.phoneme >= 0 && sink_)
        sink_({open_.start, open_.end, (*set_)[static_cast<std::size_t>(open_.phoneme)].name});
    open_ = {};
}

// One frame's class, from the words or (-1) the front end: a new segment when it changes.
void LineFollower::place(const Held& frame, int phoneme) {
    const int c = phoneme >= 0 ? phoneme : frame.heard;
    const double start = std::max(0.0, frame.time - hop_ / 2), end = frame.time + hop_ / 2;
    if (c == open_.phoneme) {
        open_.end = end;
        return;
    }
    if (open_.phoneme >= 0 && sink_)
        sink_({open_.start, start, (*set_)[static_cast<std::size_t>(open_.phoneme)].name});
    open_ = {c, start, end};
}

}  // namespace lipsyncd::dsp
