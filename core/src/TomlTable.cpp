#include <lipsyncd/toml_table.hpp>

#include <toml++/toml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace lipsyncd {

struct TomlTable::Document {
    toml::table root;
    std::string source;
};

namespace {
const toml::table& asTable(const void* p) { return *static_cast<const toml::table*>(p); }

std::size_t lineOf(const toml::node& n) {
    return static_cast<std::size_t>(n.source().begin.line);
}

std::string typeName(const toml::node& n) {
    std::ostringstream s;
    s << n.type();
    return s.str();
}
}  // namespace

TomlTable::TomlTable(std::shared_ptr<const Document> document, const void* table, std::string path)
    : document_(std::move(document)), table_(table), path_(std::move(path)) {}
TomlTable::TomlTable(TomlTable&&) noexcept = default;
TomlTable& TomlTable::operator=(TomlTable&&) noexcept = default;
TomlTable::~TomlTable() = default;

TomlTable TomlTable::parseString(std::string_view text, const std::string& sourceName) {
    auto doc = std::make_shared<Document>();
    doc->source = sourceName;
    try {
        doc->root = toml::parse(text, sourceName);
    } catch (const toml::parse_error& e) {
        throw InputError(sourceName, e.source().begin.line,
                         std::string(e.description()) + " (column " +
                             std::to_string(e.source().begin.column) + ")");
    }
    const void* root = &doc->root;
    return TomlTable(std::move(doc), root, "");
}

TomlTable TomlTable::parseFile(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file.string() + ": cannot open");
    std::ostringstream text;
    text << in.rdbuf();
    return parseString(text.str(), file.string());
}

const std::string& TomlTable::source() const { return document_->source; }

std::string TomlTable::qualified(const std::string& key) const {
    return path_.empty() ? key : path_ + "." + key;
}

const void* TomlTable::node(const std::string& key) const {
    read_.insert(key);
    return asTable(table_).get(key);
}

bool TomlTable::has(const std::string& key) const { return asTable(table_).contains(key); }

std::size_t TomlTable::line(const std::string& key) const {
    const toml::node* n = asTable(table_).get(key);
    return n ? lineOf(*n) : line();
}

std::size_t TomlTable::line() const { return lineOf(asTable(table_)); }

void TomlTable::fail(const std::string& key, const std::string& what) const {
    throw InputError(source(), line(key), "key '" + qualified(key) + "': " + what);
}

namespace {
template <typename T>
std::optional<T> typed(const TomlTable& t, const std::string& key, const toml::node* n,
                       const char* expected) {
    if (!n) return std::nullopt;
    if (auto v = n->value<T>()) return *v;
    t.fail(key, std::string("expected ") + expected + ", found " + typeName(*n));
}
}  // namespace

std::optional<std::string> TomlTable::optString(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (n && !n->is_string()) fail(key, "expected a string, found " + typeName(*n));
    return typed<std::string>(*this, key, n, "a string");
}

std::string TomlTable::getString(const std::string& key) const {
    if (auto v = optString(key)) return *v;
    throw InputError(source(), line(), "missing key '" + qualified(key) + "' (a string)");
}

std::optional<double> TomlTable::optNumber(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (n && !n->is_number()) fail(key, "expected a number, found " + typeName(*n));
    return typed<double>(*this, key, n, "a number");
}

double TomlTable::getNumber(const std::string& key) const {
    if (auto v = optNumber(key)) return *v;
    throw InputError(source(), line(), "missing key '" + qualified(key) + "' (a number)");
}

std::optional<std::int64_t> TomlTable::optInteger(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (n && !n->is_integer()) fail(key, "expected an integer, found " + typeName(*n));
    return typed<std::int64_t>(*this, key, n, "an integer");
}

std::optional<bool> TomlTable::optBool(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (n && !n->is_boolean()) fail(key, "expected true or false, found " + typeName(*n));
    return typed<bool>(*this, key, n, "true or false");
}

std::optional<std::vector<double>> TomlTable::optNumberArray(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (!n) return std::nullopt;
    const auto* arr = n->as_array();
    if (!arr) fail(key, "expected an array of numbers, found " + typeName(*n));
    std::vector<double> out;
    for (const auto& item : *arr) {
        auto v = item.value<double>();
        if (!item.is_number() || !v) fail(key, "expected only numbers in the array");
        out.push_back(*v);
    }
    return out;
}

std::optional<std::vector<std::string>> TomlTable::optStringArray(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (!n) return std::nullopt;
    const auto* arr = n->as_array();
    if (!arr) fail(key, "expected an array of strings, found " + typeName(*n));
    std::vector<std::string> out;
    for (const auto& item : *arr) {
        auto v = item.value<std::string>();
        if (!item.is_string() || !v) fail(key, "expected only strings in the array");
        out.push_back(*v);
    }
    return out;
}

std::optional<TomlTable> TomlTable::optTable(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    if (!n) return std::nullopt;
    const auto* t = n->as_table();
    if (!t) fail(key, "expected a table, found " + typeName(*n));
    return TomlTable(document_, t, qualified(key));
}

std::vector<TomlTable> TomlTable::tableArray(const std::string& key) const {
    const auto* n = static_cast<const toml::node*>(node(key));
    std::vector<TomlTable> out;
    if (!n) return out;
    const auto* arr = n->as_array();
    if (!arr || !arr->is_array_of_tables())
        fail(key, "expected an array of tables ([[" + key + "]]), found " + typeName(*n));
    for (std::size_t i = 0; i < arr->size(); ++i)
        out.push_back(TomlTable(document_, arr->get(i)->as_table(),
                                qualified(key) + "[" + std::to_string(i) + "]"));
    return out;
}

std::vector<std::string> TomlTable::keys() const {
    std::vector<std::pair<std::size_t, std::string>> byLine;
    for (const auto& [k, v] : asTable(table_)) byLine.emplace_back(lineOf(v), std::string(k.str()));
    std::stable_sort(byLine.begin(), byLine.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> out;
    for (auto& [l, k] : byLine) out.push_back(std::move(k));
    return out;
}

void TomlTable::finish() const {
    for (const auto& [k, v] : asTable(table_)) {
        const std::string key(k.str());
        if (!read_.count(key))
            throw InputError(source(), lineOf(v), "unknown key '" + qualified(key) + "'");
    }
}

}  // namespace lipsyncd
