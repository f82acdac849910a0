#include "Corpus.hpp"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>
#include <tuple>

namespace lipsyncd::cli {

namespace fs = std::filesystem;

namespace {
void addPairs(const fs::path& dir, const std::string& speaker, std::vector<CorpusItem>& items,
              std::vector<std::string>* skipped) {
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".wav") continue;
        auto lab = entry.path();
        lab.replace_extension(".lab");
        if (!fs::exists(lab)) {
            if (skipped)
                skipped->push_back(entry.path().string() + ": no " + lab.filename().string());
            continue;
        }
        items.push_back({speaker, entry.path().stem().string(), entry.path(), lab});
    }
}
}  // namespace

std::vector<CorpusItem> listCorpus(const fs::path& dir, std::vector<std::string>* skipped) {
    if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a folder");
    std::vector<CorpusItem> items;
    auto own = fs::weakly_canonical(fs::absolute(dir)).filename().string();
    addPairs(dir, own.empty() ? "corpus" : own, items, skipped);
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.is_directory())
            addPairs(entry.path(), entry.path().filename().string(), items, skipped);
    std::sort(items.begin(), items.end(), [](const auto& a, const auto& b) {
        return std::tie(a.speaker, a.name) < std::tie(b.speaker, b.name);
    });
    if (items.empty()) throw InputError(dir.string() + ": no NAME.wav + NAME.lab pairs");
    return items;
}

std::string readTextFile(const fs::path& file) {
    std::ifstream in(file);
    if (!in) throw InputError(file.string() + ": cannot open the text file");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

PhonemeSchedule readLabels(const fs::path& file, const std::string& alphabet,
                           const PhonemeSet* set) {
    std::vector<std::string> warnings;
    PhonemeSchedule labels;
    if (alphabet == "auto") {
        ScheduleReadOptions strict;
        strict.unknownIsError = true;
        strict.set = set;
        try {
            return readScheduleFile(file, strict);
        } catch (const InputError&) {
            // Not all class names: ARPAbet is the other alphabet labels come in.
        }
        return readLabels(file, "arpabet", set);
    }
    ScheduleReadOptions options;
    options.set = set;
    if (alphabet == "common") {
        labels = readScheduleFile(file, options, &warnings);
    } else {
        const auto map = PhonemeMap::named(alphabet);
        options.map = &map;
        labels = readScheduleFile(file, options, &warnings);
    }
    for (const auto& w : warnings) std::cerr << "lipsync: warning: " << w << '\n';
    return labels;
}

}  // namespace lipsyncd::cli
