// Curve sets as data: JSON, one file per set (format in config/curves/README.md). Loading
// checks every bigram and pose and names the one at fault, as "FILE: bigrams.aa-bmp.open[2]: ...".
#include <cmath>
#include <fstream>
#include <lipsyncd/lipsync.hpp>
#include <nlohmann/json.hpp>

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
    } catch (const json::exception& e) {  // bad syntax, or a number out of range (1e600)
        throw InputError(file.string() + ": not valid JSON (" + e.what() + ")");
    }
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& where,
                       const std::string& what) {
    throw InputError(file.string() + ": " + where + ": " + what);
}

// The "format" string, "" when absent or not a string (json::value would throw on a number).
std::string formatOf(const json& j) {
    return j.is_object() && j.contains("format") && j["format"].is_string()
               ? j["format"].get<std::string>()
               : std::string();
}

void checkHeader(const json& j, const std::filesystem::path& file, const char* format) {
    if (formatOf(j) != format) fail(file, "format", std::string("expected \"") + format + "\"");
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
            fail(file, at,
                 "times must increase (" + std::to_string(t) + " after " +
                     std::to_string(out.back().time) + ")");
        out.push_back({static_cast<float>(t), static_cast<float>(v)});
    }
    if (out.front().time != 0 || out.back().time != 1)
        fail(file, where, "the polygon must run from time 0 to time 1");
    return out;
}

// Reads {"a-b": {"pose": [[t, v], ...]}} into `set`; returns how many bigrams it read.
std::size_t readBigrams(const json& bigrams, const std::filesystem::path& file,
                        const PoseSet& poses, const PhonemeSet& phonemes, BigramCurveSet& set) {
    if (!bigrams.is_object())
        fail(file, "bigrams", "expected an object of \"a-b\": {pose: points}");
    for (const auto& [key, curves] : bigrams.items()) {
        const auto where = "bigrams." + key;
        const auto dash = key.find('-');
        const auto first = phonemes.find(key.substr(0, dash));
        const auto second =
            dash == std::string::npos ? std::nullopt : phonemes.find(key.substr(dash + 1));
        if (!first || !second) fail(file, where, "not a pair of phoneme classes ('aa-bmp')");
        if (!curves.is_object()) fail(file, where, "expected an object of pose: points");
        for (std::size_t p = 0; p < poses.size(); ++p)
            set.setCurve(*first, *second, p, ControlCurve({{0, 0}, {1, 0}}));
        for (const auto& [pose, points] : curves.items()) {
            const auto idx = poses.find(pose);
            if (!idx)
                fail(file, where + "." + pose, "unknown pose (pose set '" + poses.name() + "')");
            set.setCurve(*first, *second, *idx,
                         ControlCurve(readPolygon(points, file, where + "." + pose)));
        }
    }
    return bigrams.size();
}

void checkPoseSet(const json& j, const std::filesystem::path& file, const PoseSet& poses) {
    if (j.contains("pose_set") && (!j["pose_set"].is_string() || j["pose_set"] != poses.name()))
        fail(
            file, "pose_set",
            "the curves are for pose set " + j["pose_set"].dump() + ", not '" + poses.name() + "'");
}

std::filesystem::path resolveBase(const std::string& base, const std::filesystem::path& character) {
    const auto sibling = character.parent_path() / base;
    if (std::filesystem::exists(sibling)) return sibling;
    if (std::filesystem::exists(sibling.string() + ".json")) return sibling.string() + ".json";
    return findDataFile(std::filesystem::path("curves") / (base + ".json"));
}
}  // namespace

BigramCurveSet::BigramCurveSet(std::string name, const PoseSet& poses, const PhonemeSet& phonemes)
    : name_(std::move(name)),
      classes_(phonemes.size()),
      poses_(poses.size()),
      curves_(classes_ * classes_ * poses_),
      defined_(classes_ * classes_, false) {}

const ControlCurve* BigramCurveSet::curve(std::size_t first, std::size_t second,
                                          std::size_t pose) const {
    const auto& c = curves_[slot(first, second, pose)];
    return c ? &*c : nullptr;
}

void BigramCurveSet::setCurve(std::size_t first, std::size_t second, std::size_t pose,
                              ControlCurve curve) {
    defined_[first * classes_ + second] = true;
    const auto p = curve.polygon();
    const bool zero =
        std::all_of(p.begin(), p.end(), [](const ControlPoint& c) { return c.value == 0; });
    auto& slotRef = curves_[slot(first, second, pose)];
    if (zero)
        slotRef.reset();
    else
        slotRef = std::move(curve);
}

BigramCurveSet BigramCurveSet::load(const std::filesystem::path& file, const PoseSet& poses,
                                    const PhonemeSet& phonemes) {
    try {
        return loadSet(file, poses, phonemes, true);
    } catch (const json::exception& e) {  // a value of a type no check above expected
        throw InputError(file.string() + ": unexpected JSON (" + e.what() + ")");
    }
}

