// The smooth curve behind an animator's control polygon (section 2.1.2: "the linear curve
// represents the control curve for a smooth B-spline curve"). The polygon's vertices are the
// control points of a uniform cubic B-spline in the (time, value) plane, clamped by tripling
// the end points so the curve starts and ends where the polygon does. Times increase along
// the polygon, so the curve's time is monotone and the curve is a function of time; it is
// sampled once here and read by linear interpolation at run time.
#include <algorithm>
#include <cmath>
#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::lipsync {

namespace {
constexpr int kStepsPerSpan = 32;
constexpr std::size_t kSamples = 257;

// Uniform cubic B-spline basis at s in [0, 1].
ControlPoint blend(const ControlPoint& a, const ControlPoint& b, const ControlPoint& c,
                   const ControlPoint& d, float s) {
    const float s2 = s * s, s3 = s2 * s, r = 1 - s;
    const float w0 = r * r * r / 6, w1 = (3 * s3 - 6 * s2 + 4) / 6;
    const float w2 = (-3 * s3 + 3 * s2 + 3 * s + 1) / 6, w3 = s3 / 6;
    return {w0 * a.time + w1 * b.time + w2 * c.time + w3 * d.time,
            w0 * a.value + w1 * b.value + w2 * c.value + w3 * d.value};
}
}  // namespace

ControlCurve::ControlCurve(std::vector<ControlPoint> polygon) : polygon_(std::move(polygon)) {
    std::vector<ControlPoint> q;
    q.insert(q.end(), 2, polygon_.front());
    q.insert(q.end(), polygon_.begin(), polygon_.end());
    q.insert(q.end(), 2, polygon_.back());
    std::vector<ControlPoint> dense;
    for (std::size_t j = 0; j + 3 < q.size(); ++j)
        for (int k = 0; k < kStepsPerSpan; ++k)
            dense.push_back(
                blend(q[j], q[j + 1], q[j + 2], q[j + 3], static_cast<float>(k) / kStepsPerSpan));
    dense.push_back(polygon_.back());
    samples_.resize(kSamples);
    std::size_t at = 0;
    for (std::size_t i = 0; i < kSamples; ++i) {
        const float u = static_cast<float>(i) / (kSamples - 1);
        while (at + 1 < dense.size() && dense[at + 1].time < u) ++at;
        const auto& a = dense[at];
        const auto& b = dense[std::min(at + 1, dense.size() - 1)];
        const float span = b.time - a.time;
        const float f = span > 0 ? std::clamp((u - a.time) / span, 0.0f, 1.0f) : 0.0f;
        samples_[i] = std::clamp(a.value + f * (b.value - a.value), 0.0f, 1.0f);
    }
}

float ControlCurve::at(double u) const {
    const double x = std::clamp(u, 0.0, 1.0) * static_cast<double>(samples_.size() - 1);
    const auto i = std::min(static_cast<std::size_t>(x), samples_.size() - 2);
    const auto f = static_cast<float>(x - static_cast<double>(i));
    return samples_[i] + f * (samples_[i + 1] - samples_[i]);
}

}  // namespace lipsyncd::lipsync
