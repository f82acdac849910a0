// A recording the page uploaded, in memory: the decoders take paths, so the bytes go into a
// sealed memfd that libsndfile opens through /proc/self/fd. Nothing touches a disk, and no name
// from a request is ever opened.
#pragma once

#include <filesystem>
#include <string>

namespace lipsyncd::editor {

class UploadedAudio {
  public:
    // InputError (the request's fault: 400) for a WAV whose RIFF header promises more bytes
    // than came, or when the memory file cannot be made.
    explicit UploadedAudio(const std::string& bytes);
    ~UploadedAudio();
    UploadedAudio(const UploadedAudio&) = delete;
    UploadedAudio& operator=(const UploadedAudio&) = delete;

    const std::filesystem::path& path() const { return path_; }
    // The decoders' messages name the path: the user knows it as "the recording".
    std::string named(std::string message) const;

  private:
    int fd_ = -1;
    std::filesystem::path path_;
};

}  // namespace lipsyncd::editor
