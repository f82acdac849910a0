// Where command output goes: a file, or stdout for "-".
#pragma once

#include <fstream>
#include <functional>
#include <iostream>
#include <lipsyncd/core.hpp>
#include <string>
#include <vector>

namespace lipsyncd::cli {

inline void withOutputStream(const std::string& path, const std::function<void(std::ostream&)>& write) {
    if (path == "-") {
        write(std::cout);
        std::cout.flush();
        return;
    }
    std::ofstream out(path);
    if (!out) throw InputError(path + ": cannot open for writing");
    write(out);
    out.close();
    if (!out) throw InputError(path + ": write failed");
}

// What a command could read past (a file cut short, a word not placed), one line each on stderr.
inline void printWarnings(const std::string& command, const std::vector<std::string>& warnings) {
    for (const auto& w : warnings) std::cerr << "lipsync " << command << ": warning: " << w << '\n';
}

}  // namespace lipsyncd::cli
