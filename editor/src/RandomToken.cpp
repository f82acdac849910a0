// The API's token: 128 bits from the kernel's entropy source (std::random_device reads
// /dev/urandom on Linux), so another local user or a web page cannot guess it.
#include <array>
#include <cstdint>
#include <lipsyncd/editor.hpp>
#include <random>

namespace lipsyncd::editor {

std::string randomToken() {
    std::random_device entropy;
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (int i = 0; i < 4; ++i) {
        const std::uint32_t word = entropy();
        for (int shift = 28; shift >= 0; shift -= 4) out.push_back(kHex[(word >> shift) & 15]);
    }
    return out;
}

}  // namespace lipsyncd::editor
