// The fuzz input as a file that loaders taking a path can open, without touching the disk (the
// core's MemoryFile); none when the memory file cannot be made, and the input is passed over.
#pragma once

#include <cstdint>
#include <lipsyncd/core.hpp>
#include <optional>
#include <string_view>

namespace lipsyncd::fuzz {

inline std::optional<MemoryFile> memoryFileOf(const std::uint8_t* data, std::size_t size) {
    try {
        std::optional<MemoryFile> file(std::in_place, "fuzz");
        file->write({reinterpret_cast<const char*>(data), size}, "the fuzz input");
        return file;
    } catch (const std::runtime_error&) {
        return std::nullopt;
    }
}

}  // namespace lipsyncd::fuzz
