// Fuzz target: arbitrary bytes through the decoder-to-schedule path (issue: "never a crash").
// The first byte chooses how the rest is read: even, as a file whose type libsndfile detects
// (WAV, FLAC, OGG, ...); odd, as raw PCM whose format, channels and rate the next three bytes
// pick. A clean InputError or runtime_error is a correct answer; anything else is a bug.
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <lipsyncd/dsp.hpp>
#include <string>

namespace {

using namespace lipsyncd;

// The bytes as a file the decoder can open by path, without touching the disk.
class MemoryFile {
  public:
    MemoryFile(const std::uint8_t* data, std::size_t size) : fd_(::memfd_create("fuzz", 0)) {
        if (fd_ >= 0 && size > 0 && ::write(fd_, data, size) != static_cast<ssize_t>(size)) {
            ::close(fd_);
            fd_ = -1;
        }
    }
    ~MemoryFile() {
        if (fd_ >= 0) ::close(fd_);
    }
    MemoryFile(const MemoryFile&) = delete;
    MemoryFile& operator=(const MemoryFile&) = delete;
    bool ok() const { return fd_ >= 0; }
    std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

  private:
    int fd_;
};

std::optional<dsp::RawFormat> rawFormatFrom(const std::uint8_t* header) {
    static constexpr std::array formats{"s8", "u8", "s16", "s24", "s32", "f32", "f64"};
    static constexpr std::array rates{8000, 10000, 16000, 22050, 44100, 48000, 96000, 1};
    dsp::RawFormat raw;
    raw.sampleFormat = formats[header[0] % formats.size()];
    raw.channels = 1 + header[1] % 4;
    raw.sampleRate = rates[header[2] % rates.size()];
    return raw;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const auto templates = dsp::TemplateSet::loadDefault();
    if (size < 4) return 0;
    const bool raw = data[0] & 1;
    const std::size_t skip = raw ? 4 : 1;
    MemoryFile file(data + skip, size - skip);
    if (!file.ok()) return 0;
    dsp::DecodeOptions decode;
    decode.channel = (data[0] >> 1) % 3 == 2 ? 1 : -1;  // sometimes ask for the second channel
    try {
        const auto result = dsp::analyzeFile(file.path(), templates, PhonemeSet::common(), {},
                                             decode, raw ? rawFormatFrom(data + 1) : std::nullopt);
        // A schedule, when there is one, is contiguous from 0 and covers the audio.
        double t = 0;
        for (const auto& s : result.schedule) {
            if (s.start != t || !(s.end > s.start)) __builtin_trap();
            t = s.end;
        }
    } catch (const InputError&) {
    } catch (const std::runtime_error&) {
    }
    return 0;
}
