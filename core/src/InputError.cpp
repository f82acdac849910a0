#include <lipsyncd/core.hpp>

namespace lipsyncd {

namespace {
std::string located(const std::string& file, std::size_t line, const std::string& what) {
    std::string where = file;
    if (line > 0) where += ":" + std::to_string(line);
    return where.empty() ? what : where + ": " + what;
}
}  // namespace

InputError::InputError(const std::string& file, std::size_t line, const std::string& what)
    : std::runtime_error(located(file, line, what)) {}

}  // namespace lipsyncd