// A character's base may cover fewer classes than `phonemes` (a language adding one, as paper
// 000 section 4.4 does for Mandarin): every pair is required once the overrides are in.
BigramCurveSet BigramCurveSet::loadSet(const std::filesystem::path& file, const PoseSet& poses,
                                       const PhonemeSet& phonemes, bool requireEveryPair) {
    const auto j = readJson(file);
    if (formatOf(j) == kCharacterFormat) {
        checkHeader(j, file, kCharacterFormat);
        if (!j.contains("base") || !j["base"].is_string())
            fail(file, "base", "missing (the curve set it starts from)");
        auto set = loadSet(resolveBase(j["base"], file), poses, phonemes, false);
        set.applyOverrides(file, poses, phonemes);
        if (requireEveryPair) set.requireEveryPair(file, phonemes);
        return set;
    }
    checkHeader(j, file, kCurvesFormat);
    checkPoseSet(j, file, poses);
    BigramCurveSet set(j["name"], poses, phonemes);
    if (j.contains("description") && j["description"].is_string())
        set.description_ = j["description"];
    readBigrams(j.value("bigrams", json::object()), file, poses, phonemes, set);
    if (requireEveryPair) set.requireEveryPair(file, phonemes);
    return set;
}

void BigramCurveSet::requireEveryPair(const std::filesystem::path& file,
                                      const PhonemeSet& phonemes) const {
    for (std::size_t a = 0; a < phonemes.size(); ++a)
        for (std::size_t b = 0; b < phonemes.size(); ++b)
            if (!defined_[a * classes_ + b])
                fail(file, "bigrams",
                     "missing pair '" + phonemes[a].name + "-" + phonemes[b].name +
                         "' (a set covers every pair; list it with {} if no pose moves)");
}

void BigramCurveSet::applyOverrides(const std::filesystem::path& characterFile,
                                    const PoseSet& poses, const PhonemeSet& phonemes) {
    const auto j = readJson(characterFile);
    checkHeader(j, characterFile, kCharacterFormat);
    checkPoseSet(j, characterFile, poses);
    readBigrams(j.value("bigrams", json::object()), characterFile, poses, phonemes, *this);
    name_ = j["name"];
}

void BigramCurveSet::applyBigramsJson(std::string_view bigramsJson, const std::string& source,
                                      const PoseSet& poses, const PhonemeSet& phonemes) {
    json j;
    try {
        j = json::parse(bigramsJson);
    } catch (const json::exception& e) {  // bad syntax, or a number out of range
        throw InputError(source + ": not valid JSON (" + e.what() + ")");
    }
    try {
        readBigrams(j, source, poses, phonemes, *this);
    } catch (const json::exception& e) {  // a value of a type no check expected, as in load()
        throw InputError(source + ": unexpected JSON (" + e.what() + ")");
    }
}

BigramCurveSet BigramCurveSet::named(const std::string& nameOrPath, const PoseSet& poses,
                                     const PhonemeSet& phonemes) {
    return load(findNamedDataFile(nameOrPath, "curves", ".json"), poses, phonemes);
}

namespace {
json bigramsJson(const BigramCurveSet& s, const PoseSet& poseSet, const PhonemeSet& set,
                 std::optional<std::size_t> onlyWith) {
    json bigrams = json::object();
    auto rounded = [](float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0; };
    for (std::size_t a = 0; a < s.classes(); ++a)
        for (std::size_t b = 0; b < s.classes(); ++b) {
            if (onlyWith && a != *onlyWith && b != *onlyWith) continue;
            json curves = json::object();
            for (std::size_t p = 0; p < s.poses(); ++p)
                if (const auto* c = s.curve(a, b, p)) {
                    json points = json::array();
                    for (const auto& pt : c->polygon())
                        points.push_back({rounded(pt.time), rounded(pt.value)});
                    curves[poseSet[p].name] = points;
                }
            bigrams[set[a].name + "-" + set[b].name] = curves;
        }
    return bigrams;
}

// One bigram a line: a diff shows which pairs an edit or a rule change touched.
void writeSet(const std::filesystem::path& file, const json& header, const json& bigrams) {
    std::ofstream out(file);
    if (!out) throw InputError(file.string() + ": cannot write");
    out << "{";
    bool first = true;
    for (const auto& [key, value] : header.items()) {
        out << (first ? "\n " : ",\n ") << json(key).dump() << ": " << value.dump();
        first = false;
    }
    out << ",\n \"bigrams\": {";
    first = true;
    for (const auto& [key, curves] : bigrams.items()) {
        out << (first ? "\n  " : ",\n  ") << json(key).dump() << ": " << curves.dump();
        first = false;
    }
    out << "\n }\n}\n";
}
}  // namespace

void BigramCurveSet::save(const std::filesystem::path& file, const PoseSet& poseSet,
                          const PhonemeSet& set) const {
    const json header = {{"format", kCurvesFormat},
                         {"version", kVersion},
                         {"name", name_},
                         {"description", description_},
                         {"pose_set", poseSet.name()}};
    writeSet(file, header, bigramsJson(*this, poseSet, set, std::nullopt));
}

void BigramCurveSet::saveAdditions(const std::filesystem::path& file, const std::string& base,
                                   std::size_t onlyWith, const PoseSet& poseSet,
                                   const PhonemeSet& set) const {
    const json header = {
        {"format", kCharacterFormat},  {"version", kVersion}, {"name", name_},
        {"description", description_}, {"base", base},        {"pose_set", poseSet.name()}};
    writeSet(file, header, bigramsJson(*this, poseSet, set, onlyWith));
}

}  // namespace lipsyncd::lipsync
