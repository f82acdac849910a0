// Spectral templates as data: JSON under config/templates/ (format in its README.md).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>

#include "JsonField.hpp"
#include "NetworkJson.hpp"

namespace lipsyncd::dsp {

namespace {
using nlohmann::json;
constexpr const char* kFormat = "lipsyncd-templates";
constexpr int kVersion = 1;

AnalysisConfig readAnalysis(const json& a, const std::string& source) {
    AnalysisConfig c;
    const std::string p = "analysis.";
    c.analysisRate = member<int>(a, "rate", p, source);
    c.hopSeconds = member<double>(a, "hop", p, source);
    c.windowSeconds = member<double>(a, "window", p, source);
    c.order = member<int>(a, "order", p, source);
    c.preEmphasis = member<double>(a, "pre_emphasis", p, source);
    c.lagWindowHz = member<double>(a, "lag_window_hz", p, source);
    c.whiteNoiseCorrection = member<double>(a, "white_noise_correction", p, source);
    c.spectrumBins = member<int>(a, "bins", p, source);
    // Optional (sets written before it existed have none): names of features after the spectrum.
    if (a.contains("extra_features")) {
        for (const auto& name : member<std::vector<std::string>>(a, "extra_features", p, source)) {
            if (name == "log_error")
                c.errorFeature = true;
            else if (name == "level")
                c.levelFeature = true;
            else
                throw InputError(source, 0,
                                 "analysis.extra_features: unknown feature '" + name +
                                     "' (known: log_error, level)");
        }
        if (c.levelFeature)
            c.levelPeakDecayDbPerSecond = member<double>(a, "level_peak_decay", p, source);
    }
    // Optional: the channel normalisation's starting mean (AnalysisConfig::spectrumMean).
    if (a.contains("spectrum_mean")) {
        c.spectrumMean = member<std::vector<float>>(a, "spectrum_mean", p, source);
        c.meanPriorSeconds = member<double>(a, "mean_prior_seconds", p, source);
        c.meanMemorySeconds = member<double>(a, "mean_memory_seconds", p, source);
    }
    // Optional: a speaker's vocal-tract-length warp (lipsync calibrate), 1 when absent.
    if (a.contains("warp")) c.warp = member<double>(a, "warp", p, source);
    try {
        c.validate();
    } catch (const InputError& e) {
        throw InputError(source, 0, e.what());
    }
    return c;
}

std::vector<double> rounded(const std::vector<float>& v);

json writeAnalysis(const AnalysisConfig& c) {
    json a = {{"rate", c.analysisRate},
              {"hop", c.hopSeconds},
              {"window", c.windowSeconds},
              {"order", c.order},
              {"pre_emphasis", c.preEmphasis},
              {"lag_window_hz", c.lagWindowHz},
              {"white_noise_correction", c.whiteNoiseCorrection},
              {"bins", c.spectrumBins}};
    auto& extra = a["extra_features"] = json::array();
    if (c.errorFeature) extra.push_back("log_error");
    if (c.levelFeature) {
        extra.push_back("level");
        a["level_peak_decay"] = c.levelPeakDecayDbPerSecond;
    }
    if (c.warp != 1.0) a["warp"] = c.warp;
    if (!c.spectrumMean.empty()) {
        a["spectrum_mean"] = rounded(c.spectrumMean);
        a["mean_prior_seconds"] = c.meanPriorSeconds;
        a["mean_memory_seconds"] = c.meanMemorySeconds;
    }
    return a;
}

// Three decimals (0.001 dB is far below anything a distance can tell) as doubles, so the file
// shows 1.034 rather than the float's 1.034000039100647.
std::vector<double> rounded(const std::vector<float>& v) {
    std::vector<double> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        out[i] = std::round(static_cast<double>(v[i]) * 1000.0) / 1000.0;
    return out;
}
}  // namespace

void TemplateSet::validate(const std::string& source) const {
    // One weight and one template value per feature: the spectrum's bins, then the extras.
    const auto bins = static_cast<std::size_t>(analysis.featureCount());
    if (binWeights.size() != bins)
        throw InputError(source, 0,
                         "bin_weights has " + std::to_string(binWeights.size()) +
                             " values, the analysis has " + std::to_string(bins) + " features");
    for (std::size_t b = 0; b < bins; ++b)
        if (!(binWeights[b] >= 0) || !std::isfinite(binWeights[b]))
            throw InputError(source, 0, "bin_weights[" + std::to_string(b) + "] must be >= 0");
    if (!whitening.empty()) {
        if (whitening.size() != bins)
            throw InputError(source, 0,
                             "whitening has " + std::to_string(whitening.size()) +
                                 " rows, the analysis has " + std::to_string(bins) + " features");
        for (std::size_t r = 0; r < bins; ++r) {
            const std::string where = "whitening[" + std::to_string(r) + "]";
            if (whitening[r].size() != bins)
                throw InputError(source, 0,
                                 where + " has " + std::to_string(whitening[r].size()) +
                                     " values, expected " + std::to_string(bins));
            for (std::size_t c = 0; c < bins; ++c)
                if (!std::isfinite(whitening[r][c]) || (c > r && whitening[r][c] != 0))
                    throw InputError(source, 0,
                                     where + "[" + std::to_string(c) +
                                         "]: values must be finite, and 0 above the diagonal "
                                         "(the matrix is lower triangular)");
            if (!(whitening[r][r] > 0))
                throw InputError(source, 0,
                                 where + "[" + std::to_string(r) + "]: the diagonal must be > 0");
        }
    }
    if (jawNetwork) jawNetwork->validate(bins, source);
    if (classes.empty()) throw InputError(source, 0, "no classes");
    const PhonemeSet& set = PhonemeSet::common();
    if (classNetwork) {
        classNetwork->validate(bins, source);
        const auto& names = classNetwork->classes;
        for (std::size_t c = 0; c < names.size(); ++c) {
            const std::string where = "class_network.classes[" + std::to_string(c) + "]";
            if (!set.find(names[c]))
                throw InputError(source, 0, where + ": '" + names[c] + "' is not a phoneme class");
            if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(c),
                          names[c]) != names.begin() + static_cast<std::ptrdiff_t>(c))
                throw InputError(source, 0, where + ": '" + names[c] + "' listed twice");
        }
    }
    // Within ±20 dB: a fitted correction moves a class by a dB or so; more is a broken file.
    for (const auto& [name, db] : classBiasDb) {
        const std::string where = "class_bias_db." + name;
        if (!set.find(name))
            throw InputError(source, 0, where + ": '" + name + "' is not a phoneme class");
        if (!std::isfinite(db) || std::abs(db) > 20)
            throw InputError(source, 0, where + ": must be a finite dB within ±20");
    }
    for (std::size_t c = 0; c < classes.size(); ++c) {
        const auto& cls = classes[c];
        const std::string where = "classes[" + std::to_string(c) + "] ('" + cls.phoneme + "')";
        if (!set.find(cls.phoneme))
            throw InputError(source, 0, where + ": '" + cls.phoneme + "' is not a phoneme class");
        for (std::size_t d = 0; d < c; ++d)
            if (classes[d].phoneme == cls.phoneme)
                throw InputError(source, 0, where + ": class listed twice");
        if (cls.spectra.empty()) throw InputError(source, 0, where + ": no spectra");
        for (std::size_t s = 0; s < cls.spectra.size(); ++s) {
            if (cls.spectra[s].size() != bins)
                throw InputError(source, 0,
                                 where + ".spectra[" + std::to_string(s) + "] has " +
                                     std::to_string(cls.spectra[s].size()) + " values, expected " +
                                     std::to_string(bins));
            for (float v : cls.spectra[s])
                if (!std::isfinite(v) || std::abs(v) > 200)
                    throw InputError(source, 0,
                                     where + ".spectra[" + std::to_string(s) +
                                         "]: values must be finite dB within ±200");
        }
    }
}

