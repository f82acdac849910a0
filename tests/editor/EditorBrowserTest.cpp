// `lipsync edit` end to end in a real browser (Debian's chromium, headless, through
// chromedriver): load the page, pick f–ah, drag a point of `open`, type a sentence, preview,
// save. The character file then differs in exactly that bigram, and `lipsync animate
// --character` on the sentence plays the change. Skips only when chromium cannot start.
// With LIPSYNCD_SCREENSHOT_DIR set, the README's screenshots are written there.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <lipsyncd/core.hpp>
#include <lipsyncd/lipsync.hpp>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../cli/RunLipsync.hpp"
#include "WebDriver.hpp"

namespace lipsyncd::test {
namespace {
using nlohmann::json;

const char* kChromium = "/usr/bin/chromium";
const char* kChromedriver = "/usr/bin/chromedriver";
const char* kSentence = "What fun";

void writeFile(const std::filesystem::path& file, const std::string& text) {
    std::ofstream(file, std::ios::binary) << text;
}

// The address `lipsync edit` prints on its first line.
std::string editorUrl(const std::filesystem::path& out) {
    std::string url;
    waitFor(
        [&] {
            std::istringstream in(slurp(out));
            std::string line;
            if (!std::getline(in, line) || line.find("http://") == std::string::npos) return false;
            url = line.substr(line.find("http://"));
            return true;
        },
        20);
    return url;
}

json chromeCapabilities(const std::filesystem::path& profile) {
    return {{"alwaysMatch",
             {{"browserName", "chrome"},
              {"goog:chromeOptions",
               {{"binary", kChromium},
                {"args",
                 {"--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--autoplay-policy=no-user-gesture-required", "--disable-dev-shm-usage",
                  "--window-size=1380,1320", "--user-data-dir=" + profile.string()}}}}}}};
}

std::filesystem::path screenshotDir(const std::filesystem::path& fallback) {
    const char* dir = std::getenv("LIPSYNCD_SCREENSHOT_DIR");
    return dir && *dir ? std::filesystem::path(dir) : fallback;
}

// The `open` column of `lipsync animate` on the sentence, with and without the character.
std::vector<double> openColumn(const std::filesystem::path& csv) {
    const auto track = readPoseTrackCsvFile(csv);
    const auto pose = *track.pose("open");
    std::vector<double> out;
    for (std::size_t f = 0; f < track.frames(); ++f) out.push_back(track.frame(f)[pose]);
    return out;
}

TEST(EditorBrowser, DragSavePreviewAndAnimateSeeTheChange) {
    if (!std::filesystem::exists(kChromium) || !std::filesystem::exists(kChromedriver))
        GTEST_SKIP() << "chromium or chromedriver is not installed (scripts/install-deps.sh)";
    const auto dir = scratchDir("editor_browser");
    const auto character = dir / "crab.json";
    const std::string before = R"({"format": "lipsyncd-character", "version": 1, "name": "crab",
 "base": "english", "pose_set": "facefx",
 "bigrams": {"aa-bmp": {"w": [[0, 0], [0.5, 1], [1, 0]]}}}
)";
    writeFile(character, before);

    ChildProcess editor({LIPSYNCD_LIPSYNC_BIN, "edit", "--port", "0", "--no-open", "--character",
                         character.string()},
                        dir / "edit.out", dir / "edit.err");
    const auto url = editorUrl(dir / "edit.out");
    ASSERT_FALSE(url.empty()) << slurp(dir / "edit.err");

    const int driverPort = freePort();
    ChildProcess driver({kChromedriver, "--port=" + std::to_string(driverPort)}, dir / "driver.out",
                        dir / "driver.err");
    WebDriver web(driverPort);
    ASSERT_TRUE(waitFor([&] { return web.up(); }, 20)) << slurp(dir / "driver.err");
    const auto failure = web.startSession(chromeCapabilities(dir / "profile"));
    if (!failure.empty()) GTEST_SKIP() << "chromium cannot start here: " << failure;

