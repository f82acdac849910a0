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

void LevelTrack::add(double time, float frameDb) {
    if (db.empty()) start = time;
    db.push_back(frameDb);
}

float LevelTrack::speakingLevel(double percentile, double belowPeakDb) const {
    if (db.empty()) return -120.0f;
    const float peak = *std::max_element(db.begin(), db.end());
    std::vector<float> speech;
    for (float v : db)
        if (v >= peak - belowPeakDb) speech.push_back(v);
    const auto k = static_cast<std::size_t>(percentile * static_cast<double>(speech.size() - 1));
    std::nth_element(speech.begin(), speech.begin() + static_cast<std::ptrdiff_t>(k), speech.end());
    return speech[k];
}

}  // namespace lipsyncd
