// Fuzz target: arbitrary bytes through the decoder-to-schedule path (issue: "never a crash").
// The first byte chooses how the rest is read: even, as a file whose type libsndfile detects
// (WAV, FLAC, OGG, ...); odd, as raw PCM whose format, channels and rate the next three bytes
// pick. A clean InputError or runtime_error is a correct answer; anything else is a bug.
#include <array>
#include <cstdint>
#include <cstdio>
#include <lipsyncd/dsp.hpp>
#include <string>

#include "MemoryFile.hpp"

namespace {

using namespace lipsyncd;

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
    const auto file = fuzz::memoryFileOf(data + skip, size - skip);
    if (!file) return 0;
    dsp::DecodeOptions decode;
    decode.channel = (data[0] >> 1) % 3 == 2 ? 1 : -1;  // sometimes ask for the second channel
    try {
        const auto result = dsp::analyzeFile(file->path(), templates, PhonemeSet::common(), {},
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
