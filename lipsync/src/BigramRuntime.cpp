// The runtime of section 2.2 over a whole schedule: the steps in the paper's order.
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
PoseTrack toTrack(const PoseSet& poses, const PoseCurves& curves) {
    PoseTrack track;
    track.poses = poses.names();
    std::vector<float> row(poses.size());
    for (std::size_t f = 0; f < curves.frames; ++f) {
        for (std::size_t p = 0; p < poses.size(); ++p) row[p] = curves.values[p][f];
        track.append(curves.timeOf(f), row);
    }
    return track;
}
}  // namespace

PoseTrack animate(std::span<const PhonemeSegment> schedule, const BigramCurveSet& set,
                  const PoseSet& poses, const RuntimeConfig& config, const PhonemeSet& phonemes) {
    if (schedule.empty()) {
        PoseTrack empty;
        empty.poses = poses.names();
        return empty;
    }
    const double start = schedule.front().start, end = schedule.back().end;
    const auto frames =
        static_cast<std::size_t>(std::floor((end - start) * config.outputRate + 1e-9)) + 1;
    PoseCurves curves(poses.size(), config.outputRate, start, 0, frames);
    stitchBigrams(schedule, set, phonemes, curves);
    if (config.smoothing)
        for (std::size_t p = 0; p < poses.size(); ++p)
            smoothValleys(curves.values[p], curves.rate, poses[p].smoothingWindow);
    if (config.constraints) applyConstraints(poses, curves);
    if (config.restInPauses) restInPauses(schedule, phonemes, poses.rest(), curves);
    if (config.speedLimits) {
        const std::vector<float> rest(poses.size(), 0.0f);  // the mouth starts at rest
        limitSpeed(poses, config.constraints, rest, curves);
    }
    return toTrack(poses, curves);
}

}  // namespace lipsyncd::lipsync
