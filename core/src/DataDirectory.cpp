#include <lipsyncd/core.hpp>

#include <cstdlib>
#include <system_error>

namespace lipsyncd {

namespace fs = std::filesystem;

fs::path dataDirectory() {
    if (const char* env = std::getenv("LIPSYNCD_DATA_DIR"); env && *env) return env;
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    const fs::path installed = LIPSYNCD_INSTALL_DATA_DIR;
    // An installed binary sits in <prefix>/bin; its data in <prefix>/share/lipsyncd.
    if (!ec && exe.parent_path() == fs::path(LIPSYNCD_INSTALL_BIN_DIR) &&
        fs::is_directory(installed))
        return installed;
    if (fs::is_directory(LIPSYNCD_SOURCE_DATA_DIR)) return LIPSYNCD_SOURCE_DATA_DIR;
    return installed;
}

fs::path findDataFile(const fs::path& name) {
    if (fs::exists(name)) return name;
    const fs::path inData = dataDirectory() / name;
    if (fs::exists(inData)) return inData;
    throw InputError(name.string() + ": no such file (looked here and in " +
                     dataDirectory().string() + ")");
}

fs::path findNamedDataFile(const std::string& nameOrPath, const fs::path& folder,
                           const std::string& extension) {
    const fs::path given(nameOrPath);
    if (given.has_extension() || given.has_parent_path()) return findDataFile(given);
    return findDataFile(folder / (nameOrPath + extension));
}

}  // namespace lipsyncd
