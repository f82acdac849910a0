// Curve sets as data: JSON, one file per set (format in config/curves/README.md). Loading
// checks every bigram and pose and names the one at fault, as "FILE: bigrams.aa-bmp.open[2]: ...".
#include <lipsyncd/lipsync.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

namespace lipsyncd::lipsync {

namespace {
using nlohmann::json;
constexpr const char* kCurvesFormat = "lipsyncd-curves";
constexpr const char* kCharacterFormat = "lipsyncd-character";
constexpr int kVersion = 1;

json readJson(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open");
    try {
        return json::parse(in);
    } catch (const json::parse_error& e) {
        throw InputError(file.string() + ": not valid JSON (" + e.what() + ")");
    }
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& where, const std::string& what) {
    throw InputError(file.string() + ": " + where + ": " + what);
}

void checkHeader(const json& j, const std::filesystem::path& file, const char* format) {
    if (!j.is_object() || j.value("format", "") != format)
        fail(file, "format", std::string("expected \"") + format + "\"");
    if (!j.contains("version") || !j["version"].is_number_integer() || j["version"] != kVersion)
        fail(file, "version", "expected " + std::to_string(kVersion));
    if (!j.contains("name") || !j["name"].is_string()) fail(file, "name", "missing (a string)");
}

std::vector<ControlPoint> readPolygon(const json& points, const std::filesystem::path& file,
                                      const std::string& where) {
    if (!points.is_array() || points.size() < 2)
        fail(file, where, "expected a list of at least two [time, value] points");
    std::vector<ControlPoint> out;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const auto& p = points[i];
        const auto at = where + "[" + std::to_string(i) + "]";
        if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
            fail(file, at, "expected [time, value]");
        const auto t = p[0].get<double>(), v = p[1].get<double>();
        if (!(t >= 0 && t <= 1)) fail(file, at, "time must be in [0, 1]");
        if (!(v >= 0 && v <= 1)) fail(file, at, "value must be in [0, 1]");
        if (!out.empty() && !(t > out.back().time))
            fail(file, at, "times must increase (" + std::to_string(t) + " after " +
                               std::to_string(out.back().time) + ")");
        out.push_back({static_cast<float>(t), static_cast<float>(v)});
    }
    if (out.front().time != 0 || out.back().time != 1)
        fail(file, where, "the polygon must run from time 0 to time 1");
    return out;
}

// Reads {"a-b": {"pose": [[t, v], ...]}} into `set`; returns how many bigrams it read.
std::size_t readBigrams(const json& bigrams, const std::filesystem::path& file, const PoseSet& poses,
                        const PhonemeSet& phonemes, BigramCurveSet& set, std::vector<bool>* seen) {
    if (!bigrams.is_object()) fail(file, "bigrams", "expected an object of \"a-b\": {pose: points}");
    for (const auto& [key, curves] : bigrams.items()) {
        const auto where = "bigrams." + key;
        const auto dash = key.find('-');
        const auto first = phonemes.find(key.substr(0, dash));
        const auto second = dash == std::string::npos ? std::nullopt : phonemes.find(key.substr(dash + 1));
        if (!first || !second) fail(file, where, "not a pair of phoneme classes ('aa-bmp')");
        if (!curves.is_object()) fail(file, where, "expected an object of pose: points");
        for (std::size_t p = 0; p < poses.size(); ++p) set.setCurve(*first, *second, p, ControlCurve({{0, 0}, {1, 0}}));
        for (const auto& [pose, points] : curves.items()) {
            const auto idx = poses.find(pose);
            if (!idx) fail(file, where + "." + pose, "unknown pose (pose set '" + poses.name() + "')");
            set.setCurve(*first, *second, *idx, ControlCurve(readPolygon(points, file, where + "." + pose)));
        }
        if (seen) (*seen)[*first * phonemes.size() + *second] = true;
    }
    return bigrams.size();
}

void checkPoseSet(const json& j, const std::filesystem::path& file, const PoseSet& poses) {
    if (j.contains("pose_set") && (!j["pose_set"].is_string() || j["pose_set"] != poses.name()))
        fail(file, "pose_set", "the curves are for pose set " + j["pose_set"].dump() +
                                   ", not '" + poses.name() + "'");
}

std::filesystem::path resolveBase(const std::string& base, const std::filesystem::path& character) {
    const auto sibling = character.parent_path() / base;
    if (std::filesystem::exists(sibling)) return sibling;
    if (std::filesystem::exists(sibling.string() + ".json")) return sibling.string() + ".json";
    return findDataFile(std::filesystem::path("curves") / (base + ".json"));
}
}  // namespace

