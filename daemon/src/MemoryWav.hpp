// Samples heard live as a WAV file in memory: the aligner takes a path (it reads a file more
// than once: its speaking rate first, then two passes), so the samples go into a memfd that
// libsndfile opens through /proc/self/fd. Nothing touches a disk.
#pragma once

#include <filesystem>
#include <span>
#include <string>

namespace lipsyncd::daemon {

class MemoryWav {
  public:
    // InputError when the memory file cannot be made or written.
    MemoryWav(std::span<const float> samples, int rate);
    ~MemoryWav();
    MemoryWav(const MemoryWav&) = delete;
    MemoryWav& operator=(const MemoryWav&) = delete;

    const std::filesystem::path& path() const { return path_; }
    // A message naming the path as `what` (the user knows the sound as a line, not a fd).
    std::string named(std::string message, const std::string& what) const;

  private:
    int fd_ = -1;
    std::filesystem::path path_;
};

}  // namespace lipsyncd::daemon
