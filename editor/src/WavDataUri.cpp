// A WAV file in memory, base64-encoded into a data: URI: the page plays the preview's speech
// without a second request or a file on disk; and the way back, for a recording the page
// uploads in its JSON.
#include <array>
#include <cstdint>

#include "SpeechPreview.hpp"

namespace lipsyncd::editor {

namespace {
void putLe(std::string& out, std::uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

int digitValue(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}
}  // namespace

std::string encodeBase64(std::string_view in) {
    static constexpr char kDigits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((in.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < in.size(); i += 3) {
        std::uint32_t n = static_cast<unsigned char>(in[i]) << 16;
        if (i + 1 < in.size()) n |= static_cast<unsigned char>(in[i + 1]) << 8;
        if (i + 2 < in.size()) n |= static_cast<unsigned char>(in[i + 2]);
        out.push_back(kDigits[(n >> 18) & 63]);
        out.push_back(kDigits[(n >> 12) & 63]);
        out.push_back(i + 1 < in.size() ? kDigits[(n >> 6) & 63] : '=');
        out.push_back(i + 2 < in.size() ? kDigits[n & 63] : '=');
    }
    return out;
}

std::optional<std::string> decodeBase64(std::string_view in) {
    if (const auto comma = in.find(','); in.starts_with("data:")) {
        if (comma == std::string_view::npos || !in.substr(0, comma).ends_with(";base64"))
            return std::nullopt;
        in.remove_prefix(comma + 1);
    }
    while (!in.empty() && in.back() == '=') in.remove_suffix(1);
    if (in.size() % 4 == 1) return std::nullopt;
    std::string out;
    out.reserve(in.size() / 4 * 3 + 2);
    std::uint32_t bits = 0;
    int held = 0;
    for (const char c : in) {
        const int v = digitValue(c);
        if (v < 0) return std::nullopt;
        bits = (bits << 6) | static_cast<std::uint32_t>(v);
        held += 6;
        if (held >= 8) {
            held -= 8;
            out.push_back(static_cast<char>((bits >> held) & 0xff));
        }
    }
    return out;
}

std::string wavDataUri(std::span<const std::int16_t> samples, int sampleRate) {
    const auto dataBytes = static_cast<std::uint32_t>(samples.size() * 2);
    std::string wav = "RIFF";
    putLe(wav, 36 + dataBytes, 4);
    wav += "WAVEfmt ";
    putLe(wav, 16, 4);                                          // fmt chunk size
    putLe(wav, 1, 2);                                           // PCM
    putLe(wav, 1, 2);                                           // mono
    putLe(wav, static_cast<std::uint32_t>(sampleRate), 4);      // frames per second
    putLe(wav, static_cast<std::uint32_t>(sampleRate) * 2, 4);  // bytes per second
    putLe(wav, 2, 2);                                           // bytes per frame
    putLe(wav, 16, 2);                                          // bits per sample
    wav += "data";
    putLe(wav, dataBytes, 4);
    for (const auto s : samples) putLe(wav, static_cast<std::uint16_t>(s), 2);
    return "data:audio/wav;base64," + encodeBase64(wav);
}

}  // namespace lipsyncd::editor
