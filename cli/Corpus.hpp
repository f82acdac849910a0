// A labelled corpus: NAME.wav beside NAME.lab in one folder (DESIGN.md: reference labels are
// `start end phoneme`, ARPAbet in any case with stress digits, or common-set names).
#pragma once

#include <filesystem>
#include <lipsyncd/core.hpp>
#include <string>
#include <vector>

namespace lipsyncd::cli {

struct CorpusItem {
    std::string speaker;  // the subfolder it lies in, or the corpus folder's own name
    std::string name;
    std::filesystem::path audio;
    std::filesystem::path labels;
};

// Every NAME.wav with a NAME.lab in DIR and in its subfolders one level down (DIR/SPEAKER/:
// one folder per speaker, so figures can be given per speaker), sorted by speaker and name.
// Throws InputError for a missing folder or one with no pairs; audio without labels is
// reported in `skipped`.
std::vector<CorpusItem> listCorpus(const std::filesystem::path& dir,
                                   std::vector<std::string>* skipped = nullptr);

// The whole of a text file (the words of a recording: `lipsync align --text-file`, NAME.txt
// beside NAME.wav for `lipsync eval --align`). Throws InputError naming a file it cannot open.
std::string readTextFile(const std::filesystem::path& file);

// Reads labels in `alphabet`: "common", "arpabet", a map name or file, or "auto" (common-set
// names if every symbol is one, else ARPAbet).
// `set`: the classes the schedule is in (default: the common set).
PhonemeSchedule readLabels(const std::filesystem::path& file, const std::string& alphabet,
                           const PhonemeSet* set = nullptr);

}  // namespace lipsyncd::cli
