// Sync you can measure: the daemon drives the mouth exactly the puppet's lead ahead of the
// sound it plays. The sound's clock comes from the frame events (the position heard in the
// same tick as the actuator commands); the reference is the offline pass (`analyze` then
// `drive`) of the same file through the same puppet, on the file's own timeline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "DaemonProcess.hpp"

namespace lipsyncd::test {
namespace {

using Series = std::vector<std::pair<double, double>>;

// The terminal puppet with a lead time (its servo lag).
fs::path puppetWithLead(const fs::path& dir, double lead) {
    auto text = slurp(findNamedDataFile("terminal", "puppets", ".toml"));
    text.insert(text.find("[[actuator]]"), "lead = " + std::to_string(lead) + "\n\n");
    const auto path = dir / "lead.toml";
    std::ofstream(path) << text;
    return path;
}

double valueAt(const Series& s, double t) {
    const auto it = std::lower_bound(s.begin(), s.end(), std::make_pair(t, -1e300));
    if (it == s.begin()) return s.front().second;
    if (it == s.end()) return s.back().second;
    const auto& [t1, v1] = *it;
    const auto& [t0, v0] = *(it - 1);
    return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
}

Series recordedJaw(const fs::path& csv) {
    Series out;
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line))
        if (const auto at = line.find(",jaw,"); at != std::string::npos)
            out.emplace_back(std::stod(line.substr(0, at)), std::stod(line.substr(at + 5)));
    return out;
}

TEST(Sync, TheMouthLeadsTheSoundByThePuppetsLeadWithinOneFrame) {
    constexpr double kLead = 0.08, kFrame = 0.01;
    const auto tmp = scratchDir("sync_puppet");
    const auto puppet = puppetWithLead(tmp, kLead);
    DaemonProcess d("", "null", puppet.string());
    d.start();
    Client watcher(d.socket()), c(d.socket());
    ASSERT_TRUE(watcher.connected() && c.connected());
    ASSERT_TRUE(watcher.request({{"cmd", "subscribe"}})["ok"]);
    const auto example = findDataFile("examples/hello.wav");
    const auto reply = c.request({{"cmd", "play"}, {"file", example.string()}});
    ASSERT_TRUE(reply["ok"]) << reply;
    const double duration = reply["duration"].get<double>();
    // The daemon's clock minus the sound's, from every frame event while the clip plays.
    std::vector<double> offsets;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration + 3);
    while (std::chrono::steady_clock::now() < end) {
        const auto e = json::parse(watcher.readLine(), nullptr, false);
        if (e.contains("position") && e["position"].get<double>() > 0.05)
            offsets.push_back(e["time"].get<double>() - e["position"].get<double>());
        if (!offsets.empty() && !e.contains("position")) break;  // the clip has ended
    }
    EXPECT_EQ(d.stop(), 0);
    ASSERT_GT(offsets.size(), 20u);
    std::sort(offsets.begin(), offsets.end());
    const double offset = offsets[offsets.size() / 2];

    const auto off = tmp / "offline";
    fs::create_directories(off);
    ASSERT_EQ(runLipsync({"analyze", example.string(), "--weights", (off / "w.csv").string(), "-q"})
                  .exitCode,
              0);
    ASSERT_EQ(runLipsync({"drive", "--weights", (off / "w.csv").string(), "--puppet",
                          puppet.string(), "--no-hardware", "--record", (off / "rec.csv").string()})
                  .exitCode,
              0);
    const auto offline = recordedJaw(off / "rec.csv");
    const auto daemon = d.recorded("jaw");
    ASSERT_GT(offline.size(), 100u);
    // The lag (1 ms steps) at which the daemon's jaw, on the sound's timeline, best matches
    // the offline jaw: the daemon at sound time p shows what the file has at p + lag.
    double bestLag = 0, bestErr = 1e9;
    for (int ms = -200; ms <= 200; ++ms) {
        const double lag = ms / 1000.0;
        double err = 0;
        int n = 0;
        for (const auto& [t, v] : daemon) {
            const double p = t - offset;
            if (p < 0.1 || p > duration - 0.3) continue;
            err += std::abs(v - valueAt(offline, p + lag));
            ++n;
        }
        if (n > 50 && err / n < bestErr) bestErr = err / n, bestLag = lag;
    }
    std::cout << "measured lead " << bestLag * 1000 << " ms (configured " << kLead * 1000
              << " ms), mean |difference| " << bestErr << "\n";
    EXPECT_NEAR(bestLag, kLead, kFrame);
    EXPECT_LT(bestErr, 0.05);
}

TEST(Sync, StatusReportsTheEndToEndLatency) {
    const auto tmp = scratchDir("sync_status");
    DaemonProcess d("", "null", puppetWithLead(tmp, 0.05).string());
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    ASSERT_TRUE(
        c.request({{"cmd", "play"}, {"file", findDataFile("examples/hello.wav").string()}})["ok"]);
    std::this_thread::sleep_for(600ms);
    const auto s = c.request({{"cmd", "status"}});
    ASSERT_TRUE(s.contains("latency")) << s;
    EXPECT_DOUBLE_EQ(s["latency"]["lead"].get<double>(), 0.05);
    // The null device holds half a second ahead of its clock, as a device buffer would.
    EXPECT_GT(s["latency"]["end_to_end"].get<double>(), 0.3) << s;
    EXPECT_LT(s["latency"]["end_to_end"].get<double>(), 0.6) << s;
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
