// The control protocol's one table: every command and argument in it is checked the same way
// by the daemon and by `lipsync ctl`, and what the table does not know is refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <lipsyncd/daemon.hpp>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

using daemon::ControlArg;

// A value of the wrong type for `arg`.
json wrongValue(const ControlArg& arg) {
    return arg.type == ControlArg::Type::Boolean ? json("yes") : json::array({1});
}

TEST(CommandTable, EveryArgumentOfTheWrongTypeIsRefusedByName) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    for (const auto& command : daemon::controlCommands())
        for (const auto& arg : command.args) {
            json r = {{"cmd", command.name}, {arg.name, wrongValue(arg)}};
            ASSERT_TRUE(daemon::checkControlRequest(r).has_value()) << r;
            const auto reply = c.request(r);
            EXPECT_EQ(reply["ok"], false) << r << " -> " << reply;
            EXPECT_NE(reply.value("error", "").find(std::string(arg.name)), std::string::npos)
                << reply;
        }
    EXPECT_TRUE(d.running());
    EXPECT_EQ(d.stop(), 0);
}

TEST(CommandTable, AnArgumentTheTableDoesNotKnowIsRefused) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto reply = c.request({{"cmd", "stop"}, {"now", true}});
    EXPECT_EQ(reply["ok"], false) << reply;
    EXPECT_NE(reply.value("error", "").find("now"), std::string::npos) << reply;
    const auto unknown = c.request({{"cmd", "dance"}});
    for (const auto& command : daemon::controlCommands())  // the refusal lists what exists
        EXPECT_NE(unknown.value("error", "").find(std::string(command.name)), std::string::npos);
    EXPECT_EQ(d.stop(), 0);
}

TEST(CommandTable, CtlChecksItsRequestAgainstTheTableBeforeSending) {
    const auto r = runLipsync({"ctl", "--socket", "/nonexistent/sock", "live", "maybe"});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    const auto s = runLipsync({"ctl", "--socket", "/nonexistent/sock", "status", "extra"});
    EXPECT_EQ(s.exitCode, 2) << s.err;
}

// A reply for a person is indented, a field a line; into a pipe (scripts) it stays one line.
TEST(CommandTable, CtlPrintsOneLineForScriptsAndIndentedWhenAsked) {
    DaemonProcess d;
    d.start();
    ASSERT_TRUE(Client(d.socket()).connected());  // the daemon is up
    const auto lines = [](const std::string& s) { return std::count(s.begin(), s.end(), '\n'); };
    const auto piped = runLipsync({"ctl", "--socket", d.socket().string(), "status"});
    ASSERT_EQ(piped.exitCode, 0) << piped.err;
    EXPECT_EQ(lines(piped.out), 1) << piped.out;
    const auto pretty = runLipsync({"ctl", "--socket", d.socket().string(), "status", "--pretty"});
    ASSERT_EQ(pretty.exitCode, 0) << pretty.err;
    EXPECT_GT(lines(pretty.out), 20) << pretty.out;
    EXPECT_TRUE(json::parse(pretty.out)["ok"]) << pretty.out;
    const auto both =
        runLipsync({"ctl", "--socket", d.socket().string(), "status", "--pretty", "--one-line"});
    EXPECT_EQ(both.exitCode, 2) << both.err;
    EXPECT_EQ(d.stop(), 0);
}

// A socket that accepts and never answers: ctl gives up at its deadline, exit 1.
TEST(CommandTable, CtlTimesOutOnADaemonThatDoesNotAnswer) {
    const auto dir = scratchDir("ctl_timeout");
    const auto path = dir / "mute.sock";
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strncpy(a.sun_path, path.c_str(), sizeof(a.sun_path) - 1);
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    ASSERT_EQ(::listen(fd, 4), 0);
    const auto started = std::chrono::steady_clock::now();
    const auto r = runProgram("/usr/bin/timeout", {"10", LIPSYNCD_LIPSYNC_BIN, "ctl", "--socket",
                                                   path.string(), "--timeout", "0.3", "status"});
    const auto took = std::chrono::steady_clock::now() - started;
    ::close(fd);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_NE(r.err.find("did not answer"), std::string::npos) << r.err;
    EXPECT_LT(took, 8s);
}

}  // namespace
}  // namespace lipsyncd::test
