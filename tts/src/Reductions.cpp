// Common reductions (config/reductions/<language>.toml): the other ways a script's words are said
// in running speech, which the forced aligner tries beside espeak-ng's careful reading.
#include <algorithm>
#include <cctype>
#include <lipsyncd/toml_table.hpp>
#include <lipsyncd/tts.hpp>
#include <sstream>

#include "Utf8.hpp"

namespace lipsyncd {

namespace {
// A word's alternatives, its own reading included, are capped: each is a parallel path.
constexpr std::size_t kMaxPronunciations = 6;

std::vector<std::string> splitPhonemes(const std::string& s) {
    std::istringstream in(s);
    std::vector<std::string> out;
    for (std::string p; in >> p;) out.push_back(p);
    return out;
}

// Letters are kept; ASCII and Latin-1 punctuation (« » among it) and general punctuation
// (“ ” — …: U+2000..U+206F) are not.
bool isLetter(char32_t c) {
    if (c < 0x80) return std::isalpha(static_cast<int>(c)) || c == U'\'';
    if (c < 0xC0) return false;
    return c != 0xD7 && c != 0xF7 && !(c >= 0x2000 && c <= 0x206F);
}

// "And," → "and", "«Со" → "со": the written word as the [words] table keys it.
std::string keyOf(const std::string& written) {
    std::string key;
    for (const char32_t c : utf8::codePoints(written))
        if (isLetter(c)) utf8::append(key, utf8::lowerCase(c));
    return key;
}

// The sounds of a word (marks and pauses left out), in espeak-ng mnemonics.
PhonemeSchedule soundsOf(const PhonemeSchedule& raw, const PhonemeMap& map) {
    PhonemeSchedule out;
    for (const auto& p : raw) {
        if (map.isIgnored(p.phoneme)) continue;
        const auto r = map.map(p.phoneme);
        if (r && r->phoneme != "sil") out.push_back(p);
    }
    return out;
}

struct Classes {
    const PhonemeMap& map;
    const PhonemeSet& set;
    bool consonant(const PhonemeSegment& p) const {
        const auto r = map.map(p.phoneme);
        if (!r) return false;
        const auto idx = set.find(r->phoneme);
        return idx && *idx != set.silence() && !set[*idx].vowel;
    }
};

bool among(const std::vector<std::string>& list, const std::string& phoneme) {
    return std::find(list.begin(), list.end(), phoneme) != list.end();
}

// `phonemes` said with the durations of `reading` (espeak-ng's own): a phoneme it also says, in
// order, keeps that duration; another takes the duration of the one in its place.
PhonemeSchedule withDurations(const std::vector<std::string>& phonemes,
                              const PhonemeSchedule& reading) {
    PhonemeSchedule out;
    std::size_t cursor = 0;
    double t = 0;
    for (const auto& p : phonemes) {
        double d = 0.06;
        if (!reading.empty()) {
            auto it =
                std::find_if(reading.begin() + static_cast<std::ptrdiff_t>(cursor), reading.end(),
                             [&](const PhonemeSegment& s) { return s.phoneme == p; });
            if (it != reading.end()) {
                cursor = static_cast<std::size_t>(it - reading.begin()) + 1;
                d = it->duration();
            } else {
                d = reading[std::min(cursor, reading.size() - 1)].duration();
                ++cursor;
            }
        }
        out.push_back({t, t + d, p, 1.0f});
        t += d;
    }
    return out;
}
}  // namespace

Reductions Reductions::load(const std::filesystem::path& file, const PhonemeMap& map) {
    const auto doc = TomlTable::parseFile(file);
    doc.getString("name");
    doc.optString("description");
    Reductions r;
    const auto known = [&](const TomlTable& t, const std::string& key, const std::string& p) {
        if (!map.map(p) || map.isIgnored(p))
            t.fail(key, "phoneme '" + p + "' is not in phoneme map '" + map.name() + "'");
    };
    if (const auto words = doc.optTable("words")) {
        for (const auto& word : words->keys()) {
            const auto forms = words->optStringArray(word);
            if (!forms || forms->empty())
                words->fail(word, "expected a list of pronunciations (\"p h o\", ...)");
            if (keyOf(word) != word) words->fail(word, "write the word in lower case letters");
            for (const auto& form : *forms) {
                const auto phonemes = splitPhonemes(form);
                if (phonemes.empty()) words->fail(word, "an empty pronunciation");
                for (const auto& p : phonemes) known(*words, word, p);
                r.words_[word].push_back(phonemes);
            }
        }
        words->finish();
    }
    if (const auto rules = doc.optTable("rules")) {
        for (auto [key, list] : {std::pair{"drop_final_between_consonants", &r.dropFinal_},
                                 std::pair{"drop_between_consonants", &r.dropBetween_}}) {
            if (const auto v = rules->optStringArray(key)) {
                for (const auto& p : *v) known(*rules, key, p);
                *list = *v;
            }
        }
        rules->finish();
    }
    doc.finish();
    return r;
}

Reductions Reductions::forVoice(const std::string& voice, const PhonemeMap& map) {
    std::string language = voice.substr(0, voice.find('+'));
    language = language.substr(0, language.find('-'));
    const auto file = dataDirectory() / "reductions" / (language + ".toml");
    if (!std::filesystem::exists(file)) return {};
    return load(file, map);
}

std::vector<PhonemeSchedule> Reductions::alternatives(const SpokenWord& word,
                                                      const SpokenWord* next, const PhonemeMap& map,
                                                      const PhonemeSet& set) const {
    const Classes classes{map, set};
    const auto reading = soundsOf(word.phonemes, map);
    if (reading.empty()) return {};
    std::vector<PhonemeSchedule> bases{reading};
    if (const auto it = words_.find(keyOf(word.text)); it != words_.end())
        for (const auto& form : it->second) bases.push_back(withDurations(form, reading));

    const PhonemeSchedule nextSounds = next ? soundsOf(next->phonemes, map) : PhonemeSchedule{};
    const bool consonantNext = !nextSounds.empty() && classes.consonant(nextSounds.front());
    std::vector<PhonemeSchedule> out;
    const auto keep = [&](PhonemeSchedule p) {
        const auto same = [&](const PhonemeSchedule& q) {
            return std::equal(p.begin(), p.end(), q.begin(), q.end(),
                              [&](const PhonemeSegment& a, const PhonemeSegment& b) {
                                  return map.map(a.phoneme)->phoneme == map.map(b.phoneme)->phoneme;
                              });
        };
        if (p.empty() || same(reading) || std::any_of(out.begin(), out.end(), same)) return;
        if (out.size() + 1 < kMaxPronunciations) out.push_back(std::move(p));
    };
    for (const auto& base : bases) {
        keep(base);
        // t/d deletion: the last sound, after a consonant, before a word starting with one.
        PhonemeSchedule shortened = base;
        const auto n = shortened.size();
        if (consonantNext && n >= 2 && among(dropFinal_, shortened[n - 1].phoneme) &&
            classes.consonant(shortened[n - 2])) {
            shortened.pop_back();
            keep(shortened);
        }
        // Schwa deletion between consonants, inside the word.
        PhonemeSchedule syncopated;
        for (std::size_t i = 0; i < shortened.size(); ++i) {
            const bool between = i > 0 && i + 1 < shortened.size() &&
                                 classes.consonant(shortened[i - 1]) &&
                                 classes.consonant(shortened[i + 1]);
            if (!(between && among(dropBetween_, shortened[i].phoneme)))
                syncopated.push_back(shortened[i]);
        }
        if (syncopated.size() < shortened.size()) keep(syncopated);
    }
    return out;
}

}  // namespace lipsyncd
