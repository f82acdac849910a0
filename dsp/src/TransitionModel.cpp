// Class-to-class transitions and minimum durations as data: JSON under config/decoder/ (format
// in its README.md), made by scripts/make-transitions.sh.
#include <cmath>
#include <lipsyncd/dsp.hpp>

#include "JsonField.hpp"

namespace lipsyncd::dsp {

namespace {
using nlohmann::json;
constexpr const char* kFormat = "lipsyncd-transitions";
constexpr int kVersion = 1;
constexpr int kMaxMinFrames = 50;  // half a second at 10 ms: no phoneme needs more
}  // namespace

TransitionModel TransitionModel::load(const std::filesystem::path& file) {
    const std::string source = file.string();
    const json j = readDataDocument(file, kFormat, kVersion);
    TransitionModel m;
    m.description = j.value("description", "");
    m.classes = member<std::vector<std::string>>(j, "classes", "", source);
    m.minFrames = member<std::vector<int>>(j, "min_frames", "", source);
    m.logProb = member<std::vector<std::vector<float>>>(j, "log_prob", "", source);
    m.validate(source);
    return m;
}

TransitionModel TransitionModel::loadDefault() {
    return load(findDataFile("decoder/english-transitions.json"));
}

void TransitionModel::validate(const std::string& source) const {
    const auto& set = PhonemeSet::common();
    const std::size_t n = classes.size();
    if (n < 2) throw InputError(source, 0, "'classes' needs at least two classes");
    for (std::size_t i = 0; i < n; ++i) {
        if (!set.find(classes[i]))
            throw InputError(source, 0,
                             "classes[" + std::to_string(i) + "]: '" + classes[i] +
                                 "' is not a class of the common set");
        for (std::size_t k = 0; k < i; ++k)
            if (classes[k] == classes[i])
                throw InputError(source, 0, "classes: '" + classes[i] + "' appears twice");
    }
    if (minFrames.size() != n)
        throw InputError(source, 0,
                         "min_frames has " + std::to_string(minFrames.size()) +
                             " values, expected " + std::to_string(n));
    for (std::size_t i = 0; i < n; ++i)
        if (minFrames[i] < 1 || minFrames[i] > kMaxMinFrames)
            throw InputError(source, 0,
                             "min_frames[" + std::to_string(i) +
                                 "] = " + std::to_string(minFrames[i]) + " is outside 1.." +
                                 std::to_string(kMaxMinFrames));
    if (logProb.size() != n)
        throw InputError(source, 0,
                         "log_prob has " + std::to_string(logProb.size()) + " rows, expected " +
                             std::to_string(n));
    for (std::size_t i = 0; i < n; ++i) {
        if (logProb[i].size() != n)
            throw InputError(source, 0,
                             "log_prob[" + std::to_string(i) + "] has " +
                                 std::to_string(logProb[i].size()) + " values, expected " +
                                 std::to_string(n));
        for (std::size_t k = 0; k < n; ++k)
            if (k != i && (!std::isfinite(logProb[i][k]) || logProb[i][k] > 0))
                throw InputError(source, 0,
                                 "log_prob[" + std::to_string(i) + "][" + std::to_string(k) +
                                     "] must be a finite log probability (≤ 0)");
    }
}

}  // namespace lipsyncd::dsp
