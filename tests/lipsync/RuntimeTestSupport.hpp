// Small pose sets and curve sets built in code, for hand-computed runtime cases.
#pragma once

#include <lipsyncd/lipsync.hpp>

namespace lipsyncd::test {

// Two poses: open (priority 1) and pbm (priority 6), C(pbm, open) = 0.5.
inline lipsync::PoseSet twoPoses(double speedLimit = 100, double window = 0.18) {
    std::vector<lipsync::Pose> poses{{"open", 1, speedLimit, window},
                                     {"pbm", 6, speedLimit, window}};
    return lipsync::PoseSet("two", poses, {{1, 0, 0.5}});
}

inline lipsync::ControlCurve flat(float v) {
    return lipsync::ControlCurve({{0, v}, {1, v}});
}

// The shipped pose set and curve set (facefx, english), loaded once.
struct Shipped {
    lipsync::PoseSet poses = lipsync::PoseSet::named("facefx");
    lipsync::BigramCurveSet curves = lipsync::BigramCurveSet::named("english", poses);
};
inline const Shipped& shipped() {
    static const Shipped s;
    return s;
}

inline std::size_t cls(const std::string& name) {
    return *PhonemeSet::common().find(name);
}

}  // namespace lipsyncd::test
