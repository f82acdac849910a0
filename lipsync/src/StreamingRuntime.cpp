// The runtime fed segment by segment (the front end closes them as it goes). Each push reruns
// the steps of section 2.2 over a short window of recent segments and lets out the frames that
// no later segment can change any more: those older than the newest boundary minus the delay.
// The window keeps enough past (a segment, the smoothing window and a margin) for every step
// to see what the offline pass sees, and the speed limit continues from the last frame out.
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
      last_(poses.size(), 0.0f) {}

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
    const double windowStart = window_.empty() ? open->start : window_.front().start;
    const auto firstFrame =
        static_cast<std::size_t>(std::max(0.0, std::ceil((windowStart - origin_) * rate - 1e-9)));
    // Work past the last frame to let out by a smoothing window, so that a curve cut short
    // there does not look like a peak to the valley smoothing.
    const double knownEnd = open ? open->end : window_.back().end;
    const auto known = static_cast<long long>(std::floor((knownEnd - origin_) * rate + 1e-9));
    const auto margin = static_cast<long long>(std::ceil(longestWindow() * rate)) + 2;
    const auto workTo = final ? lastFrame : std::min(known, lastFrame + margin);
    const std::size_t frames = static_cast<std::size_t>(workTo) + 1 - firstFrame;
    PoseCurves curves(poses_->size(), rate, origin_, firstFrame, frames);

    std::vector<PhonemeSegment> schedule(window_.begin(), window_.end());
    const bool causal = delay_ == 0 && !final;
    if (causal) {  // what comes next is unknown: assume the last phoneme goes on, for a typical
                   // length
        double total = 0;
        for (const auto& s : window_) total += s.duration();
        const double typical = window_.empty() ? 0.1 : total / static_cast<double>(window_.size());
        if (open) {
            schedule.push_back(
                {open->start, std::max(open->end, open->start + typical), open->phoneme, 0});
        } else {
            const auto& last = window_.back();
            schedule.push_back({last.end, last.end + typical, last.phoneme, 0});
        }
    }
    stitchBigrams(schedule, *set_, *phonemes_, curves, {atStart_, final});
    if (config_.smoothing)
        for (std::size_t p = 0; p < poses_->size(); ++p)
            smoothValleys(curves.values[p], rate, (*poses_)[p].smoothingWindow);
    const std::size_t from = emitted_ - firstFrame;
    if (config_.constraints) applyConstraints(*poses_, curves, from);
    // The newest segment counts as the end: if it is silence, speech may have stopped, and the
    // mouth must not wait for the next segment to find out (a live puppet would hang open).
    if (config_.restInPauses)
        restInPauses(schedule, *phonemes_, poses_->rest(), curves, from, {atStart_, true});
    if (config_.speedLimits) limitSpeed(*poses_, config_.constraints, last_, curves, from);

    const std::size_t end = static_cast<std::size_t>(lastFrame) + 1 - firstFrame;
    for (std::size_t f = from; f < end; ++f) {
        for (std::size_t p = 0; p < poses_->size(); ++p) last_[p] = curves.values[p][f];
        out.append(curves.timeOf(f), last_);
    }
    emitted_ = static_cast<std::size_t>(lastFrame) + 1;
    dropOldSegments();
}

// Keeps two segments before the margin: frames inside window_[1] see both bigrams covering them.
double StreamingRuntime::longestWindow() const {
    double longest = 0;
    for (const auto& p : poses_->poses()) longest = std::max(longest, p.smoothingWindow);
    return longest;
}

void StreamingRuntime::dropOldSegments() {
    const double keepFrom =
        origin_ + static_cast<double>(emitted_) / config_.outputRate - longestWindow() - 0.05;
    while (window_.size() > 3 && window_[2].start <= keepFrom) {
        window_.erase(window_.begin());
        atStart_ = false;
    }
}

}  // namespace lipsyncd::lipsync