BigramCurveSet::BigramCurveSet(std::string name, const PoseSet& poses, const PhonemeSet& phonemes)
    : name_(std::move(name)), classes_(phonemes.size()), poses_(poses.size()),
      curves_(classes_ * classes_ * poses_) {}

const ControlCurve* BigramCurveSet::curve(std::size_t first, std::size_t second, std::size_t pose) const {
    const auto& c = curves_[slot(first, second, pose)];
    return c ? &*c : nullptr;
}

void BigramCurveSet::setCurve(std::size_t first, std::size_t second, std::size_t pose, ControlCurve curve) {
    const auto p = curve.polygon();
    const bool zero = std::all_of(p.begin(), p.end(), [](const ControlPoint& c) { return c.value == 0; });
    auto& slotRef = curves_[slot(first, second, pose)];
    if (zero)
        slotRef.reset();
    else
        slotRef = std::move(curve);
}

BigramCurveSet BigramCurveSet::load(const std::filesystem::path& file, const PoseSet& poses,
                                    const PhonemeSet& phonemes) {
    const auto j = readJson(file);
    if (j.is_object() && j.value("format", "") == kCharacterFormat) {
        checkHeader(j, file, kCharacterFormat);
        if (!j.contains("base") || !j["base"].is_string()) fail(file, "base", "missing (the curve set it starts from)");
        auto set = load(resolveBase(j["base"], file), poses, phonemes);
        set.applyOverrides(file, poses, phonemes);
        return set;
    }
    checkHeader(j, file, kCurvesFormat);
    checkPoseSet(j, file, poses);
    BigramCurveSet set(j["name"], poses, phonemes);
    if (j.contains("description") && j["description"].is_string()) set.description_ = j["description"];
    std::vector<bool> seen(phonemes.size() * phonemes.size(), false);
    readBigrams(j.value("bigrams", json::object()), file, poses, phonemes, set, &seen);
    for (std::size_t a = 0; a < phonemes.size(); ++a)
        for (std::size_t b = 0; b < phonemes.size(); ++b)
            if (!seen[a * phonemes.size() + b])
                fail(file, "bigrams", "missing pair '" + phonemes[a].name + "-" + phonemes[b].name +
                                          "' (a set covers every pair; list it with {} if no pose moves)");
    return set;
}

void BigramCurveSet::applyOverrides(const std::filesystem::path& characterFile, const PoseSet& poses,
                                    const PhonemeSet& phonemes) {
    const auto j = readJson(characterFile);
    checkHeader(j, characterFile, kCharacterFormat);
    checkPoseSet(j, characterFile, poses);
    readBigrams(j.value("bigrams", json::object()), characterFile, poses, phonemes, *this, nullptr);
    name_ = j["name"];
}

BigramCurveSet BigramCurveSet::named(const std::string& nameOrPath, const PoseSet& poses,
                                     const PhonemeSet& phonemes) {
    const std::filesystem::path p(nameOrPath);
    if (p.has_extension() || p.has_parent_path()) return load(findDataFile(p), poses, phonemes);
    return load(findDataFile(std::filesystem::path("curves") / (nameOrPath + ".json")), poses, phonemes);
}

void BigramCurveSet::save(const std::filesystem::path& file, const PoseSet& poseSet,
                          const PhonemeSet& set) const {
    json bigrams = json::object();
    auto rounded = [](float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0; };
    for (std::size_t a = 0; a < classes_; ++a)
        for (std::size_t b = 0; b < classes_; ++b) {
            json curves = json::object();
            for (std::size_t p = 0; p < poses_; ++p)
                if (const auto* c = curve(a, b, p)) {
                    json points = json::array();
                    for (const auto& pt : c->polygon()) points.push_back({rounded(pt.time), rounded(pt.value)});
                    curves[poseSet[p].name] = points;
                }
            bigrams[set[a].name + "-" + set[b].name] = curves;
        }
    // One bigram a line: a diff shows which pairs an edit or a rule change touched.
    std::ofstream out(file);
    if (!out) throw InputError(file.string() + ": cannot write");
    out << "{\n \"format\": \"" << kCurvesFormat << "\",\n \"version\": " << kVersion
        << ",\n \"name\": " << json(name_).dump() << ",\n \"description\": " << json(description_).dump()
        << ",\n \"pose_set\": " << json(poseSet.name()).dump() << ",\n \"bigrams\": {";
    bool first = true;
    for (const auto& [key, curves] : bigrams.items()) {
        out << (first ? "\n  " : ",\n  ") << json(key).dump() << ": " << curves.dump();
        first = false;
    }
    out << "\n }\n}\n";
}

}  // namespace lipsyncd::lipsync
