// The upload as a memory file. Sealed against writes, so what was checked is what is decoded.
#include "UploadedAudio.hpp"

#include <cstdint>
#include <lipsyncd/core.hpp>

namespace lipsyncd::editor {

namespace {
std::uint32_t le32(const std::string& b, std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + i]);
    return v;
}

// libsndfile reads what there is of a cut-off WAV without a word: a preview of half a
// recording would look like a bad alignment, so a RIFF size or a data chunk that runs past
// the end is refused. 0 and 0xffffffff are what streaming writers put when they did not know.
void refuseTruncatedWav(const std::string& b) {
    if (b.size() < 12 || b.compare(0, 4, "RIFF") != 0 || b.compare(8, 4, "WAVE") != 0) return;
    const auto unknown = [](std::uint32_t size) { return size == 0 || size == 0xffffffffu; };
    const auto truncated = [&](const std::string& what, std::uint64_t needs) {
        throw InputError("wav: truncated: its " + what + " needs " + std::to_string(needs) +
                         " bytes, the upload has " + std::to_string(b.size()) +
                         " (upload the whole file)");
    };
    const std::uint32_t riff = le32(b, 4);
    if (!unknown(riff) && riff + std::uint64_t{8} > b.size() + 1)  // + 1: a missing pad byte
        truncated("RIFF header", riff + std::uint64_t{8});
    for (std::uint64_t at = 12; at + 8 <= b.size();) {
        const std::uint32_t size = le32(b, at + 4);
        if (b.compare(at, 4, "data") == 0) {
            if (!unknown(size) && at + 8 + size > b.size()) truncated("data chunk", at + 8 + size);
            return;
        }
        at += 8 + std::uint64_t{size} + (size & 1);
    }
    throw InputError("wav: truncated: no data chunk after the header");
}
}  // namespace

UploadedAudio::UploadedAudio(const std::string& bytes) {
    refuseTruncatedWav(bytes);
    file_.write(bytes, "the upload");
    file_.seal();
}

std::string UploadedAudio::named(std::string message) const {
    return file_.named(std::move(message), "the recording");
}

}  // namespace lipsyncd::editor
