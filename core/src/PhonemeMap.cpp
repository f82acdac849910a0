#include <algorithm>
#include <cctype>
#include <lipsyncd/core.hpp>
#include <lipsyncd/toml_table.hpp>

namespace lipsyncd {

namespace {
// Reads a symbol -> class table, checking every target is a class of the common set.
std::unordered_map<std::string, std::string> readTable(const TomlTable& doc, const char* key,
                                                       const PhonemeSet& set) {
    std::unordered_map<std::string, std::string> out;
    const auto table = doc.optTable(key);
    if (!table) return out;
    for (const auto& symbol : table->keys()) {
        std::string target = table->getString(symbol);
        if (!set.find(target))
            table->fail(symbol, "maps to '" + target + "', which is not a phoneme class");
        out.emplace(symbol, std::move(target));
    }
    table->finish();
    return out;
}
}  // namespace

PhonemeMap PhonemeMap::load(const std::filesystem::path& file) {
    return load(file, 0);
}

PhonemeMap PhonemeMap::load(const std::filesystem::path& file, int depth) {
    const auto doc = TomlTable::parseFile(file);
    PhonemeMap m;
    m.name_ = doc.optString("name").value_or(file.stem().string());
    doc.optString("description");
    m.caseSensitive_ = doc.optBool("case_sensitive").value_or(true);
    m.stripStressDigits_ = doc.optBool("strip_stress_digits").value_or(false);
    m.ignored_ = doc.optStringArray("ignore").value_or(std::vector<std::string>{});
    m.phonemeSet_ = doc.optString("phoneme_set").value_or("common");
    const PhonemeSet& set = PhonemeSet::named(m.phonemeSet_);
    // Keys are stored normalised so lookups can normalise the symbol the same way.
    for (auto& [k, v] : readTable(doc, "map", set)) m.exact_.emplace(m.normalise(k), v);
    for (auto& [k, v] : readTable(doc, "nearest", set)) m.nearest_.emplace(m.normalise(k), v);
    for (auto& s : m.ignored_) s = m.normalise(s);
    const auto fallback = doc.optString("fallback");
    doc.finish();
    if (m.exact_.empty()) throw InputError(file.string(), 0, "phoneme map has an empty [map]");
    if (fallback) m.addFallback(file, *fallback, depth);
    return m;
}

// A language's espeak-ng voice reads some words with another voice (French and Bulgarian switch
// to English for words they take for English), and their phonemes come under that voice's
// names: the map names the map those come from. Its entries count where this map has none.
void PhonemeMap::addFallback(const std::filesystem::path& file, const std::string& name,
                             int depth) {
    constexpr int kMaxFallbacks = 4;  // a chain, not a cycle
    if (depth >= kMaxFallbacks)
        throw InputError(file.string(), 0,
                         "fallback '" + name + "': more than " + std::to_string(kMaxFallbacks) +
                             " maps fall back in a chain (a cycle?)");
    const auto other = load(findNamedDataFile(name, "phonemes", ".toml"), depth + 1);
    if (other.phonemeSet_ != phonemeSet_)
        throw InputError(file.string(), 0,
                         "fallback '" + name + "' maps onto phoneme set '" + other.phonemeSet_ +
                             "', not '" + phonemeSet_ + "'");
    for (const auto& [k, v] : other.exact_) exact_.emplace(normalise(k), v);
    for (const auto& [k, v] : other.nearest_) nearest_.emplace(normalise(k), v);
    for (const auto& s : other.ignored_)
        if (!isIgnored(s)) ignored_.push_back(normalise(s));
}

PhonemeMap PhonemeMap::named(std::string_view nameOrPath) {
    return load(findNamedDataFile(std::string(nameOrPath), "phonemes", ".toml"));
}

std::string PhonemeMap::normalise(std::string_view symbol) const {
    std::string s(symbol);
    if (stripStressDigits_)
        while (s.size() > 1 && std::isdigit(static_cast<unsigned char>(s.back()))) s.pop_back();
    if (!caseSensitive_)
        std::transform(s.begin(), s.end(), s.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

std::optional<PhonemeMap::Result> PhonemeMap::map(std::string_view symbol) const {
    const std::string key = normalise(symbol);
    if (auto it = exact_.find(key); it != exact_.end()) return Result{it->second, false};
    if (auto it = nearest_.find(key); it != nearest_.end()) return Result{it->second, true};
    return std::nullopt;
}

bool PhonemeMap::isIgnored(std::string_view symbol) const {
    // A name in parentheses is espeak-ng's switch of language ("(en)" before an English word in
    // a French line, "(de)" in a Croatian one): never a sound, in whatever map.
    if (symbol.size() > 2 && symbol.front() == '(' && symbol.back() == ')') return true;
    const std::string key = normalise(symbol);
    return std::find(ignored_.begin(), ignored_.end(), key) != ignored_.end();
}

}  // namespace lipsyncd
