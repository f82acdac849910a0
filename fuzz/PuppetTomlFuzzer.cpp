// Fuzz target: bytes as a puppet file. A puppet that loads has finite numbers, min < max, a
// rest within the limits and names safe for the command record; anything else is an
// InputError naming the file and line.
#include <cmath>
#include <cstdint>
#include <lipsyncd/output.hpp>

#include "MemoryFile.hpp"

using namespace lipsyncd;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = fuzz::memoryFileOf(data, size);
    if (!file) return 0;
    try {
        const auto p = output::Puppet::load(file->path());
        if (!(p.leadSeconds >= 0 && p.leadSeconds <= 1)) __builtin_trap();
        for (const auto& a : p.actuators) {
            if (!(std::isfinite(a.min) && std::isfinite(a.max) && a.min < a.max)) __builtin_trap();
            if (!(a.rest >= a.min && a.rest <= a.max)) __builtin_trap();
            if (!(std::isfinite(a.neutral) && std::isfinite(a.trim))) __builtin_trap();
            for (const auto& [pose, gain] : a.gains)
                if (!std::isfinite(gain)) __builtin_trap();
            if (a.name.find_first_of(",\"\n\r") != std::string::npos) __builtin_trap();
        }
    } catch (const InputError&) {
    }
    return 0;
}
