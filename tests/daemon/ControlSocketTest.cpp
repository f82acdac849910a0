// The control socket as a system resource: one daemon per path, nothing but its own socket
// removed, a bounded number of clients, and no spinning when file descriptors run out.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

// Runs a second lipsyncd that is expected to refuse to start (killed after 10 s if it runs).
RunResult runDaemonExpectingRefusal(const fs::path& config) {
    return runProgram("/usr/bin/timeout", {"10", LIPSYNCD_DAEMON_BIN, "--config", config.string()});
}

TEST(ControlSocket, ASecondDaemonOnTheSamePathRefusesToStart) {
    DaemonProcess first;
    first.start();
    Client c(first.socket());
    ASSERT_TRUE(c.connected());
    const auto second = runDaemonExpectingRefusal(first.dir / "lipsyncd.toml");
    EXPECT_EQ(second.exitCode, 1);
    EXPECT_NE(second.err.find("another lipsyncd answers"), std::string::npos) << second.err;
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);
    Client again(first.socket());  // the path still leads to the first daemon
    ASSERT_TRUE(again.connected());
    EXPECT_TRUE(again.request({{"cmd", "status"}})["ok"]);
    EXPECT_EQ(first.stop(), 0);
}

TEST(ControlSocket, ARegularFileAtTheSocketPathIsNeverRemoved) {
    DaemonProcess d;
    std::ofstream(d.socket()) << "precious\n";
    const auto r = runDaemonExpectingRefusal(d.dir / "lipsyncd.toml");
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("not a socket"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(d.socket()), "precious\n");
}

TEST(ControlSocket, ClientsBeyondTheCapAreToldWhy) {
    DaemonProcess d;
    d.append("max_clients = 2");
    d.start();
    Client a(d.socket()), b(d.socket());
    ASSERT_TRUE(a.connected() && b.connected());
    EXPECT_TRUE(a.request({{"cmd", "status"}})["ok"]);
    EXPECT_TRUE(b.request({{"cmd", "status"}})["ok"]);
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto reply = json::parse(c.readLine());
    EXPECT_EQ(reply["ok"], false);
    EXPECT_NE(reply["error"].get<std::string>().find("too many clients"), std::string::npos);
    EXPECT_TRUE(a.request({{"cmd", "status"}})["ok"]);
    EXPECT_EQ(d.stop(), 0);
}

TEST(ControlSocket, PeerCredentialsAreLogged) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);
    EXPECT_EQ(d.stop(), 0);
    EXPECT_NE(d.log().find("client pid " + std::to_string(::getpid()) + " uid " +
                           std::to_string(::getuid())),
              std::string::npos)
        << d.log();
}

TEST(ControlSocket, RunningOutOfFileDescriptorsDegradesAndNeverSpins) {
    DaemonProcess d;
    d.append("max_clients = 500");
    rlimit saved{};
    ::getrlimit(RLIMIT_NOFILE, &saved);
    rlimit low = saved;
    low.rlim_cur = 48;  // the daemon's own files, and a few clients
    ::setrlimit(RLIMIT_NOFILE, &low);
    d.start();
    ::setrlimit(RLIMIT_NOFILE, &saved);
    Client first(d.socket());
    ASSERT_TRUE(first.connected());
    ASSERT_TRUE(first.request({{"cmd", "status"}})["ok"]);
    std::vector<std::unique_ptr<Client>> crowd;
    for (int i = 0; i < 80; ++i) crowd.push_back(std::make_unique<Client>(d.socket()));
    std::this_thread::sleep_for(300ms);
    const double cpu0 = d.cpuSeconds();
    std::this_thread::sleep_for(1s);
    const double cpu = d.cpuSeconds() - cpu0;
    EXPECT_LT(cpu, 0.5) << "the loop spins while descriptors are exhausted";
    int refused = 0;
    for (auto& c : crowd) {
        if (!c->connected()) continue;
        c->sendLine(R"({"cmd":"status"})");
        const auto line = c->readLine();
        if (line.find("out of file descriptors") != std::string::npos) ++refused;
    }
    EXPECT_GT(refused, 0) << "nobody was told why";
    EXPECT_TRUE(first.request({{"cmd", "status"}})["ok"]) << "a connected client lost its service";
    crowd.clear();
    bool recovered = false;  // once the daemon has seen the crowd go
    for (int i = 0; i < 40 && !recovered; ++i) {
        Client later(d.socket());
        recovered = later.connected() && later.request({{"cmd", "status"}}).value("ok", false);
        if (!recovered) std::this_thread::sleep_for(50ms);
    }
    EXPECT_TRUE(recovered) << "no recovery once descriptors are free";
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
