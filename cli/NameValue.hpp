// NAME=VALUE words: `lipsync ctl pose jaw=0.5`, `--class-bias bmp=0.3`.
#pragma once

#include <exception>
#include <optional>
#include <string>
#include <utility>

namespace lipsyncd::cli {

// The name before the first '=' (not empty) and a number that fills the rest; nullopt otherwise
// (no '=', no name, not a number, trailing characters, or out of a double's range).
inline std::optional<std::pair<std::string, double>> parseNameValue(const std::string& word) {
    const auto eq = word.find('=');
    if (eq == std::string::npos || eq == 0) return std::nullopt;
    std::size_t used = 0;
    double value = 0;
    try {
        value = std::stod(word.substr(eq + 1), &used);
    } catch (const std::exception&) {
        return std::nullopt;
    }
    if (eq + 1 + used != word.size()) return std::nullopt;
    return std::pair{word.substr(0, eq), value};
}

}  // namespace lipsyncd::cli
