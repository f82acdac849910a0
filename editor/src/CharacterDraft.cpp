// The curves being edited. Xu et al. 2013, section 2.1: characters share the base set and replace
// single bigrams, so a save writes only the character's own bigrams; the base is never touched.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>

namespace lipsyncd::editor {

namespace {
using nlohmann::json;
using nlohmann::ordered_json;

json readCharacterJson(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open");
    return json::parse(in, nullptr, false);  // load() has checked it already
}

lipsync::BigramCurveSet loadStart(const std::filesystem::path& character,
                                  const std::string& baseCurves, const lipsync::PoseSet& poses,
                                  const PhonemeSet& phonemes) {
    if (!character.empty() && std::filesystem::exists(character))
        return lipsync::BigramCurveSet::load(character, poses, phonemes);
    return lipsync::BigramCurveSet::named(baseCurves, poses, phonemes);
}

// How a new character file names its base: the short name as given, or a path relative to the
// character file (the loader looks beside the character first).
std::string baseReference(const std::string& baseCurves, const std::filesystem::path& character) {
    const std::filesystem::path given(baseCurves);
    if (!given.has_extension() && !given.has_parent_path()) return baseCurves;
    const auto file = std::filesystem::absolute(findNamedDataFile(baseCurves, "curves", ".json"));
    const auto dir = std::filesystem::absolute(character).parent_path();
    return file.lexically_relative(dir).string();
}

// Saved with three decimals, as the curve-set writer does: what the page shows is what is saved.
float rounded(float v) {
    return static_cast<float>(std::round(static_cast<double>(v) * 1000) / 1000);
}
double asSaved(float v) {
    return std::round(static_cast<double>(v) * 1000) / 1000;
}

std::string pairName(const PhonemeSet& phonemes, std::size_t a, std::size_t b) {
    return phonemes[a].name + "-" + phonemes[b].name;
}
}  // namespace

std::string_view toString(BigramState state) {
    switch (state) {
        case BigramState::generated:
            return "generated";
        case BigramState::character:
            return "character";
        case BigramState::edited:
            return "edited";
    }
    return "generated";
}

CharacterDraft::CharacterDraft(lipsync::PoseSet poses, const PhonemeSet& phonemes,
                               const std::string& baseCurves, std::filesystem::path characterFile)
    : poses_(std::move(poses)),
      phonemes_(&phonemes),
      file_(std::move(characterFile)),
      saved_(loadStart(file_, baseCurves, poses_, phonemes)),
      working_(saved_) {
    if (file_.empty()) {
        base_ = baseCurves;
        return;
    }
    if (!std::filesystem::exists(file_)) {
        base_ = baseReference(baseCurves, file_);
        name_ = file_.stem().string();
        return;
    }
    const auto j = readCharacterJson(file_);
    base_ = j.value("base", baseCurves);
    name_ = j.value("name", file_.stem().string());
    description_ = j.value("description", "");
    const auto bigrams = j.value("bigrams", json::object());
    for (const auto& [key, curves] : bigrams.items()) {
        const auto dash = key.find('-');
        inCharacter_.emplace(*phonemes.find(key.substr(0, dash)),
                             *phonemes.find(key.substr(dash + 1)));
    }
}

bool CharacterDraft::differs(const lipsync::BigramCurveSet& a, const lipsync::BigramCurveSet& b,
                             std::size_t first, std::size_t second) const {
    for (std::size_t p = 0; p < poses_.size(); ++p) {
        const auto* ca = a.curve(first, second, p);
        const auto* cb = b.curve(first, second, p);
        if (!ca || !cb) {
            if (ca != cb) return true;
            continue;
        }
        if (!std::ranges::equal(ca->polygon(), cb->polygon())) return true;
    }
    return false;
}

BigramState CharacterDraft::state(std::size_t first, std::size_t second) const {
    if (differs(working_, saved_, first, second)) return BigramState::edited;
    if (inCharacter_.contains({first, second})) return BigramState::character;
    return BigramState::generated;
}

std::vector<std::vector<lipsync::ControlPoint>> CharacterDraft::polygons(std::size_t first,
                                                                         std::size_t second) const {
    std::vector<std::vector<lipsync::ControlPoint>> out;
    for (std::size_t p = 0; p < poses_.size(); ++p) {
        const auto* c = working_.curve(first, second, p);
        if (c)
            out.emplace_back(c->polygon().begin(), c->polygon().end());
        else
            out.push_back({{0, 0}, {1, 0}});
    }
    return out;
}

void CharacterDraft::replace(std::size_t first, std::size_t second, std::string_view posesJson,
                             const std::string& source) {
    const auto key = pairName(*phonemes_, first, second);
    lipsync::BigramCurveSet scratch("edit", poses_, *phonemes_);
    scratch.applyBigramsJson("{" + json(key).dump() + ": " + std::string(posesJson) + "}", source,
                             poses_, *phonemes_);
    std::vector<lipsync::ControlCurve> curves;
    for (std::size_t p = 0; p < poses_.size(); ++p) {
        const auto* c = scratch.curve(first, second, p);
        std::vector<lipsync::ControlPoint> points{{0, 0}, {1, 0}};
        if (c) points.assign(c->polygon().begin(), c->polygon().end());
        for (std::size_t i = 0; i < points.size(); ++i) {
            points[i] = {rounded(points[i].time), rounded(points[i].value)};
            if (i > 0 && !(points[i].time > points[i - 1].time))
                throw InputError(source + ": bigrams." + key + "." + poses_[p].name + "[" +
                                 std::to_string(i) +
                                 "]: closer than 0.001 in time to the point before");
        }
        curves.emplace_back(std::move(points));
    }
    for (std::size_t p = 0; p < poses_.size(); ++p)
        working_.setCurve(first, second, p, std::move(curves[p]));
}

std::size_t CharacterDraft::unsaved() const {
    std::size_t n = 0;
    for (std::size_t a = 0; a < phonemes_->size(); ++a)
        for (std::size_t b = 0; b < phonemes_->size(); ++b)
            n += differs(working_, saved_, a, b) ? 1 : 0;
    return n;
}

std::string CharacterDraft::characterJson() const {
    ordered_json head;
    head["format"] = "lipsyncd-character";
    head["version"] = 1;
    head["name"] = name_;
    if (!description_.empty()) head["description"] = description_;
    head["base"] = base_;
    head["pose_set"] = poses_.name();
    std::string out = "{\n";
    for (const auto& [k, v] : head.items()) out += " " + json(k).dump() + ": " + v.dump() + ",\n";
    out += " \"bigrams\": {";
    bool firstBigram = true;
    for (std::size_t a = 0; a < phonemes_->size(); ++a)
        for (std::size_t b = 0; b < phonemes_->size(); ++b) {
            if (!inCharacter_.contains({a, b}) && !differs(working_, saved_, a, b)) continue;
            ordered_json curves = ordered_json::object();
            for (std::size_t p = 0; p < poses_.size(); ++p)
                if (const auto* c = working_.curve(a, b, p)) {
                    auto& points = curves[poses_[p].name] = ordered_json::array();
                    for (const auto& pt : c->polygon())
                        points.push_back({asSaved(pt.time), asSaved(pt.value)});
                }
            out += std::string(firstBigram ? "\n" : ",\n") + "  " +
                   json(pairName(*phonemes_, a, b)).dump() + ": " + curves.dump();
            firstBigram = false;
        }
    out += "\n }\n}\n";
    return out;
}

std::size_t CharacterDraft::save() {
    if (file_.empty())
        throw InputError("no character file to save to: start `lipsync edit --character FILE`");
    // Written beside the file and renamed over it, so a failed save leaves the old file whole.
    auto saving = file_;
    saving += ".saving";
    {
        std::ofstream out(saving);
        out << characterJson();
        if (!out.flush()) throw InputError(file_.string() + ": cannot write");
    }
    try {
        (void)lipsync::BigramCurveSet::load(saving, poses_, *phonemes_);
    } catch (const InputError& e) {
        std::filesystem::remove(saving);
        std::string what = e.what();
        if (what.starts_with(saving.string()))
            what.replace(0, saving.string().size(), file_.string());
        throw InputError(what + " (not saved)");
    }
    std::filesystem::rename(saving, file_);
    std::size_t written = 0;
    for (std::size_t a = 0; a < phonemes_->size(); ++a)
        for (std::size_t b = 0; b < phonemes_->size(); ++b)
            if (inCharacter_.contains({a, b}) || differs(working_, saved_, a, b)) {
                inCharacter_.emplace(a, b);
                ++written;
            }
    saved_ = working_;
    return written;
}

}  // namespace lipsyncd::editor
