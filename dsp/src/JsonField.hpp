// Reading a JSON member with a message naming the JSON path (template and transition files).
#pragma once

#include <filesystem>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <nlohmann/json.hpp>
#include <string>

namespace lipsyncd::dsp {

// Reads a member with a message naming the JSON path when it is missing or of the wrong type.
template <typename T>
T member(const nlohmann::json& j, const std::string& key, const std::string& path,
         const std::string& source) {
    if (!j.is_object() || !j.contains(key))
        throw InputError(source, 0, "missing field '" + path + key + "'");
    try {
        return j.at(key).get<T>();
    } catch (const nlohmann::json::exception&) {
        throw InputError(source, 0,
                         "field '" + path + key + "' has the wrong type (" +
                             std::string(j.at(key).type_name()) + ")");
    }
}

// Parses a JSON data file and checks its "format" and "version" fields.
inline nlohmann::json readDataDocument(const std::filesystem::path& file, const std::string& format,
                                       int version) {
    const std::string source = file.string();
    std::ifstream in(file);
    if (!in) throw InputError(source + ": cannot open");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {  // bad syntax, or a number out of range
        throw InputError(source, 0, std::string("not valid JSON: ") + e.what());
    }
    if (member<std::string>(j, "format", "", source) != format)
        throw InputError(source, 0, "field 'format' must be \"" + format + "\"");
    if (const int v = member<int>(j, "version", "", source); v != version)
        throw InputError(source, 0,
                         format + " version " + std::to_string(v) +
                             " is not supported (this build reads " + std::to_string(version) +
                             ")");
    return j;
}

}  // namespace lipsyncd::dsp
