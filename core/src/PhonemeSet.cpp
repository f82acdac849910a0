#include <algorithm>
#include <lipsyncd/core.hpp>
#include <lipsyncd/toml_table.hpp>
#include <map>
#include <memory>
#include <mutex>

namespace lipsyncd {

PhonemeSet::PhonemeSet(std::vector<PhonemeClass> classes) : classes_(std::move(classes)) {
    if (classes_.empty()) throw InputError("phoneme set has no classes");
    for (std::size_t i = 0; i < classes_.size(); ++i) {
        const auto& name = classes_[i].name;
        if (name.empty()) throw InputError("phoneme class " + std::to_string(i) + " has no name");
        if (!index_.emplace(name, i).second)
            throw InputError("phoneme class '" + name + "' is defined twice");
    }
    const auto sil = find("sil");
    if (!sil) throw InputError("phoneme set has no 'sil' (silence) class");
    silence_ = *sil;
}

PhonemeSet PhonemeSet::load(const std::filesystem::path& file) {
    const auto doc = TomlTable::parseFile(file);
    std::vector<PhonemeClass> classes;
    if (const auto base = doc.optString("extends")) {
        const auto& b = named(*base);
        classes.assign(b.classes().begin(), b.classes().end());
    }
    doc.optInteger("version");
    doc.optString("description");
    for (const auto& entry : doc.tableArray("class")) {
        PhonemeClass c{entry.getString("name"), entry.getString("group"),
                       entry.optString("examples").value_or(""),
                       entry.optBool("vowel").value_or(false)};
        if (const auto jaw = entry.optNumber("jaw")) {
            if (!(*jaw >= 0 && *jaw <= 1)) entry.fail("jaw", "must be in [0, 1]");
            c.jaw = static_cast<float>(*jaw);
        }
        entry.finish();
        classes.push_back(std::move(c));
    }
    doc.finish();
    try {
        return PhonemeSet(std::move(classes));
    } catch (const InputError& e) {
        throw InputError(file.string(), 0, e.what());
    }
}

const PhonemeSet& PhonemeSet::named(const std::string& nameOrPath) {
    if (nameOrPath == "common") return common();
    // Sets are small and few; each is loaded once and lives as long as the process.
    static std::mutex mutex;
    static std::map<std::string, std::unique_ptr<PhonemeSet>> loaded;
    std::lock_guard lock(mutex);
    auto& slot = loaded[nameOrPath];
    if (!slot)
        slot =
            std::make_unique<PhonemeSet>(load(findNamedDataFile(nameOrPath, "phonemes", ".toml")));
    return *slot;
}

const PhonemeSet& PhonemeSet::common() {
    static const PhonemeSet set = load(findDataFile("phonemes/common.toml"));
    return set;
}

std::optional<std::size_t> PhonemeSet::find(std::string_view name) const {
    const auto it = index_.find(std::string(name));
    if (it == index_.end()) return std::nullopt;
    return it->second;
}

std::vector<std::string> PhonemeSet::groups() const {
    std::vector<std::string> out;
    for (const auto& c : classes_)
        if (std::find(out.begin(), out.end(), c.group) == out.end()) out.push_back(c.group);
    return out;
}

}  // namespace lipsyncd
