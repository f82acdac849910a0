// Requests a careless or hostile client sends: each gets a valid JSON reply on its own
// connection, the daemon keeps running, and nothing of a refused line ever runs.
#include <gtest/gtest.h>

#include <string>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

// The daemon answered `line` with valid JSON saying no, and still answers status.
void expectRefusedAndAlive(DaemonProcess& d, Client& c, const std::string& line) {
    c.sendLine(line);
    const auto reply = c.readLine();
    ASSERT_FALSE(reply.empty()) << "no reply to " << line;
    const auto j = json::parse(reply, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << "reply is not JSON: " << reply;
    EXPECT_EQ(j["ok"], false) << reply;
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);
    EXPECT_TRUE(d.running());
}

TEST(HostileClient, SubscribeWithANonBooleanOnIsRefused) {
    DaemonProcess d;
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    expectRefusedAndAlive(d, c, R"({"cmd":"subscribe","on":"x"})");
    expectRefusedAndAlive(d, c, R"({"cmd":"subscribe","on":1})");
    EXPECT_EQ(d.stop(), 0);
}

TEST(HostileClient, InvalidUtf8GetsAValidJsonReply) {
    DaemonProcess d;
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    expectRefusedAndAlive(d, c, "\xff");
    expectRefusedAndAlive(d, c, "{\"cmd\":\"play\",\"file\":\"\xc3\x28\"}");
    expectRefusedAndAlive(d, c, "{\"cmd\":\"\xfe\xff\"}");
    EXPECT_EQ(d.stop(), 0);
}

TEST(HostileClient, ANumberBeyondADoubleGetsAnErrorNotAnExit) {
    // nlohmann::json reports 1e600 as out_of_range, not parse_error (found by fuzzing
    // curve_json; the control socket had the same catch).
    DaemonProcess d;
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    expectRefusedAndAlive(d, c, R"({"cmd":"status","n":1e600})");
    expectRefusedAndAlive(d, c, R"({"cmd":"say","text":"hi","voice":-1e999})");
    EXPECT_EQ(d.stop(), 0);
}

TEST(HostileClient, TheTailOfAnOverlongLineNeverRuns) {
    DaemonProcess d;
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    // 70 KB in two writes, so the limit is crossed before the newline has arrived.
    c.sendRaw(std::string(66 * 1024, ' '));
    std::this_thread::sleep_for(200ms);
    c.sendRaw(std::string(4 * 1024, ' ') + R"({"cmd":"status"})" + "\n");
    c.sendLine(R"({"cmd":"frobnicate"})");
    const auto first = json::parse(c.readLine());
    EXPECT_EQ(first["ok"], false);
    EXPECT_NE(first["error"].get<std::string>().find("64 KiB"), std::string::npos) << first;
    const auto second = json::parse(c.readLine());
    EXPECT_FALSE(second.contains("playing")) << "the overlong line's tail ran: " << second;
    EXPECT_NE(second.dump().find("frobnicate"), std::string::npos) << second;
    EXPECT_EQ(d.stop(), 0);
}

TEST(HostileClient, ATenMegabyteLineGetsOneError) {
    DaemonProcess d;
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    c.sendRaw(std::string(10 * 1024 * 1024, 'a') + "\n");
    c.sendLine(R"({"cmd":"status"})");
    const auto first = json::parse(c.readLine());
    EXPECT_EQ(first["ok"], false) << first;
    const auto second = json::parse(c.readLine());
    EXPECT_TRUE(second.contains("playing")) << "more than one reply to one line: " << second;
    EXPECT_EQ(d.stop(), 0);
}

TEST(HostileClient, AnotherClientsErrorsNeverReachASubscriber) {
    DaemonProcess d;
    d.start();
    Client watcher(d.dir / "control.sock"), vandal(d.dir / "control.sock");
    ASSERT_TRUE(watcher.connected() && vandal.connected());
    ASSERT_TRUE(watcher.request({{"cmd", "subscribe"}})["ok"]);
    ASSERT_TRUE(vandal.request({{"cmd", "say"}, {"text", "Hello there."}})["ok"]);
    for (const auto* line : {"\xff", R"({"cmd":"subscribe","on":"x"})", "{broken", "[1]"})
        vandal.sendLine(line);
    for (int i = 0; i < 20; ++i) {
        const auto line = watcher.readLine();
        ASSERT_FALSE(line.empty()) << "the subscriber's connection ended";
        const auto j = json::parse(line, nullptr, false);
        EXPECT_EQ(j["event"], "frame") << line;
    }
    EXPECT_TRUE(d.running());
    EXPECT_EQ(d.stop(), 0);
    EXPECT_EQ(d.recorded("jaw").back().second, 0.0) << "not at rest on exit";
}

}  // namespace
}  // namespace lipsyncd::test
