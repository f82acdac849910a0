// lipsyncd as systemd runs it: a subprocess with a test NOTIFY_SOCKET, the null or file audio
// device and the recorder, driven over its control socket.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <nlohmann/json.hpp>
#include <thread>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

TEST(Daemon, NotifiesSystemdReloadsOnSighupAndRestsOnSigterm) {
    DaemonProcess d;
    NotifySocket notify(d.dir / "notify");
    d.start();
    ASSERT_TRUE(notify.waitFor("READY=1")) << "no READY=1";
    EXPECT_TRUE(notify.waitFor("STATUS=ready"));
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    EXPECT_TRUE(c.request({{"cmd", "say"}, {"text", "Open wide."}})["ok"]);
    waitUntilIdle(c);
    // SIGHUP: RELOADING=1, then READY=1 again; the socket stays open.
    std::ofstream(d.dir / "lipsyncd.toml", std::ios::app) << "";
    ::kill(d.pid, SIGHUP);
    EXPECT_TRUE(notify.waitFor("RELOADING=1"));
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);
    // SIGTERM: the mouth goes to rest, then the process exits 0.
    EXPECT_TRUE(c.request({{"cmd", "say"}, {"text", "Hello hello hello hello."}})["ok"]);
    std::this_thread::sleep_for(400ms);
    EXPECT_EQ(d.stop(SIGTERM), 0);
    EXPECT_TRUE(notify.waitFor("STOPPING=1"));
    const auto jaw = d.recorded("jaw");
    ASSERT_FALSE(jaw.empty());
    double peak = 0;
    for (const auto& [t, v] : jaw) peak = std::max(peak, v);
    EXPECT_GT(peak, 0.2) << "the jaw never moved";
    EXPECT_EQ(jaw.back().second, 0.0) << "not at rest after SIGTERM";
}

TEST(Daemon, MalformedConfigStopsStartupWithTheLine) {
    const auto dir = scratchDir("daemon_badconf");
    std::ofstream(dir / "bad.toml")
        << "[audio]\ndevice = \"null\"\n[mouth]\npupet = \"terminal\"\n";
    const auto r = runProgram(LIPSYNCD_DAEMON_BIN, {"--config", (dir / "bad.toml").string()});
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("bad.toml:4"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("pupet"), std::string::npos) << r.err;
}

TEST(Daemon, PlayedFileDrivesTheMouthAsTheOfflinePassDoes) {
    DaemonProcess d("", "file:" + (scratchDir("daemon_audio") / "out.wav").string());
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    const auto example = findDataFile("examples/hello.wav");
    const auto reply = c.request({{"cmd", "play"}, {"file", example.string()}});
    ASSERT_TRUE(reply["ok"]) << reply.dump();
    waitUntilIdle(c);
    EXPECT_EQ(d.stop(), 0);
    // Offline: the same audio, analysed and driven through the same puppet.
    const auto off = d.dir / "offline";
    fs::create_directories(off);
    ASSERT_EQ(runLipsync({"analyze", example.string(), "--weights", (off / "w.csv").string(), "-q"})
                  .exitCode,
              0);
    ASSERT_EQ(runLipsync({"drive", "--weights", (off / "w.csv").string(), "--puppet", "terminal",
                          "--no-hardware", "--record", (off / "rec.csv").string()})
                  .exitCode,
              0);
    std::vector<double> offline;
    {
        std::ifstream in(off / "rec.csv");
        std::string line;
        std::getline(in, line);
        while (std::getline(in, line))
            if (line.find(",jaw,") != std::string::npos)
                offline.push_back(std::stod(line.substr(line.find(",jaw,") + 5)));
    }
    // The daemon's jaw while the clip played, resampled onto 10 ms steps from its first movement.
    const auto live = d.recorded("jaw");
    ASSERT_GT(live.size(), 100u);
    std::vector<double> daemon;
    std::size_t i = 0;
    const double t0 = live.front().first;
    for (double t = t0; t < live.back().first; t += 0.01) {
        while (i + 1 < live.size() && live[i + 1].first <= t) ++i;
        daemon.push_back(live[i].second);
    }
    // Best agreement within ±150 ms of lag (start-up and the device clock's granularity).
    double best = 1e9;
    for (int lag = -15; lag <= 15; ++lag) {
        double err = 0;
        std::size_t n = 0;
        for (std::size_t k = 0; k < offline.size(); ++k) {
            const long j = static_cast<long>(k) + lag;
            if (j < 0 || j >= static_cast<long>(daemon.size())) continue;
            err += std::abs(daemon[static_cast<std::size_t>(j)] - offline[k]);
            ++n;
        }
        if (n > offline.size() / 2) best = std::min(best, err / static_cast<double>(n));
    }
    EXPECT_LT(best, 0.05) << "mean |daemon − offline| jaw difference at the best lag";
}

