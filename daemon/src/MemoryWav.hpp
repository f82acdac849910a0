// Samples heard live as a WAV file in memory: the aligner takes a path (it reads a file more
// than once: its speaking rate first, then two passes), so the samples go into a MemoryFile
// that libsndfile opens through /proc/self/fd. Nothing touches a disk.
#pragma once

#include <filesystem>
#include <lipsyncd/core.hpp>
#include <span>
#include <string>

namespace lipsyncd::daemon {

class MemoryWav {
  public:
    // InputError when the samples cannot be written; std::runtime_error when the memory file
    // cannot be made.
    MemoryWav(std::span<const float> samples, int rate);

    const std::filesystem::path& path() const { return file_.path(); }
    // A message naming the path as `what` (the user knows the sound as a line, not a fd).
    std::string named(std::string message, const std::string& what) const {
        return file_.named(std::move(message), what);
    }

  private:
    MemoryFile file_{"lipsyncd-live-line"};
};

}  // namespace lipsyncd::daemon
