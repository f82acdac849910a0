// A recording the page uploaded, in memory: the decoders take paths, so the bytes go into a
// sealed memfd that libsndfile opens through /proc/self/fd. Nothing touches a disk, and no name
// from a request is ever opened.
#pragma once

#include <filesystem>
#include <lipsyncd/core.hpp>
#include <string>

namespace lipsyncd::editor {

class UploadedAudio {
  public:
    // InputError (the request's fault: 400) for a WAV whose RIFF header promises more bytes
    // than came, or when the memory file cannot be made.
    explicit UploadedAudio(const std::string& bytes);

    const std::filesystem::path& path() const { return file_.path(); }
    // The decoders' messages name the path: the user knows it as "the recording".
    std::string named(std::string message) const;

  private:
    MemoryFile file_{"lipsync-edit-upload"};
};

}  // namespace lipsyncd::editor
