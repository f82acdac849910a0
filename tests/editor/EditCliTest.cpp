// `lipsync edit` as a user starts it: the address with its token on the first line, a busy
// port or a folder that does not exist refused at once with exit code 1 and a clear message.
#include <gtest/gtest.h>

#include <regex>

#include "../cli/RunLipsync.hpp"
#include "WebDriver.hpp"

namespace lipsyncd::test {
namespace {

TEST(EditCli, PrintsALoopbackAddressWithATokenAndRefusesABusyPort) {
    const auto dir = scratchDir("edit_cli");
    ChildProcess editor({LIPSYNCD_LIPSYNC_BIN, "edit", "--port", "0", "--no-open"},
                        dir / "edit.out", dir / "edit.err");
    std::smatch m;
    std::string first;
    const std::regex address(R"(^lipsync edit: http://127\.0\.0\.1:(\d+)/\?token=[0-9a-f]{32}\n)");
    ASSERT_TRUE(waitFor(
        [&] {
            first = slurp(dir / "edit.out");
            return std::regex_search(first, m, address);
        },
        20))
        << first << slurp(dir / "edit.err");
    const auto busy = runLipsync({"edit", "--port", m[1].str(), "--no-open"});
    EXPECT_EQ(busy.exitCode, 1);
    EXPECT_NE(busy.err.find("cannot listen on 127.0.0.1:" + m[1].str()), std::string::npos)
        << busy.err;
    // Without the token the API answers 401 and nothing else.
    httplib::Client http("127.0.0.1", std::stoi(m[1].str()));
    const auto r = http.Get("/api/bigrams");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 401);
}

TEST(EditCli, ACharacterInAFolderThatDoesNotExistIsRefused) {
    const auto r = runLipsync(
        {"edit", "--character", "/nonexistent-folder/crab.json", "--no-open", "--port", "0"});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("/nonexistent-folder/crab.json: no such folder"), std::string::npos)
        << r.err;
}

}  // namespace
}  // namespace lipsyncd::test
