// The show goes on: hostile and careless clients (every case of issue 12 at once) while the
// daemon plays. It stays up, answers status promptly, and the recorded actuator stream never
// stops and never moves faster than the puppet's slew. And a full queue of the longest clips
// the config allows keeps memory small (clips are prepared one ahead of the one playing).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <atomic>
#include <cmath>
#include <lipsyncd/output.hpp>
#include <numeric>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

// A 16-bit mono WAV of `seconds` of a 150 Hz buzz at `rate`.
void writeBuzz(const fs::path& path, double seconds, int rate) {
    const auto n = static_cast<std::uint32_t>(seconds * rate);
    std::ofstream out(path, std::ios::binary);
    const auto put = [&](std::uint32_t v, int bytes) {
        out.write(reinterpret_cast<const char*>(&v), bytes);
    };
    out << "RIFF";
    put(36 + n * 2, 4);
    out << "WAVEfmt ";
    put(16, 4), put(1, 2), put(1, 2), put(static_cast<std::uint32_t>(rate), 4),
        put(static_cast<std::uint32_t>(rate * 2), 4), put(2, 2), put(16, 2);
    out << "data";
    put(n * 2, 4);
    std::vector<std::int16_t> pcm(n);
    for (std::uint32_t i = 0; i < n; ++i)
        pcm[i] = static_cast<std::int16_t>(8000 * std::sin(2 * M_PI * 150 * i / rate));
    out.write(reinterpret_cast<const char*>(pcm.data()), n * 2);
}

// Every way of asking badly from issue 12, over and over, until `stop`.
void vandalise(const fs::path& socket, const fs::path& fifo, const std::atomic<bool>& stop) {
    const std::vector<std::string> lines = {
        R"({"cmd":"subscribe","on":"x"})",
        R"({"cmd":"subscribe","on":1})",
        "\xff",
        R"({"cmd":"play","file":")" + fifo.string() + R"("})",
        json{{"cmd", "say"}, {"text", std::string(20000, 'a')}}.dump(),
        std::string(70 * 1024, ' ') + R"({"cmd":"stop"})",
        R"({"cmd":"live","on":"yes"})",
        "[1,2,3]",
    };
    while (!stop) {
        Client c(socket);
        if (!c.connected()) continue;
        for (const auto& l : lines) {
            c.sendLine(l);
            c.readLine();
        }
        c.sendRaw(std::string(10 * 1024 * 1024, 'x') + "\n");
        c.readLine();
    }
}

TEST(Soak, HostileClientsDuringPlaybackNeitherStopNorStallTheShow) {
    DaemonProcess d;
    d.append("max_clients = 8");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto fifo = d.dir / "pipe.wav";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto example = findDataFile("examples/hello.wav").string();
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(c.request({{"cmd", "play"}, {"file", example}})["ok"]);
    std::atomic<bool> stop{false};
    std::vector<std::thread> vandals;
    for (int i = 0; i < 3; ++i) vandals.emplace_back([&] { vandalise(d.socket(), fifo, stop); });
    std::vector<std::unique_ptr<Client>> crowd;  // more than max_clients
    for (int i = 0; i < 10; ++i) crowd.push_back(std::make_unique<Client>(d.socket()));
    std::vector<double> answers;
    for (int i = 0; i < 70; ++i) {  // 7 s: the first 5.2 s clip plays through
        const auto t0 = std::chrono::steady_clock::now();
        const auto s = c.request({{"cmd", "status"}});
        answers.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        ASSERT_TRUE(s["ok"]) << s;
        if (i == 35) ::kill(d.pid, SIGHUP);
        std::this_thread::sleep_for(100ms);
    }
    stop = true;
    for (auto& v : vandals) v.join();
    EXPECT_TRUE(d.running());
    EXPECT_GE(c.request({{"cmd", "status"}})["played"].get<int>(), 1) << "nothing played";
    EXPECT_EQ(d.stop(), 0);
    std::sort(answers.begin(), answers.end());
    std::cout << "status answered in " << answers[answers.size() / 2] * 1000 << " ms (median), "
              << answers.back() * 1000 << " ms (slowest of " << answers.size() << ")\n";
    EXPECT_LT(answers[answers.size() * 9 / 10], 0.1) << "status slower than 100 ms";
    const auto jaw = d.recorded("jaw");
    ASSERT_GT(jaw.size(), 300u);
    double gap = 0, fastest = 0;
    for (std::size_t i = 1; i < jaw.size(); ++i) {
        const double dt = jaw[i].first - jaw[i - 1].first;
        gap = std::max(gap, dt);
        // (Steps closer than 5 ms say little: the record's times are rounded to 0.1 ms.)
        if (dt >= 0.005)
            fastest = std::max(fastest, std::abs(jaw[i].second - jaw[i - 1].second) / dt);
    }
    EXPECT_LT(gap, 0.25) << "the actuator stream stopped";
    const auto& puppet = output::Puppet::named("terminal");
    const double slew =
        std::find_if(puppet.actuators.begin(), puppet.actuators.end(), [](const auto& a) {
            return a.name == "jaw";
        })->slew;
    EXPECT_LE(fastest, slew * 1.05) << "the jaw jumped (faster than its slew, " << slew << "/s)";
}

TEST(Soak, AFullQueueOfTheLongestClipsKeepsMemorySmall) {
    const auto tmp = scratchDir("soak_rss");
    writeBuzz(tmp / "long.wav", 30, 48000);
    DaemonProcess d;
    d.append("[limits]\nmax_clip_seconds = 30\nmax_queue = 8\n");
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    for (int i = 0; i < 8; ++i)
        ASSERT_TRUE(c.request({{"cmd", "play"}, {"file", (tmp / "long.wav").string()}})["ok"]);
    EXPECT_EQ(c.request({{"cmd", "play"}, {"file", (tmp / "long.wav").string()}})["ok"], false)
        << "the queue took a ninth";
    long peak = 0;
    for (int i = 0; i < 40; ++i) {  // the first plays, the second is prepared meanwhile
        peak = std::max(peak, d.rssKiB());
        std::this_thread::sleep_for(100ms);
    }
    const auto s = c.request({{"cmd", "status"}});
    EXPECT_FALSE(s["playing"].is_null()) << s;
    std::cout << "RSS with 8 queued 30 s clips at 48 kHz: " << peak << " KiB at most\n";
    // What the clips hold is counted exactly: the one playing and the one ready ahead, never
    // the eight (2.9 MB each at 48 kHz, and the weights).
    const std::size_t clip = 30 * 48000 * 2 * 101 / 100 + 3002 * (10 * 4 + 8);
    const auto& m = s["memory"];
    EXPECT_LE(m["playing_bytes"].get<std::size_t>() + m["queue_bytes"].get<std::size_t>(),
              2 * clip + 8 * 4096)
        << s;
    // RSS, loosely: 8 clips held decoded would be 8 x 2.9 MB over the ~15 MB idle daemon.
    // (The 29-31 MB once seen under contention were transients of the worker: a second float
    // copy of each file for its levels and a per-sample buffer in the level meter, both gone;
    // scripts/measure-daemon.sh memory measures the peak.)
    EXPECT_LT(peak, 36 * 1024);
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
