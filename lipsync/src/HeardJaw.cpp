// The jaw as the front end heard it. A schedule keeps one class per segment, and a wrong pick
// between two open vowels (aa taken for ao) or a vowel taken for a consonant moves the jaw as
// far as the pick says. The front end's per-frame jaw estimate (dsp FrameLabel::jaw) weighs
// every class by its nearness instead, so classes of like height agree whichever wins; blended
// into the jaw pose it keeps the runtime's timing and closures and takes the height from what
// was heard. (Measured per speaker in docs/measurements.md, "The heard jaw".)
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
// Mean of the frames within ±half seconds of t (nearest-frame indices, clamped to the track).
double heardAt(const LevelTrack& levels, double t, double half) {
    const auto last = static_cast<long>(levels.jaw.size()) - 1;
    const auto index = [&](double time) {
        return std::clamp(std::lround((time - levels.start) * levels.rate), 0L, last);
    };
    const long from = index(t - half), to = index(t + half);
    double sum = 0;
    for (long i = from; i <= to; ++i) sum += levels.jaw[static_cast<std::size_t>(i)];
    return sum / static_cast<double>(to - from + 1);
}

// How much of a closure the schedule places holds the heard jaw back: all of it, but from audio
// alone, offline, less where the heard jaw is open. There the schedule's bilabial is a guess
// the ear contradicts (in vowels, most false closures were such bilabials), and the jaw's dips
// close the mouth between syllables (deepenDips).
double closureHeld(const Pose& pose, double heard, HeardSpeech speech) {
    if (speech != HeardSpeech::analysed || heard <= pose.closureHeldBelow) return 1;
    if (heard >= pose.closureDoubtedAbove) return 0;
    return (pose.closureDoubtedAbove - heard) / (pose.closureDoubtedAbove - pose.closureHeldBelow);
}
}  // namespace

void blendHeardJaw(const PoseSet& poses, double heard, std::span<float> weights,
                   HeardSpeech speech) {
    heard = std::isfinite(heard) ? std::clamp(heard, 0.0, 1.0) : 0.0;
    for (std::size_t p = 0; p < poses.size(); ++p) {
        const auto& pose = poses.poses()[p];
        const double g = speech == HeardSpeech::aligned ? pose.heardJawAligned : pose.heardJaw;
        if (g <= 0) continue;
        // Where the schedule closes the lips, the heard height gives way: a bilabial the
        // schedule places stays a closure.
        const auto closer = poses.find(pose.heardJawClosedBy);
        const double closed = closer ? std::clamp<double>(weights[*closer], 0.0, 1.0) *
                                           closureHeld(pose, heard, speech)
                                     : 0.0;
        weights[p] = static_cast<float>((1 - g) * weights[p] + g * heard * (1 - closed));
    }
}

void blendHeardJaw(const PoseSet& poses, const LevelTrack& levels, PoseTrack& track,
                   double smoothingSeconds) {
    if (levels.jaw.empty() || track.poses.size() != poses.size()) return;
    for (std::size_t f = 0; f < track.frames(); ++f)
        blendHeardJaw(poses, heardAt(levels, track.times[f], smoothingSeconds / 2),
                      std::span<float>(track.values).subspan(f * poses.size(), poses.size()),
                      levels.aligned ? HeardSpeech::aligned : HeardSpeech::analysed);
}

}  // namespace lipsyncd::lipsync
