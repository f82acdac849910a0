// The one espeak-ng synthesiser of a test process (espeak-ng cannot be initialised again once
// terminated, and one synthesiser exists at a time), shared by every test file.
#pragma once

#include <lipsyncd/tts.hpp>

namespace lipsyncd::test {

inline EspeakSynthesizer& espeak() {
    static EspeakSynthesizer instance;
    return instance;
}

}  // namespace lipsyncd::test
