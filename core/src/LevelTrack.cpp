#include <algorithm>
#include <cmath>
#include <lipsyncd/core.hpp>

namespace lipsyncd {

float LevelTrack::at(double t) const {
    if (db.empty()) return -120.0f;
    const double f = std::round((t - start) * rate);
    if (!(f > 0)) return db.front();  // also NaN
    return db[std::min(static_cast<std::size_t>(f), db.size() - 1)];
}

}  // namespace lipsyncd