TEST(Daemon, ManyClientsAndMalformedRequestsLoseNothingAndMemoryStaysFlat) {
    DaemonProcess d;
    d.start();
    {
        Client warm(d.dir / "control.sock");
        ASSERT_TRUE(warm.connected());
        warm.request({{"cmd", "status"}});
    }
    std::this_thread::sleep_for(200ms);
    const long before = d.rssKiB();
    std::vector<std::thread> threads;
    std::atomic<int> good{0}, refused{0}, lost{0};
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            Client c(d.dir / "control.sock");
            for (int i = 0; i < 80; ++i) {
                std::string line;
                switch ((i + t) % 5) {
                    case 0:
                        line = R"({"cmd":"status"})";
                        break;
                    case 1:
                        line = "{broken json";
                        break;
                    case 2:
                        line = R"({"cmd":"frobnicate"})";
                        break;
                    case 3:
                        line = R"({"cmd":"play","file":"/nonexistent.wav"})";
                        break;
                    default:
                        line = R"([1,2,3])";
                        break;
                }
                c.sendLine(line);
                const auto reply = c.readLine();
                if (reply.empty()) {
                    ++lost;
                    continue;
                }
                json::parse(reply)["ok"].get<bool>() ? ++good : ++refused;
            }
        });
    for (auto& t : threads) t.join();
    EXPECT_EQ(lost.load(), 0);
    EXPECT_EQ(good.load(), 4 * 16);
    EXPECT_EQ(refused.load(), 4 * 64);
    const long after = d.rssKiB();
    EXPECT_LT(after - before, 4096) << "RSS grew from " << before << " to " << after << " KiB";
    Client c(d.dir / "control.sock");
    EXPECT_TRUE(c.request({{"cmd", "status"}})["ok"]);  // and it is still there
    EXPECT_EQ(d.stop(), 0);
}

// 16-bit mono WAV: `silence` seconds, then a 120 Hz buzz (a voiced sound) for `sound` seconds.
void writeOnsetWav(const fs::path& path, double silence, double sound, int rate = 16000) {
    std::vector<std::int16_t> pcm(static_cast<std::size_t>((silence + sound + 1.0) * rate), 0);
    const auto from = static_cast<std::size_t>(silence * rate),
               to = static_cast<std::size_t>((silence + sound) * rate);
    for (std::size_t i = from; i < to; ++i) {
        double v = 0;
        for (int h = 1; h <= 20; ++h)
            v += std::sin(2 * M_PI * 120 * h * static_cast<double>(i) / rate) / h *
                 (h == 6 || h == 10 ? 3 : 1);
        pcm[i] = static_cast<std::int16_t>(std::clamp(v * 4000, -32000.0, 32000.0));
    }
    std::ofstream out(path, std::ios::binary);
    const auto put = [&](std::uint32_t v, int bytes) {
        out.write(reinterpret_cast<const char*>(&v), bytes);
    };
    const auto data = static_cast<std::uint32_t>(pcm.size() * 2);
    out << "RIFF";
    put(36 + data, 4);
    out << "WAVEfmt ";
    put(16, 4), put(1, 2), put(1, 2), put(static_cast<std::uint32_t>(rate), 4),
        put(static_cast<std::uint32_t>(rate * 2), 4), put(2, 2), put(16, 2);
    out << "data";
    put(data, 4);
    out.write(reinterpret_cast<const char*>(pcm.data()), data);
}

TEST(Daemon, LiveCaptureMovesTheMouthSoonAfterASoundStarts) {
    const auto dir = scratchDir("daemon_live");
    writeOnsetWav(dir / "onset.wav", 1.0, 0.6);
    DaemonProcess d("", "null");
    std::ofstream(d.dir / "lipsyncd.toml", std::ios::app)
        << "[live]\ndevice = \"file:" << (dir / "onset.wav").string() << "\"\n";
    d.start();
    Client c(d.dir / "control.sock");
    ASSERT_TRUE(c.connected());
    const auto on = c.request({{"cmd", "live"}, {"on", true}});
    ASSERT_TRUE(on["ok"]) << on.dump();
    std::this_thread::sleep_for(2500ms);
    EXPECT_TRUE(c.request({{"cmd", "status"}})["live"]);
    EXPECT_TRUE(c.request({{"cmd", "live"}, {"on", false}})["ok"]);
    EXPECT_EQ(d.stop(), 0);
    // The first command that leaves rest, measured from the sound's onset in the capture.
    const double onset = on["started"].get<double>() + 1.0;
    double first = -1;
    for (const auto* name : {"jaw", "lips_round", "lips_closed", "tongue"})
        for (const auto& [t, v] : d.recorded(name))
            if (t > onset - 0.5 && v > 0.01) {
                if (first < 0 || t < first) first = t;
                break;
            }
    ASSERT_GT(first, 0) << "the mouth never moved on live input";
    const double latency = first - onset;
    std::cout << "live latency (onset -> first actuator command): " << latency * 1000
              << " ms (front end bound " << on["front_end_latency"].get<double>() * 1000
              << " ms)\n";
    EXPECT_GT(latency, 0.0) << "moved before the sound";
    EXPECT_LT(latency, 0.6);
}

}  // namespace
}  // namespace lipsyncd::test
