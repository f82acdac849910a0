// The runtime fed segment by segment (the front end closes them as it goes). Each push reruns
// the steps of section 2.2 over a short window of recent segments and lets out the frames that
// no later segment can change any more: those older than the newest boundary minus the delay.
// The window keeps enough past (a segment, the smoothing window and a margin) for every step
// to see what the offline pass sees, and the speed limit continues from the last frame out.
// It runs on the live path, every 10 ms: the window, the schedule and the curves live in
// members whose memory each push reuses, so once they have grown to the longest window seen
// nothing allocates.
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

StreamingRuntime::StreamingRuntime(const BigramCurveSet& set, const PoseSet& poses,
                                   double delaySeconds, const RuntimeConfig& config,
                                   const PhonemeSet& phonemes)
    : set_(&set),
      poses_(&poses),
      phonemes_(&phonemes),
      config_(config),
      delay_(std::max(0.0, delaySeconds)),
      last_(poses.size(), 0.0f),
      curves_(poses.size(), config.outputRate, 0, 0, 0),
      speed_(poses) {
    // Room for what a window holds (the delay, the smoothing window and a margin, two segments
    // more, the causal estimate) at one segment per 10 ms analysis hop, and for its frames and a
    // few seconds let out at once (a push after a long segment, with a delay). The steps never
    // run over more than that past (pastKept()), however long a pause lasts; only a push that
    // lets out more than a few seconds at once grows them, geometrically.
    constexpr double kSegmentsPerSecond = 100, kOpenSeconds = 4;
    const double kept = delay_ + longestWindow() + 0.05;
    const auto segments = static_cast<std::size_t>(kept * kSegmentsPerSecond) + 4;
    window_.reserve(segments);
    schedule_.reserve(segments + 1);
    const auto frames = static_cast<std::size_t>((kept + kOpenSeconds) * config_.outputRate);
    for (auto& pose : curves_.values) pose.reserve(frames);
}

void StreamingRuntime::push(const PhonemeSegment& segment, PoseTrack& out) {
    if (!started_) {
        started_ = true;
        origin_ = segment.start;
    } else if (!window_.empty() && std::abs(segment.start - window_.back().end) > 1e-6) {
        throw InputError("streaming schedule: segment at " + std::to_string(segment.start) +
                         " s does not start where the previous one ended (" +
                         std::to_string(window_.back().end) + " s)");
    }
    window_.push_back(segment);
    emitUntil(segment.end - delay_, false, out);
    expected_.reset();
}

void StreamingRuntime::expect(const std::string& phoneme, double from) {
    if (!expected_) expected_.emplace();
    expected_->start = from;
    expected_->phoneme = phoneme;
}

void StreamingRuntime::preview(const std::string& phoneme, double until, PoseTrack& out) {
    if (delay_ > 0) return;
    if (!started_) {
        started_ = true;
        origin_ = 0;
    }
    const double from = window_.empty() ? origin_ : window_.back().end;
    if (!(until > from)) return;
    const PhonemeSegment open{from, until, phoneme, 0};
    emitUntil(until, false, out, &open);
    expected_.reset();
}

void StreamingRuntime::finish(PoseTrack& out) {
    if (!window_.empty()) emitUntil(window_.back().end, true, out);
}

