// A template set that must not validate: the error names the file and the field at fault.
#pragma once

#include <gtest/gtest.h>

#include <lipsyncd/dsp.hpp>
#include <string>

namespace lipsyncd::test {

inline void expectRejected(const dsp::TemplateSet& bad, const std::string& named) {
    try {
        bad.validate("set.json");
        ADD_FAILURE() << "accepted a set with " << named;
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("set.json"), std::string::npos) << e.what();
    }
}

}  // namespace lipsyncd::test
