// Section 2.2.2: poses that must not combine (open with pbm, ...). When c_a + c_b > C(a, b),
// the lower-priority curve is reduced so that the sum is C: c_b' = c_b − (c_a + c_b − C).
// Constraints are applied highest winning priority first (PoseSet orders them), and only ever
// lower a value, so a constraint met stays met.
#include <algorithm>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

void applyConstraints(const PoseSet& poses, PoseCurves& curves, std::size_t fromFrame) {
    for (const auto& c : poses.constraints()) {
        const auto& high = curves.values[c.high];
        auto& low = curves.values[c.low];
        const auto threshold = static_cast<float>(c.threshold);
        for (std::size_t f = fromFrame; f < curves.frames; ++f)
            if (high[f] + low[f] > threshold) low[f] = std::max(0.0f, threshold - high[f]);
    }
}

}  // namespace lipsyncd::lipsync