    // Load the page and pick f–ah.
    web.go(url);
    ASSERT_TRUE(
        waitFor([&] { return web.script("return document.body.dataset.ready") == "yes"; }, 20))
        << web.script("return document.getElementById('error').textContent");
    web.click("#grid button[data-pair='f-ah']");
    const std::string point = "svg[data-pose='open'] circle[data-index='6']";
    ASSERT_TRUE(waitFor(
        [&] {
            return web.script("return !!document.querySelector(arguments[0])",
                              json::array({point})) == true;
        },
        10));
    const auto valueBefore = web.script("return app.bigram.poses.open[6][1]").get<double>();

    // Drag that point of `open` up; the grid marks the bigram changed, not saved.
    web.drag(point, 0, -24);
    ASSERT_TRUE(waitFor(
        [&] {
            return web.script(
                       "return document.querySelector(\"#grid button[data-pair='f-ah']\")"
                       ".classList.contains('edited') && !app.sending") == true;
        },
        10))
        << web.script(
               "return JSON.stringify({error: document.getElementById('error').textContent,"
               " open: app.bigram.poses.open, dragging: !!app.drag})");
    const auto valueAfter = web.script("return app.bigram.poses.open[6][1]").get<double>();
    EXPECT_GT(valueAfter, valueBefore + 0.1);
    const auto shots = screenshotDir(dir);
    std::filesystem::create_directories(shots);
    writeFile(shots / "editor-curves.png", web.screenshotPng());

    // Undo puts the base's curve back, redo the drag; a typed point the loader refuses is
    // refused with the loader's message and changes nothing.
    const auto pairState = [&] {
        return web.script(
            "return document.querySelector(\"#grid button[data-pair='f-ah']\")"
            ".classList.contains('edited') ? 'edited' : 'not edited'");
    };
    const auto settled = [&](const char* state, double value) {
        return waitFor(
            [&] {
                return pairState() == state && web.script("return app.sending") == false &&
                       web.script("return app.bigram.poses.open[6][1]") == value;
            },
            10);
    };
    web.click("#undo");
    EXPECT_TRUE(settled("not edited", valueBefore));
    web.click("#redo");
    EXPECT_TRUE(settled("edited", valueAfter));
    web.click(point);  // select it for numeric entry
    web.type("#point-time", "1.5");
    web.click("#point-set");
    EXPECT_TRUE(waitFor(
        [&] {
            return web.script("return document.getElementById('error').textContent")
                       .get<std::string>()
                       .find("bigrams.f-ah.open[6]: time must be in [0, 1]") != std::string::npos;
        },
        10));
    EXPECT_TRUE(settled("edited", valueAfter));

    // Type a sentence and preview it: the schedule, the curves, the audio, the mouth.
    web.type("#sentence", kSentence);
    web.click("#step-constraints");  // see the raised point (the README says why)
    web.click("#preview");
    ASSERT_TRUE(
        waitFor([&] { return web.script("return document.body.dataset.preview") == "ready"; }, 20))
        << web.script("return document.getElementById('error').textContent");
    EXPECT_TRUE(web.script("return document.querySelector(\"#grid button[data-pair='f-ah']\")"
                           ".classList.contains('used')") == true);
    EXPECT_TRUE(waitFor(
        [&] { return web.script("return document.getElementById('audio').duration > 0") == true; },
        10));
    // The cursor in the pair's second phoneme, where `open` peaks: the mouth is drawn open.
    const auto middle = web.script(
        "const s = app.preview.schedule.find((x, i, all) => x.phoneme === 'ah' && i > 0"
        " && all[i - 1].phoneme === 'f'); const audio = document.getElementById('audio');"
        " audio.pause(); audio.currentTime = (s.start + s.end) / 2; return audio.currentTime;");
    EXPECT_TRUE(waitFor(
        [&] {
            return web.script(
                       "return Number(document.getElementById('cursor').getAttribute('x1'))"
                       " === tlX(arguments[0])",
                       json::array({middle})) == true;
        },
        5));
    EXPECT_GT(web.script("return document.querySelectorAll('#mouth path').length").get<int>(), 2);
    writeFile(shots / "editor-preview.png", web.screenshotPng());

