// A numeric option within a range, its default shown in --help: the shape most of the tool's
// tuning options take.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace lipsyncd::cli {

template <class T, class Bound>
CLI::Option* addNumberOption(CLI::App& cmd, const std::string& name, T& field,
                             const std::string& help, Bound lo, Bound hi) {
    return cmd.add_option(name, field, help)->check(CLI::Range(lo, hi))->capture_default_str();
}

}  // namespace lipsyncd::cli
