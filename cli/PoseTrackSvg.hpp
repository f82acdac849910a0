// Pose weights as an SVG chart, as the phone-bigram paper's figures 6-10 show them: one
// polyline per pose over time, phoneme boundaries as vertical lines and the phonemes named
// under the curves. Written by hand (SVG is text); no plotting library.
#pragma once

#include <iosfwd>
#include <lipsyncd/core.hpp>

namespace lipsyncd::cli {

struct SvgChartOptions {
    double pixelsPerSecond = 400;
    double plotHeight = 240;
};

void writePoseTrackSvg(std::ostream& out, const PoseTrack& track, const PhonemeSchedule* schedule,
                       const SvgChartOptions& options = {});

}  // namespace lipsyncd::cli
