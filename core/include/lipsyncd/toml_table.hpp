// TomlTable: strict, line-aware reading of TOML configuration (puppets, phoneme maps, the
// daemon's config). Every getter names file, line and key when a value is missing or of the
// wrong type, and finish() rejects keys nobody read ("unknown key 'x'"), as MPD does for its
// config: a typo must never be silently ignored.
#pragma once

#include <lipsyncd/core.hpp>

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace lipsyncd {

class TomlTable {
public:
    // Parses a whole file; syntax errors become InputError with line and column.
    static TomlTable parseFile(const std::filesystem::path& file);
    static TomlTable parseString(std::string_view text, const std::string& sourceName);

    TomlTable(const TomlTable&) = delete;
    TomlTable& operator=(const TomlTable&) = delete;
    TomlTable(TomlTable&&) noexcept;
    TomlTable& operator=(TomlTable&&) noexcept;
    ~TomlTable();

    bool has(const std::string& key) const;
    std::string getString(const std::string& key) const;
    std::optional<std::string> optString(const std::string& key) const;
    double getNumber(const std::string& key) const;  // integer or float
    std::optional<double> optNumber(const std::string& key) const;
    std::optional<std::int64_t> optInteger(const std::string& key) const;
    std::optional<bool> optBool(const std::string& key) const;
    std::optional<std::vector<double>> optNumberArray(const std::string& key) const;
    std::optional<std::vector<std::string>> optStringArray(const std::string& key) const;
    std::optional<TomlTable> optTable(const std::string& key) const;
    // An array of tables ([[key]]); empty when absent.
    std::vector<TomlTable> tableArray(const std::string& key) const;
    // All keys, in file order (for free-form maps such as [map] in a phoneme map).
    std::vector<std::string> keys() const;

    // Throws InputError for the first key of this table that no getter asked for.
    void finish() const;
    // An error at this key's line ("FILE:LINE: key 'k': what").
    [[noreturn]] void fail(const std::string& key, const std::string& what) const;
    std::size_t line(const std::string& key) const;  // 0 when unknown
    std::size_t line() const;                        // the table's own line
    const std::string& source() const;
    // "name.sub" path of this table, for messages.
    const std::string& path() const { return path_; }

private:
    struct Document;  // the parsed toml++ document, shared by all tables cut from it
    TomlTable(std::shared_ptr<const Document> document, const void* table, std::string path);
    const void* node(const std::string& key) const;  // a toml::node*, opaque here
    std::string qualified(const std::string& key) const;

    std::shared_ptr<const Document> document_;
    const void* table_;  // a toml::table* inside document_
    std::string path_;
    mutable std::set<std::string> read_;
};

}  // namespace lipsyncd