void StreamingRuntime::emitUntil(double until, bool final, PoseTrack& out,
                                 const PhonemeSegment* open) {
    if (out.poses.empty()) out.poses = poses_->names();
    if (window_.empty() && !open) return;
    const double rate = config_.outputRate;
    const auto lastFrame = static_cast<long long>(std::floor((until - origin_) * rate + 1e-9));
    if (lastFrame < static_cast<long long>(emitted_)) return;
    // The steps run from the window's start, or from the past that can still change a frame
    // to come (pastKept()) where that is later: a pause heard live is one open segment that
    // grows as long as the pause lasts, and each tick's work and memory must not grow with it.
    const double windowStart = window_.empty() ? open->start : window_.front().start;
    const auto firstFrame =
        static_cast<std::size_t>(std::max({0.0, std::ceil((windowStart - origin_) * rate - 1e-9),
                                           std::ceil((pastKept() - origin_) * rate - 1e-9)}));
    // Work past the last frame to let out by a smoothing window, so that a curve cut short
    // there does not look like a peak to the valley smoothing.
    const double knownEnd = open ? open->end : window_.back().end;
    const auto known = static_cast<long long>(std::floor((knownEnd - origin_) * rate + 1e-9));
    const auto margin = static_cast<long long>(std::ceil(longestWindow() * rate)) + 2;
    const auto workTo = final ? lastFrame : std::min(known, lastFrame + margin);
    const std::size_t frames = static_cast<std::size_t>(workTo) + 1 - firstFrame;
    resetCurves(firstFrame, frames);
    buildSchedule(delay_ == 0 && !final, open);
    stitchBigrams(schedule_, *set_, *phonemes_, curves_, {atStart_, final});
    if (config_.smoothing)
        for (std::size_t p = 0; p < poses_->size(); ++p)
            smoothValleys(curves_.values[p], rate, (*poses_)[p].smoothingWindow);
    const std::size_t from = emitted_ - firstFrame;
    if (config_.constraints) applyConstraints(*poses_, curves_, from);
    // The newest segment counts as the end: if it is silence, speech may have stopped, and the
    // mouth must not wait for the next segment to find out (a live puppet would hang open).
    if (config_.restInPauses)
        restInPauses(schedule_, *phonemes_, poses_->rest(), curves_, from, {atStart_, true});
    if (config_.speedLimits) limitSpeed(*poses_, config_.constraints, last_, curves_, from, speed_);

    const std::size_t end = static_cast<std::size_t>(lastFrame) + 1 - firstFrame;
    for (std::size_t f = from; f < end; ++f) {
        for (std::size_t p = 0; p < poses_->size(); ++p) last_[p] = curves_.values[p][f];
        out.append(curves_.timeOf(f), last_);
    }
    emitted_ = static_cast<std::size_t>(lastFrame) + 1;
    dropOldSegments();
}

// The segments the steps run over: the window, and in the causal mode what comes next, unknown
// yet: the last phoneme (or the open one) going on for a typical length, or, when expect()
// said what follows, that after it.
void StreamingRuntime::buildSchedule(bool causal, const PhonemeSegment* open) {
    schedule_.assign(window_.begin(), window_.end());
    if (!causal) return;
    // The typical length comes from the phonemes heard, not the pauses: a pause says nothing
    // about how long the next phoneme lasts, and a long one would stretch the guess over seconds.
    double total = 0;
    std::size_t counted = 0;
    const auto& silence = (*phonemes_)[phonemes_->silence()].name;
    for (const auto& s : window_)
        if (s.phoneme != silence) total += s.duration(), ++counted;
    const double typical = counted == 0 ? 0.1 : total / static_cast<double>(counted);
    if (open) {
        if (expected_ && expected_->start > open->start) {
            const double next = std::max(open->end, expected_->start);
            schedule_.push_back({open->start, next, open->phoneme, 0});
            schedule_.push_back({next, next + typical, expected_->phoneme, 0});
        } else {
            schedule_.push_back(
                {open->start, std::max(open->end, open->start + typical), open->phoneme, 0});
        }
    } else {
        const auto& last = window_.back();
        const auto& next = expected_ ? expected_->phoneme : last.phoneme;
        schedule_.push_back({last.end, last.end + typical, next, 0});
    }
}

// What a fresh PoseCurves(poses, rate, origin_, firstFrame, frames) holds (every value 0), in
// curves_'s memory. A longer stretch than any before grows it by at least double.
void StreamingRuntime::resetCurves(std::size_t firstFrame, std::size_t frames) {
    curves_.startTime = origin_;
    curves_.firstFrame = firstFrame;
    curves_.rate = config_.outputRate;
    curves_.frames = frames;
    for (auto& pose : curves_.values) {
        if (pose.capacity() < frames) pose.reserve(std::max(frames, 2 * pose.capacity()));
        pose.assign(frames, 0.0f);
    }
}

// Keeps two segments before the margin: frames inside window_[1] see both bigrams covering them.
double StreamingRuntime::longestWindow() const {
    double longest = 0;
    for (const auto& p : poses_->poses()) longest = std::max(longest, p.smoothingWindow);
    return longest;
}

// Frames before this cannot change a frame not yet out: the valley smoothing reaches back a
// smoothing window, and nothing else looks back further than the frame before.
double StreamingRuntime::pastKept() const {
    return origin_ + static_cast<double>(emitted_) / config_.outputRate - longestWindow() - 0.05;
}

void StreamingRuntime::dropOldSegments() {
    const double keepFrom = pastKept();
    while (window_.size() > 3 && window_[2].start <= keepFrom) {
        window_.erase(window_.begin());
        atStart_ = false;
    }
}

}  // namespace lipsyncd::lipsync
