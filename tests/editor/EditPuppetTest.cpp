// `lipsync edit --socket`: the preview moves the puppet the running lipsyncd drives. Against a
// test daemon (null audio, the terminal puppet, the command recorder): the recorded jaw follows
// the preview's jaw weights while the page plays, rests after it, and the service's refusals
// (a clip playing, the wrong puppet, no daemon) reach the user as clear errors.
#include <gtest/gtest.h>

#include <lipsyncd/editor.hpp>
#include <regex>

#include "../daemon/DaemonProcess.hpp"
#include "WebDriver.hpp"

namespace lipsyncd::test {
namespace {

struct Editor {
    ChildProcess process;
    std::unique_ptr<httplib::Client> http;
    httplib::Headers headers;

    Editor(const fs::path& dir, const fs::path& socket)
        : process({LIPSYNCD_LIPSYNC_BIN, "edit", "--socket", socket.string(), "--puppet",
                   "terminal", "--port", "0", "--no-open"},
                  dir / "edit.out", dir / "edit.err") {
        std::smatch m;
        std::string out;
        const std::regex address(R"(http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32}))");
        if (!waitFor(
                [&] {
                    out = slurp(dir / "edit.out");
                    return std::regex_search(out, m, address);
                },
                20))
            return;
        http = std::make_unique<httplib::Client>("127.0.0.1", std::stoi(m[1].str()));
        http->set_read_timeout(30);
        headers = {{"X-Lipsync-Token", m[2].str()}};
    }
    json post(const std::string& path, const json& body, int expectStatus = 200) {
        const auto r = http->Post(path.c_str(), headers, body.dump(), "application/json");
        EXPECT_TRUE(r);
        if (!r) return {};
        EXPECT_EQ(r->status, expectStatus) << path << ": " << r->body.substr(0, 300);
        return json::parse(r->body);
    }
};

// The preview's `jaw` weights, one per 10 ms frame.
std::vector<double> jawWeights(const json& preview) {
    const auto poses = preview["weights"]["poses"].get<std::vector<std::string>>();
    const auto at = std::find(poses.begin(), poses.end(), "jaw") - poses.begin();
    return preview["weights"]["values"][at].get<std::vector<double>>();
}

TEST(EditPuppet, ThePreviewMovesThePuppetTheServiceDrivesAndItRestsAfter) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    Editor e(d.dir, d.socket());
    ASSERT_TRUE(e.http) << slurp(d.dir / "edit.err");
    EXPECT_EQ(e.http->Get("/api/bigrams", e.headers)->body.find("\"puppet\":\"terminal\"") !=
                  std::string::npos,
              true);

    const auto preview = e.post("/api/preview", {{"text", "Open wide, father, I am awake."}});
    const auto jaw = jawWeights(preview);
    ASSERT_GT(*std::max_element(jaw.begin(), jaw.end()), 0.3);
    const auto perform = e.post("/api/perform", {{"from", 0}});
    EXPECT_EQ(perform["playing"], true);
    std::this_thread::sleep_for(std::chrono::duration<double>(
        preview["duration"].get<double>() + 1.2));  // the hold, the stall timeout, the slew
    EXPECT_EQ(d.stop(), 0);

