// A speaker's learnt frames in a file: {"format": "lipsyncd-speaker", "version": 1, "base":
// FINGERPRINT, "heard": [{"template": INDEX, "frames": N, "sum": [one number a feature]}, ...]},
// and the networks trained further on them when there are any ("class_network", "jaw_network",
// as in a template file; files written before they existed have none). Only the templates heard
// are written; the fingerprint ties the sums to the base set they were assigned against (another
// set's template indices mean other sounds).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <lipsyncd/dsp.hpp>
#include <sstream>

#include "JsonField.hpp"
#include "NetworkJson.hpp"
#include "TemplateMatrix.hpp"

namespace lipsyncd::dsp {

namespace {
constexpr const char* kFormat = "lipsyncd-speaker";
constexpr int kVersion = 1;

// FNV-1a over the classes' names and the bits of their templates (Fowler, Noll & Vo).
std::string fingerprint(const TemplateSet& base) {
    std::uint64_t h = 1469598103934665603ull;
    const auto mix = [&](const void* data, std::size_t n) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
    };
    for (const auto& cls : base.classes) {
        mix(cls.phoneme.data(), cls.phoneme.size() + 1);
        for (const auto& spectrum : cls.spectra)
            mix(spectrum.data(), spectrum.size() * sizeof(float));
    }
    std::ostringstream s;
    s << std::hex << std::setw(16) << std::setfill('0') << h;
    return s.str();
}

// The networks a speaker file carries, each valid and of the base's own network's shape (its
// weights trained further: another set's networks, or none, are another base).
std::pair<std::optional<ClassNetwork>, std::optional<JawNetwork>> readNetworks(
    const nlohmann::json& j, const TemplateSet& base, const std::string& source) {
    const auto features = static_cast<std::size_t>(base.analysis.featureCount());
    std::optional<ClassNetwork> classNetwork;
    std::optional<JawNetwork> jawNetwork;
    if (j.contains("class_network")) {
        classNetwork = readClassNetwork(j["class_network"], source);
        classNetwork->validate(features, source);
        if (!base.classNetwork || base.classNetwork->classes != classNetwork->classes ||
            base.classNetwork->hiddenUnits() != classNetwork->hiddenUnits() ||
            base.classNetwork->slopeFrames != classNetwork->slopeFrames)
            throw InputError(source, 0,
                             "field 'class_network': not the base set's class network trained "
                             "further; start again with `speaker reset`");
    }
    if (j.contains("jaw_network")) {
        jawNetwork = readJawNetwork(j["jaw_network"], source);
        jawNetwork->validate(features, source);
        if (!base.jawNetwork || base.jawNetwork->hiddenUnits() != jawNetwork->hiddenUnits() ||
            base.jawNetwork->slopeFrames != jawNetwork->slopeFrames)
            throw InputError(source, 0,
                             "field 'jaw_network': not the base set's jaw network trained "
                             "further; start again with `speaker reset`");
    }
    return {std::move(classNetwork), std::move(jawNetwork)};
}
}  // namespace

void SpeakerAdaptation::save(const std::filesystem::path& file) const {
    const std::size_t features = weighting_->features();
    auto heard = nlohmann::json::array();
    for (std::size_t t = 0; t < counts_.size(); ++t) {
        if (counts_[t] <= 0) continue;
        const auto* sum = &sums_[t * features];
        heard.push_back({{"template", t},
                         {"frames", counts_[t]},
                         {"sum", std::vector<double>(sum, sum + features)}});
    }
    nlohmann::json j = {
        {"format", kFormat}, {"version", kVersion}, {"base", fingerprint(base_)}, {"heard", heard}};
    if (classNetwork_) j["class_network"] = writeClassNetwork(*classNetwork_);
    if (jawNetwork_) j["jaw_network"] = writeJawNetwork(*jawNetwork_);
    auto temporary = file;
    temporary += ".tmp";
    {
        std::ofstream out(temporary);
        if (!out) throw InputError(temporary.string() + ": cannot write");
        out << j.dump() << '\n';
        if (!out.flush()) throw InputError(temporary.string() + ": write failed");
    }
    std::error_code ec;
    std::filesystem::rename(temporary, file, ec);
    if (ec) throw InputError(file.string() + ": cannot replace (" + ec.message() + ")");
}

void SpeakerAdaptation::load(const std::filesystem::path& file) {
    const std::string source = file.string();
    const auto j = readDataDocument(file, kFormat, kVersion);
    if (member<std::string>(j, "base", "", source) != fingerprint(base_))
        throw InputError(source, 0,
                         "field 'base': learnt on other templates than these (" +
                             base_.description + "); start again with `speaker reset`");
    const auto heard = member<nlohmann::json>(j, "heard", "", source);
    if (!heard.is_array()) throw InputError(source, 0, "field 'heard' must be an array");
    const std::size_t features = weighting_->features();
    std::vector<double> sums(sums_.size(), 0.0), counts(counts_.size(), 0.0);
    double frames = 0;
    for (std::size_t i = 0; i < heard.size(); ++i) {
        const std::string p = "heard[" + std::to_string(i) + "].";
        const auto t = member<std::size_t>(heard[i], "template", p, source);
        const auto n = member<double>(heard[i], "frames", p, source);
        const auto sum = member<std::vector<double>>(heard[i], "sum", p, source);
        if (t >= counts.size())
            throw InputError(source, 0,
                             "field '" + p + "template' is beyond the base set's " +
                                 std::to_string(counts.size()) + " templates");
        if (!(n > 0) || !std::isfinite(n))
            throw InputError(source, 0, "field '" + p + "frames' must be a positive number");
        if (sum.size() != features)
            throw InputError(
                source, 0,
                "field '" + p + "sum' must have " + std::to_string(features) + " numbers");
        for (const double v : sum)
            if (!std::isfinite(v))
                throw InputError(source, 0, "field '" + p + "sum' has a number that is not finite");
        std::copy(sum.begin(), sum.end(), sums.begin() + static_cast<std::ptrdiff_t>(t * features));
        counts[t] = n;
        frames += n;
    }
    auto [classNetwork, jawNetwork] = readNetworks(j, base_, source);
    sums_ = std::move(sums);
    counts_ = std::move(counts);
    frames_ = static_cast<std::size_t>(std::llround(frames));
    classNetwork_ = std::move(classNetwork);
    jawNetwork_ = std::move(jawNetwork);
}

}  // namespace lipsyncd::dsp
