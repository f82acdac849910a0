// Listing device files for `lipsync devices`: the entries of a folder whose names start with
// one of some prefixes, sorted; none (not an error) when the folder is missing.
#pragma once

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <string_view>
#include <vector>

namespace lipsyncd::output {

inline std::vector<std::filesystem::path> sortedEntries(
    const std::filesystem::path& dir, std::initializer_list<std::string_view> prefixes = {}) {
    std::vector<std::filesystem::path> out;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
        const auto name = e.path().filename().string();
        if (prefixes.size() == 0 ||
            std::any_of(prefixes.begin(), prefixes.end(),
                        [&](std::string_view p) { return name.starts_with(p); }))
            out.push_back(e.path());
    }
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace lipsyncd::output