    // The daemon rests until the editor's stream opens the jaw: from there on 10 ms steps,
    // against the preview from where its jaw opens.
    const auto rec = d.recorded("jaw");
    std::size_t i = 0;
    while (i < rec.size() && rec[i].second == 0.0) ++i;
    ASSERT_LT(i, rec.size()) << "the jaw never moved";
    std::vector<double> moved;
    for (double t = rec[i].first; t < rec.back().first; t += 0.01) {
        while (i + 1 < rec.size() && rec[i + 1].first <= t) ++i;
        moved.push_back(rec[i].second);
    }
    const auto opens = static_cast<std::size_t>(
        std::find_if(jaw.begin(), jaw.end(), [](double v) { return v > 0; }) - jaw.begin());
    // The terminal puppet's jaw is the jaw pose (gain 1), slew-limited: it follows the preview
    // closely at the best lag within ±100 ms (the socket, the daemon's tick).
    double best = 1e9;
    const std::size_t compared = jaw.size() - opens;
    for (int lag = -10; lag <= 10; ++lag) {
        double err = 0;
        std::size_t n = 0;
        for (std::size_t k = opens; k < jaw.size(); ++k) {
            const long j = static_cast<long>(k - opens) + lag;
            if (j < 0 || j >= static_cast<long>(moved.size())) continue;
            err += std::abs(moved[static_cast<std::size_t>(j)] - jaw[k]);
            ++n;
        }
        if (n > compared * 3 / 4) best = std::min(best, err / static_cast<double>(n));
    }
    std::cout << "puppet jaw against the preview's jaw: mean |difference| " << best << '\n';
    EXPECT_LT(best, 0.05) << "mean |puppet jaw − preview jaw| at the best lag";
    EXPECT_EQ(rec.back().second, 0.0) << "the jaw did not go back to rest after the preview";
}

// A puppet with a servo lag: the stream starts the lead into the preview and sends each frame
// that much early, so the frames sent are exactly those from `from` + lead on.
TEST(EditPuppet, TheStreamLeadsByThePuppetsLead) {
    const auto dir = scratchDir("edit_puppet_lead");
    auto puppet = slurp(findDataFile("puppets/terminal.toml"));
    puppet.insert(puppet.find("\n[[actuator]]"), "\nlead = 0.2\n");
    std::ofstream(dir / "laggy.toml") << puppet;
    DaemonProcess d("", "null", (dir / "laggy.toml").string());
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    editor::PuppetStream stream(d.socket(), "");
    EXPECT_DOUBLE_EQ(stream.leadSeconds(), 0.2);
    PoseTrack track;
    track.poses = {"jaw"};
    for (int f = 0; f < 100; ++f) track.append(f / 100.0, std::vector<float>{f < 20 ? 0.0f : 0.5f});
    ASSERT_FALSE(stream.play(track, 0.3));  // from 0.3 s: frames 50..99 (0.5 s and on)
    std::this_thread::sleep_for(800ms);     // 0.5 s of frames, 0.2 s early
    EXPECT_EQ(stream.framesSent(), 50u);
    EXPECT_EQ(stream.lastError(), "");
    EXPECT_EQ(d.stop(), 0);
}

TEST(EditPuppet, TheServicesRefusalsReachTheUser) {
    DaemonProcess d;
    d.start();
    Client c(d.socket());
    ASSERT_TRUE(c.connected());
    const auto wrong = runLipsync(
        {"edit", "--socket", d.socket().string(), "--puppet", "crab", "--port", "0", "--no-open"});
    EXPECT_EQ(wrong.exitCode, 1);
    EXPECT_NE(wrong.err.find("lipsyncd drives the puppet 'terminal', not 'crab'"),
              std::string::npos)
        << wrong.err;
    const auto none = runLipsync(
        {"edit", "--socket", (d.dir / "nobody.sock").string(), "--port", "0", "--no-open"});
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_NE(none.err.find("cannot connect to lipsyncd"), std::string::npos) << none.err;
    const auto alone = runLipsync({"edit", "--puppet", "terminal", "--port", "0", "--no-open"});
    EXPECT_EQ(alone.exitCode, 2) << alone.err;

    Editor e(d.dir, d.socket());
    ASSERT_TRUE(e.http) << slurp(d.dir / "edit.err");
    EXPECT_NE(e.post("/api/perform", {{"from", 0}}, 409)["error"].get<std::string>().find(
                  "preview first"),
              std::string::npos);
    // A clip that starts while the preview streams takes the mouth; the stream stops and the
    // page hears why when it stops too.
    e.post("/api/preview", {{"text", "Open wide, father, I am awake and ready to talk to you."}});
    EXPECT_EQ(e.post("/api/perform", {{"from", 0}})["playing"], true);
    ASSERT_EQ(c.request({{"cmd", "say"}, {"text", "Hello hello hello hello hello."}})["ok"], true);
    ASSERT_TRUE(waitFor([&] { return !c.request({{"cmd", "status"}})["playing"].is_null(); }, 20));
    std::this_thread::sleep_for(100ms);
    const auto stopped = e.post("/api/perform", {{"stop", true}});
    EXPECT_GT(stopped["frames_sent"].get<int>(), 0);
    EXPECT_NE(stopped.value("stopped_early", "").find("refused while a clip plays"),
              std::string::npos)
        << stopped;
    // Starting while the clip plays: refused at once, with the service's reason.
    const auto refused = e.post("/api/perform", {{"from", 0}}, 409);
    EXPECT_NE(refused["error"].get<std::string>().find("refused while a clip plays"),
              std::string::npos)
        << refused;
    EXPECT_EQ(d.stop(), 0);
}

}  // namespace
}  // namespace lipsyncd::test
