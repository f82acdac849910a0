// Louder speech opens the mouth wider. Lewis (1991) computes each frame's excitation volume
// beside its spectrum for exactly this: the spectrum says which mouth shape, the volume says how
// far. Here the phoneme's pose weight is the most the mouth may open, and the level relative to
// the utterance's speaking level decides how much of it is used.
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
// s in [0, 1]: 0 at `reference − range` and below, 1 at the reference and above.
double relativeLevel(double db, double reference, double rangeDb) {
    return std::clamp((db - (reference - rangeDb)) / rangeDb, 0.0, 1.0);
}

void scaleFrame(std::span<const double> gains, double s, std::span<float> weights) {
    for (std::size_t p = 0; p < weights.size(); ++p)
        weights[p] *= static_cast<float>(1 - gains[p] + gains[p] * s);
}

std::vector<double> gainsOf(const PoseSet& poses) {
    std::vector<double> g;
    for (const auto& p : poses.poses()) g.push_back(p.loudnessGain);
    return g;
}

// Where the schedule's pauses start: each silence that follows speech.
std::vector<double> pauseStarts(std::span<const PhonemeSegment> schedule,
                                const std::string& silence) {
    std::vector<double> starts;
    for (std::size_t i = 1; i < schedule.size(); ++i)
        if (schedule[i].phoneme == silence && schedule[i - 1].phoneme != silence)
            starts.push_back(schedule[i].start);
    return starts;
}

// The time whose level shapes the frame at `t`: t itself, or, for speech within `hold` of the
// next pause, the time `hold` before that pause. `next` (the first pause not yet passed) and
// `segment` (the one holding t) walk forward with t: the frames come in time order.
double levelTimeFor(double t, std::span<const PhonemeSegment> schedule, const std::string& silence,
                    std::span<const double> pauses, double hold, std::size_t& segment,
                    std::size_t& next) {
    while (segment + 1 < schedule.size() && schedule[segment].end <= t) ++segment;
    while (next < pauses.size() && pauses[next] <= t) ++next;
    if (hold <= 0 || next == pauses.size() || schedule[segment].phoneme == silence) return t;
    return pauses[next] - t < hold ? pauses[next] - hold : t;
}
}  // namespace

void shapeByLoudness(const PoseSet& poses, const LevelTrack& levels,
                     std::span<const PhonemeSegment> schedule, const PhonemeSet& phonemes,
                     PoseTrack& track, const LoudnessConfig& config) {
    if (levels.db.empty() || track.poses.size() != poses.size()) return;
    const auto gains = gainsOf(poses);
    const double reference = levels.speakingLevel(config.percentile, config.speechBelowPeakDb);
    const auto& silence = phonemes[phonemes.silence()].name;
    const auto pauses = pauseStarts(schedule, silence);
    std::size_t segment = 0, next = 0;
    for (std::size_t f = 0; f < track.frames(); ++f) {
        const double t = track.times[f];
        const double held =
            levelTimeFor(t, schedule, silence, pauses, config.fadeHoldSeconds, segment, next);
        const double s = std::max(relativeLevel(levels.at(t), reference, config.rangeDb),
                                  relativeLevel(levels.at(held), reference, config.rangeDb));
        scaleFrame(gains, s,
                   std::span<float>(track.values).subspan(f * poses.size(), poses.size()));
    }
}

LoudnessShaper::LoudnessShaper(const PoseSet& poses, const LoudnessConfig& config)
    : gains_(gainsOf(poses)), config_(config) {}

void LoudnessShaper::shape(float db, double dt, std::span<float> weights) {
    peak_ = std::max<double>(db, peak_ - config_.peakDecayDbPerS * std::max(0.0, dt));
    scaleFrame(gains_, relativeLevel(db, peak_, config_.rangeDb), weights);
}

}  // namespace lipsyncd::lipsync
