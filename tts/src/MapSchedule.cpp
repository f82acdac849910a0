#include <algorithm>
#include <filesystem>
#include <lipsyncd/tts.hpp>

namespace lipsyncd {

PhonemeSchedule mapSchedule(const PhonemeSchedule& raw, const PhonemeMap& map,
                            std::vector<std::string>* warnings) {
    PhonemeSchedule out;
    for (const auto& seg : raw) {
        if (map.isIgnored(seg.phoneme)) {
            // A mark takes no time of its own in practice; give its span to the neighbour.
            if (!out.empty()) out.back().end = seg.end;
            continue;
        }
        std::string phoneme = "sil";
        if (auto r = map.map(seg.phoneme)) {
            phoneme = r->phoneme;
            if (r->approximate && warnings)
                warnings->push_back("phoneme '" + seg.phoneme + "' approximated as '" + phoneme +
                                    "' (map " + map.name() + ")");
        } else if (warnings) {
            warnings->push_back("unknown phoneme '" + seg.phoneme + "' (not in map " +
                                map.name() + "); treated as silence");
        }
        const double start = out.empty() ? seg.start : out.back().end;
        if (!out.empty() && out.back().phoneme == phoneme)
            out.back().end = seg.end;
        else
            out.push_back({start, seg.end, phoneme, seg.confidence});
    }
    if (!out.empty() && out.front().start > 0) {
        if (out.front().phoneme == "sil")
            out.front().start = 0;
        else
            out.insert(out.begin(), {0.0, out.front().start, "sil", 1.0f});
    }
    return out;
}

namespace {
// "de, en, fr, ...": the languages of the espeak-LANG.toml files in `folder`, sorted.
std::string languagesWithMaps(const std::filesystem::path& folder) {
    std::vector<std::string> languages;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        const auto stem = entry.path().stem().string();
        if (entry.path().extension() == ".toml" && stem.rfind("espeak-", 0) == 0)
            languages.push_back(stem.substr(7));
    }
    std::sort(languages.begin(), languages.end());
    std::string out;
    for (const auto& l : languages) out += (out.empty() ? "" : ", ") + l;
    return out.empty() ? "no language" : out;
}
}  // namespace

PhonemeMap espeakMapForVoice(const std::string& voice) {
    // "en-us+f2" -> language "en"; "cmn" -> "cmn".
    std::string language = voice.substr(0, voice.find('+'));
    language = language.substr(0, language.find('-'));
    const std::string name = "espeak-" + language;
    const auto file = dataDirectory() / "phonemes" / (name + ".toml");
    if (!std::filesystem::exists(file))
        throw InputError("voice '" + voice + "': no phoneme map for language '" + language +
                         "' (expected " + file.string() + "; there are maps for " +
                         languagesWithMaps(file.parent_path()) + ")");
    return PhonemeMap::load(file);
}

}  // namespace lipsyncd
