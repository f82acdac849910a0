// Section 2.2.3: "we cap the parametric speed dl(t)/dt ... by a value l_max. This prevents
// overly fast changes to any shape." Frame by frame, each pose moves toward its target by at
// most its limit × dt. Capping can hold a pose up that the curves let fall, which could break
// a constraint again; so, when constraints are on, poses are placed highest priority first
// (the order constraints resolve in) under a ceiling that keeps every constraint satisfiable
// (ceilingFor). Starting from a frame that meets the constraints, every frame then meets both.
#include <algorithm>
#include <lipsyncd/lipsync.hpp>
#include <numeric>

namespace lipsyncd::lipsync {

namespace {
// Highest value `pose` may take this frame so that every constraint can still hold. After
// section 2.2.2 a constraint means low ≤ max(0, C − high): the higher-priority pose is free
// once its partner can reach 0 this frame; until then it may rise only as far as the partner
// can fall. The lower-priority pose, placed after, must stay under C − high.
float ceilingFor(const PoseSet& poses, std::size_t pose, std::span<const float> previous,
                 std::span<const float> placed, double dt) {
    float ceiling = 1.0f;
    for (const auto& c : poses.constraints()) {
        const auto threshold = static_cast<float>(c.threshold);
        if (c.low == pose) {
            ceiling = std::min(ceiling, std::max(0.0f, threshold - placed[c.high]));
        } else if (c.high == pose) {
            const auto fall = static_cast<float>(poses[c.low].speedLimit * dt);
            const float lowest = std::max(0.0f, previous[c.low] - fall);
            if (lowest > 0) ceiling = std::min(ceiling, threshold - lowest);
        }
    }
    return ceiling;
}
}  // namespace

SpeedLimitScratch::SpeedLimitScratch(const PoseSet& poses)
    : order(poses.size()), prev(poses.size()), now(poses.size()) {
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return poses[a].priority > poses[b].priority;
    });
}

void limitSpeed(const PoseSet& poses, bool keepConstraints, std::span<const float> previous,
                PoseCurves& curves, std::size_t fromFrame) {
    SpeedLimitScratch scratch(poses);
    limitSpeed(poses, keepConstraints, previous, curves, fromFrame, scratch);
}

void limitSpeed(const PoseSet& poses, bool keepConstraints, std::span<const float> previous,
                PoseCurves& curves, std::size_t fromFrame, SpeedLimitScratch& scratch) {
    const std::size_t n = poses.size();
    const double dt = 1.0 / curves.rate;
    auto& prev = scratch.prev;
    auto& now = scratch.now;
    prev.assign(previous.begin(), previous.end());
    // ceilingFor reads `now` of poses not yet placed this frame: as a fresh call, it starts at 0.
    now.assign(n, 0.0f);
    for (std::size_t f = fromFrame; f < curves.frames; ++f) {
        for (const std::size_t p : scratch.order) {
            const auto step = static_cast<float>(poses[p].speedLimit * dt);
            const float lo = std::max(0.0f, prev[p] - step);
            float hi = std::min(1.0f, prev[p] + step);
            if (keepConstraints) hi = std::min(hi, ceilingFor(poses, p, prev, now, dt));
            // hi < lo only when the previous frame broke a constraint; the constraint wins.
            now[p] = std::min(std::max(curves.values[p][f], lo), std::max(0.0f, hi));
        }
        for (std::size_t p = 0; p < n; ++p) curves.values[p][f] = now[p];
        prev = now;
    }
}

}  // namespace lipsyncd::lipsync