    // A recording with its words: picked in the page, sent as its bytes, aligned; it previews
    // the same way (schedule, curves, audio, the pairs it uses).
    const auto recording = dir / "what-fun.wav";
    ASSERT_EQ(
        runLipsync({"say", kSentence, "--voice", "en-us+f2", "--wav", recording.string()}).exitCode,
        0);
    web.script("document.body.dataset.preview = ''; app.used = new Set(); paintGrid();");
    web.type("#recording", recording.string());
    web.type("#words", kSentence);
    web.click("#preview-recording");
    ASSERT_TRUE(
        waitFor([&] { return web.script("return document.body.dataset.preview") == "ready"; }, 30))
        << web.script("return document.getElementById('error').textContent");
    EXPECT_EQ(web.script("return document.body.dataset.source"), "aligned");
    EXPECT_NE(web.script("return document.getElementById('status').textContent")
                  .get<std::string>()
                  .find("words aligned"),
              std::string::npos);
    EXPECT_TRUE(web.script("return document.querySelector(\"#grid button[data-pair='f-ah']\")"
                           ".classList.contains('used')") == true);
    EXPECT_TRUE(waitFor(
        [&] { return web.script("return document.getElementById('audio').duration > 0") == true; },
        10));

    // Save; the file holds its old bigram and the changed one, nothing else.
    web.click("#save");
    ASSERT_TRUE(waitFor(
        [&] {
            return web.script("return document.getElementById('status').textContent")
                .get<std::string>()
                .starts_with("saved");
        },
        10))
        << web.script("return document.getElementById('error').textContent");

    const auto was = json::parse(before), now = json::parse(slurp(character));
    EXPECT_EQ(now["base"], was["base"]);
    EXPECT_EQ(now["bigrams"].size(), 2u);
    EXPECT_EQ(now["bigrams"]["aa-bmp"], was["bigrams"]["aa-bmp"]);
    // f–ah is the base's f–ah with exactly one point of `open` moved.
    const auto base = json::parse(slurp(findDataFile("curves/english.json")))["bigrams"]["f-ah"];
    ASSERT_TRUE(now["bigrams"].contains("f-ah"));
    auto edited = now["bigrams"]["f-ah"];
    ASSERT_EQ(edited.size(), base.size());
    for (const auto& [pose, points] : base.items())
        if (pose != "open") {
            EXPECT_EQ(edited[pose], points) << pose;
        }
    ASSERT_EQ(edited["open"].size(), base["open"].size());
    for (std::size_t i = 0; i < base["open"].size(); ++i)
        if (i == 6) {
            EXPECT_NEAR(edited["open"][i][1].get<double>(), valueAfter, 1e-9);
            // Dragged straight up: the time moves by at most the pixel the pointer lands on.
            EXPECT_NEAR(edited["open"][i][0].get<double>(), base["open"][i][0].get<double>(),
                        0.005);
        } else {
            EXPECT_EQ(edited["open"][i], base["open"][i]) << i;
        }

    // `lipsync animate --character` on the sentence plays the change. Without constraints: the
    // shipped pose set's constraints on `open` (threshold 0.5) cap it at 0.5 even where the
    // other pose is 0, so a point raised above 0.5 shows only where no constraint applies.
    const auto schedule = (dir / "what-fun.tsv").string();
    ASSERT_EQ(runLipsync({"say", kSentence, "--schedule", schedule}).exitCode, 0);
    const auto plain = runLipsync({"animate", "--schedule", schedule, "--no-constraints",
                                   "--weights", (dir / "plain.csv").string()});
    const auto crab =
        runLipsync({"animate", "--schedule", schedule, "--no-constraints", "--character",
                    character.string(), "--weights", (dir / "crab.csv").string()});
    ASSERT_EQ(plain.exitCode, 0) << plain.err;
    ASSERT_EQ(crab.exitCode, 0) << crab.err;
    const auto a = openColumn(dir / "plain.csv"), b = openColumn(dir / "crab.csv");
    ASSERT_EQ(a.size(), b.size());
    double most = 0;
    for (std::size_t f = 0; f < a.size(); ++f) most = std::max(most, b[f] - a[f]);
    EXPECT_GT(most, 0.1) << "the raised point should open the mouth more in f-ah";
}

}  // namespace
}  // namespace lipsyncd::test