TemplateSet TemplateSet::load(const std::filesystem::path& file) {
    const std::string source = file.string();
    const json j = readDataDocument(file, kFormat, kVersion);
    TemplateSet t;
    t.description = j.value("description", "");
    t.analysis = readAnalysis(member<json>(j, "analysis", "", source), source);
    t.binWeights = member<std::vector<float>>(j, "bin_weights", "", source);
    if (j.contains("whitening"))
        t.whitening = member<std::vector<std::vector<float>>>(j, "whitening", "", source);
    if (j.contains("jaw_network"))
        t.jawNetwork = readJawNetwork(member<json>(j, "jaw_network", "", source), source);
    if (j.contains("class_network"))
        t.classNetwork = readClassNetwork(member<json>(j, "class_network", "", source), source);
    if (j.contains("class_bias_db"))
        t.classBiasDb = member<std::map<std::string, float>>(j, "class_bias_db", "", source);
    const auto classes = member<json>(j, "classes", "", source);
    if (!classes.is_array()) throw InputError(source, 0, "field 'classes' must be an array");
    for (std::size_t i = 0; i < classes.size(); ++i) {
        const std::string p = "classes[" + std::to_string(i) + "].";
        ClassTemplates c;
        c.phoneme = member<std::string>(classes[i], "phoneme", p, source);
        c.spectra = member<std::vector<std::vector<float>>>(classes[i], "spectra", p, source);
        c.frames = classes[i].value("frames", std::size_t{0});
        t.classes.push_back(std::move(c));
    }
    t.validate(source);
    return t;
}

TemplateSet TemplateSet::loadDefault() {
    return load(findDataFile("templates/default.json"));
}

TemplateSet TemplateSet::named(const std::string& nameOrPath) {
    if (nameOrPath.empty()) return loadDefault();
    return load(findNamedDataFile(nameOrPath, "templates", ".json"));
}

void TemplateSet::save(const std::filesystem::path& file) const {
    validate(file.string());
    json classesJson = json::array();
    for (const auto& c : classes) {
        json spectra = json::array();
        for (const auto& s : c.spectra) spectra.push_back(rounded(s));
        classesJson.push_back({{"phoneme", c.phoneme}, {"frames", c.frames}, {"spectra", spectra}});
    }
    json j = {{"format", kFormat},
              {"version", kVersion},
              {"description", description},
              {"analysis", writeAnalysis(analysis)},
              {"bin_weights", rounded(binWeights)},
              {"classes", classesJson}};
    if (!whitening.empty()) {
        json rows = json::array();
        for (const auto& row : whitening) rows.push_back(precise(row));
        j["whitening"] = rows;
    }
    if (jawNetwork) j["jaw_network"] = writeJawNetwork(*jawNetwork);
    if (classNetwork) j["class_network"] = writeClassNetwork(*classNetwork);
    if (!classBiasDb.empty()) {
        json bias = json::object();
        for (const auto& [name, db] : classBiasDb)
            bias[name] = std::round(static_cast<double>(db) * 1000) / 1000;  // to 1/1000 dB
        j["class_bias_db"] = bias;
    }
    std::ofstream out(file);
    if (!out) throw InputError(file.string() + ": cannot write");
    out << j.dump(1) << '\n';
    if (!out) throw InputError(file.string() + ": write failed");
}

}  // namespace lipsyncd::dsp
