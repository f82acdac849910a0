// A syllable closes the jaw. Speaking, the jaw opens for each vowel and closes toward the
// consonants between them, and a puppeteer's hand does the same once a syllable. From audio
// alone the jaw is mostly the heard jaw (blendHeardJaw, heard_jaw 0.8), an estimate smoothed
// over 40 ms: between two vowels it dips, but a consonant of a few tens of milliseconds rarely
// brings it near closed, and the puppet's mouth stays ajar through the word. So each clear dip
// (the lowest point within ±lowestWithin, the jaw rising by the pose's dip_rise within
// riseWithin on both sides) is lowered by the pose's dip_depth at its lowest frame, tapering
// to nothing at ±(taper + one frame). Offline only: it needs riseWithin of the future.
// Chosen on the tune voices (docs/measurements.md, "A syllable closes the jaw").
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>
#include <numbers>
#include <vector>

namespace lipsyncd::lipsync {

namespace {
// The track's frames within `seconds`, at least one.
std::size_t framesFor(const PoseTrack& track, double seconds) {
    if (track.frames() < 2) return 1;
    const double step = (track.times.back() - track.times.front()) / double(track.frames() - 1);
    return std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(seconds / step)));
}

// Is frame f of curve c a clear dip: the lowest within ±lowest frames (the first frame of a
// flat bottom), with c rising by `rise` within `within` frames on both sides?
bool isDip(std::span<const float> c, std::size_t f, std::size_t lowest, std::size_t within,
           double rise) {
    const std::size_t n = c.size();
    if (f == 0 || f + 1 >= n) return false;
    for (std::size_t k = f - std::min(f, lowest); k <= std::min(n - 1, f + lowest); ++k)
        if (c[k] < c[f] || (k < f && c[k] == c[f])) return false;
    const auto peak = [&](std::size_t from, std::size_t to) {
        return *std::max_element(c.begin() + long(from), c.begin() + long(to) + 1);
    };
    const double before = peak(f - std::min(f, within), f - 1);
    const double after = peak(f + 1, std::min(n - 1, f + within));
    return before - c[f] >= rise && after - c[f] >= rise;
}

// How much of the dip's depth frame k keeps, k being `distance` frames from the lowest:
// 1 − depth·cos² over ±(taper + 1) frames.
float deepening(std::size_t distance, std::size_t taper, double depth) {
    const double c = std::cos(double(distance) / double(taper + 1) * std::numbers::pi / 2);
    return static_cast<float>(1 - depth * c * c);
}
}  // namespace

void deepenDips(const PoseSet& poses, PoseTrack& track, const DipConfig& config) {
    if (track.poses.size() != poses.size() || track.frames() < 3) return;
    const std::size_t n = track.frames(), width = poses.size();
    const auto lowest = framesFor(track, config.lowestWithin);
    const auto within = framesFor(track, config.riseWithin);
    const auto taper = framesFor(track, config.taper);
    std::vector<float> curve(n), scale(n);
    for (std::size_t p = 0; p < width; ++p) {
        const auto& pose = poses.poses()[p];
        if (pose.dipDepth <= 0) continue;
        for (std::size_t f = 0; f < n; ++f) curve[f] = track.values[f * width + p];
        std::fill(scale.begin(), scale.end(), 1.0f);
        // Dips are found on the curve as it came, so one deepened dip never makes the next.
        for (std::size_t f = 1; f + 1 < n; ++f) {
            if (!isDip(curve, f, lowest, within, pose.dipRise)) continue;
            for (std::size_t k = f - std::min(f, taper); k <= std::min(n - 1, f + taper); ++k)
                scale[k] =
                    std::min(scale[k], deepening(k > f ? k - f : f - k, taper, pose.dipDepth));
        }
        for (std::size_t f = 0; f < n; ++f) track.values[f * width + p] = curve[f] * scale[f];
    }
}

}  // namespace lipsyncd::lipsync
