// Where command output goes: a file, or stdout for "-".
#pragma once

#include <lipsyncd/core.hpp>

#include <fstream>
#include <functional>
#include <iostream>
#include <string>

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

}  // namespace lipsyncd::cli
