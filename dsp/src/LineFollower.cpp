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
#include <utility>

#include "AlignerInput.hpp"

namespace lipsyncd::dsp {

namespace {
// The aligner's config for following, once the lag is known to fit its lookahead.
AlignerConfig following(AlignerConfig config, double lagSeconds) {
    if (!(lagSeconds >= 0) || lagSeconds > config.lookaheadSeconds)
        throw InputError("the lag of a followed line must lie in 0.." +
                         std::to_string(config.lookaheadSeconds) + " s (the aligner's lookahead)");
    config.commitSeconds = LineFollower::kCommitSeconds;
    config.silenceInSpeechCost = config.followingSilenceInSpeechCost;
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
    path_.resize(static_cast<std::size_t>(lag_) + 1);
}

// The frame `back` before the newest (at most lag_), from the ring.
const LineFollower::Held& LineFollower::heldBack(int back) const {
    return held_[static_cast<std::size_t>((frames_ - 1 - back) % std::ssize(held_))];
}

// The class the best path gives the frame `back` before the newest: the words', or the front
// end's own in a stretch no word explains.
int LineFollower::classBack(int back) const {
    const int c = path_[static_cast<std::size_t>(back)];
    if (c >= 0) return c;
    return heldBack(back).heard;
}

void LineFollower::push(const FrameLabel& label, std::span<const float> templateDistances,
                        std::span<const float> distances) {
    if (share_ > 0) networkTerm(templateDistances, distances, term_);
    pushFrame(aligner_, label.time, templateDistances, term_, share_, label.silent, mixed_);
    held_[static_cast<std::size_t>(frames_ % std::ssize(held_))] = {label.time, label.phoneme};
    ++frames_;
    aligner_.phonemesBack(path_);
    if (frames_ > lag_) place(lag_);
    // What the best path goes on to after the open phoneme, in the frames not decided yet.
    upcoming_ = {};
    const int undecided = static_cast<int>(std::min<std::int64_t>(lag_, frames_));
    for (int back = undecided - 1; back >= 0; --back) {
        const int c = classBack(back);
        if (c == open_.phoneme) continue;
        upcoming_ = {c, std::max(0.0, heldBack(back).time - hop_ / 2), 0};
        break;
    }
}

void LineFollower::finish() {
    // The newest frames, on the best path as it stands at the end (the oldest lag back).
    for (int back = static_cast<int>(std::min<std::int64_t>(lag_, frames_)) - 1; back >= 0; --back)
        place(back);
    upcoming_ = {};
    if (open_.phoneme >= 0 && sink_)
        sink_({open_.start, open_.end, (*set_)[static_cast<std::size_t>(open_.phoneme)].name});
    open_ = {};
}

// The frame `back` before the newest is decided: a new segment when its class changes. The new
// one is open before the old one goes to the sink, so that the sink sees what comes next.
void LineFollower::place(int back) {
    const auto& frame = heldBack(back);
    const int c = classBack(back);
    const double start = std::max(0.0, frame.time - hop_ / 2), end = frame.time + hop_ / 2;
    if (c == open_.phoneme) {
        open_.end = end;
        return;
    }
    const auto closed = std::exchange(open_, {c, start, end});
    if (closed.phoneme >= 0 && sink_)
        sink_({closed.start, start, (*set_)[static_cast<std::size_t>(closed.phoneme)].name});
}

}  // namespace lipsyncd::dsp
