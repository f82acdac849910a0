// The editor's HTTP API, called as the server calls it: the token guards every call, bad
// bigram names and bad curves get a clear 4xx naming what is wrong, and nothing is written
// then; a save writes exactly the character's bigrams, and `animate` plays them.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <lipsyncd/editor.hpp>
#include <nlohmann/json.hpp>

#include "../../editor/src/SpeechPreview.hpp"  // wavDataUri, encodeBase64, decodeBase64
#include "../cli/RunLipsync.hpp"

namespace lipsyncd::editor {
namespace {
using nlohmann::json;
using test::scratchDir;
using test::slurp;

EspeakSynthesizer& speech() {
    static EspeakSynthesizer synth;  // espeak-ng starts once per process
    return synth;
}

struct Editor {
    std::filesystem::path character;
    std::unique_ptr<EditorApi> api;

    explicit Editor(const std::filesystem::path& file, const PreviewSettings& settings = {})
        : character(file) {
        auto poses = lipsync::PoseSet::named("facefx");
        auto mouth = MouthDrawing::load(findDataFile("editor/mouth.toml"), poses);
        CharacterDraft draft(std::move(poses), PhonemeSet::common(), "english", file);
        api = std::make_unique<EditorApi>(std::move(draft), std::move(mouth), "secret", speech(),
                                          settings);
    }
    ApiResponse call(const std::string& method, const std::string& path,
                     const std::string& body = "", const std::string& token = "secret") {
        return api->handle({method, path, token, body});
    }
};

json body(const ApiResponse& r) {
    return json::parse(r.body);
}
std::string errorOf(const ApiResponse& r) {
    return body(r).value("error", "");
}

const std::string kOpenPut = R"({"poses": {"open": [[0, 0], [0.4, 0.9], [1, 0]]}})";

TEST(EditorApi, EveryCallNeedsTheTokenAndAWrongOneWritesNothing) {
    const auto dir = scratchDir("editor_token");
    Editor e(dir / "crab.json");
    for (const auto& token : {std::string(), std::string("secreT"), std::string("secret2")}) {
        EXPECT_EQ(e.call("GET", "/api/bigrams", "", token).status, 401);
        const auto put = e.call("PUT", "/api/bigrams/f/ah", kOpenPut, token);
        EXPECT_EQ(put.status, 401);
        EXPECT_NE(errorOf(put).find("token"), std::string::npos) << put.body;
        EXPECT_EQ(e.call("POST", "/api/save", "{}", token).status, 401);
    }
    EXPECT_FALSE(std::filesystem::exists(e.character));
    EXPECT_EQ(body(e.call("GET", "/api/bigrams/f/ah"))["state"], "generated");
}

TEST(EditorApi, BadBigramNamesAre404NamingTheClass) {
    const auto dir = scratchDir("editor_names");
    Editor e(dir / "crab.json");
    for (const auto& path : {"/api/bigrams/f/zz", "/api/bigrams/zz/ah", "/api/bigrams/..%2f/ah"}) {
        const auto r = e.call("PUT", path, kOpenPut);
        EXPECT_EQ(r.status, 404) << path;
        EXPECT_NE(errorOf(r).find("no phoneme class"), std::string::npos) << r.body;
    }
    EXPECT_EQ(e.call("GET", "/api/bigrams/f").status, 404);
    EXPECT_EQ(e.call("GET", "/api/bigrams/f/ah/open").status, 404);
    EXPECT_EQ(e.call("DELETE", "/api/bigrams/f/ah").status, 405);
    EXPECT_EQ(body(e.call("GET", "/api/bigrams"))["unsaved"], 0);
}

TEST(EditorApi, OutOfRangeAndNonMonotonicPointsAre422NamingThePointAndChangeNothing) {
    const auto dir = scratchDir("editor_points");
    Editor e(dir / "crab.json");
    const auto before = e.call("GET", "/api/bigrams/f/ah").body;
    struct Case {
        std::string put, message;
    };
    const std::vector<Case> cases{
        {R"({"poses": {"open": [[0, 0], [0.5, 1.5], [1, 0]]}})",
         "bigrams.f-ah.open[1]: value must be in [0, 1]"},
        {R"({"poses": {"open": [[0, 0], [1.2, 0.5], [1, 0]]}})",
         "bigrams.f-ah.open[1]: time must be in [0, 1]"},
        {R"({"poses": {"open": [[0, 0], [0.6, 0.5], [0.5, 1], [1, 0]]}})",
         "bigrams.f-ah.open[2]: times must increase"},
        {R"({"poses": {"open": [[0, 0], [0.5, 0.5]]}})", "must run from time 0 to time 1"},
        {R"({"poses": {"open": [[0, 0], [0.5, 0.5], [0.5004, 0.5], [1, 0]]}})",
         "closer than 0.001 in time"},
        {R"({"poses": {"no_such_pose": [[0, 0], [1, 0]]}})", "unknown pose"},
    };
    for (const auto& c : cases) {
        const auto r = e.call("PUT", "/api/bigrams/f/ah", c.put);
        EXPECT_EQ(r.status, 422) << c.put;
        EXPECT_NE(errorOf(r).find(c.message), std::string::npos) << r.body;
        EXPECT_NE(errorOf(r).find("PUT /api/bigrams/f/ah"), std::string::npos) << r.body;
    }
    for (const auto& malformed : {"", "[1, 2]", "{\"poses\": 3}", "{\"curves\": {}}", "{oops"})
        EXPECT_EQ(e.call("PUT", "/api/bigrams/f/ah", malformed).status, 400) << malformed;
    EXPECT_EQ(e.call("GET", "/api/bigrams/f/ah").body, before);
    EXPECT_EQ(e.call("POST", "/api/save", "{}").status, 200);
    EXPECT_EQ(body(e.call("GET", "/api/bigrams"))["unsaved"], 0);
    EXPECT_EQ(json::parse(slurp(e.character))["bigrams"].size(), 0u);
}

TEST(EditorApi, TheBigramListHasEveryPairAndThePoseSetsPoses) {
    const auto dir = scratchDir("editor_list");
    Editor e(dir / "crab.json");
    const auto list = body(e.call("GET", "/api/bigrams"));
    const auto& phonemes = PhonemeSet::common();
    EXPECT_EQ(list["bigrams"].size(), phonemes.size() * phonemes.size());
    EXPECT_EQ(list["poses"].get<std::vector<std::string>>(),
              lipsync::PoseSet::named("facefx").names());
    const auto bigram = body(e.call("GET", "/api/bigrams/f/ah"));
    for (const auto& pose : list["poses"]) {
        EXPECT_TRUE(bigram["poses"].contains(pose)) << pose;
        EXPECT_TRUE(bigram["curves"].contains(pose)) << pose;
    }
}

TEST(EditorApi, SaveWritesOnlyTheCharactersBigramsAsAFileThatLoads) {
    const auto dir = scratchDir("editor_save");
    const auto file = dir / "crab.json";
    {
        std::ofstream out(file);
        out << R"({"format": "lipsyncd-character", "version": 1, "name": "crab",
                   "base": "english", "pose_set": "facefx",
                   "bigrams": {"aa-bmp": {"w": [[0, 0], [0.5, 1], [1, 0]]}}})";
    }
    Editor e(file);
    EXPECT_EQ(body(e.call("GET", "/api/bigrams/aa/bmp"))["state"], "character");
    const auto put = e.call("PUT", "/api/bigrams/f/ah", kOpenPut);
    ASSERT_EQ(put.status, 200) << put.body;
    EXPECT_EQ(body(put)["state"], "edited");
    EXPECT_EQ(body(put)["poses"]["open"], json::parse("[[0, 0], [0.4, 0.9], [1, 0]]"));
    const auto saved = e.call("POST", "/api/save", "{}");
    ASSERT_EQ(saved.status, 200) << saved.body;
    EXPECT_EQ(body(saved)["saved"], 2);

    const auto written = json::parse(slurp(file));
    EXPECT_EQ(written["base"], "english");
    EXPECT_EQ(written["bigrams"].size(), 2u);
    EXPECT_EQ(written["bigrams"]["aa-bmp"], json::parse(R"({"w": [[0, 0], [0.5, 1], [1, 0]]})"));
    EXPECT_EQ(written["bigrams"]["f-ah"], json::parse(R"({"open": [[0, 0], [0.4, 0.9], [1, 0]]})"));
    EXPECT_FALSE(std::filesystem::exists(dir / "crab.json.saving"));
    EXPECT_EQ(body(e.call("GET", "/api/bigrams/f/ah"))["state"], "character");

    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::BigramCurveSet::load(file, poses);
    const auto& common = PhonemeSet::common();
    const auto* open = set.curve(*common.find("f"), *common.find("ah"), *poses.find("open"));
    ASSERT_NE(open, nullptr);
    EXPECT_EQ(open->polygon().size(), 3u);
}

TEST(EditorApi, WithoutACharacterFileSavingIsRefused) {
    auto poses = lipsync::PoseSet::named("facefx");
    auto mouth = MouthDrawing::load(findDataFile("editor/mouth.toml"), poses);
    EditorApi api(CharacterDraft(std::move(poses), PhonemeSet::common(), "english", ""),
                  std::move(mouth), "t", speech());
    const auto r = api.handle({"POST", "/api/save", "t", "{}"});
    EXPECT_EQ(r.status, 409);
    EXPECT_NE(r.body.find("--character"), std::string::npos);
}

TEST(EditorApi, PreviewSpeaksTheSentenceWithItsScheduleWeightsAndAudio) {
    const auto dir = scratchDir("editor_preview");
    Editor e(dir / "crab.json");
    const auto r = e.call("POST", "/api/preview", R"({"text": "What fun"})");
    ASSERT_EQ(r.status, 200) << r.body;
    const auto p = body(r);
    EXPECT_GE(p["schedule"].size(), 4u);
    const auto pairs = p["pairs"].get<std::vector<std::string>>();
    EXPECT_NE(std::find(pairs.begin(), pairs.end(), "f-ah"), pairs.end());
    const auto poseCount = lipsync::PoseSet::named("facefx").size();
    EXPECT_EQ(p["weights"]["values"].size(), poseCount);
    const auto frames = p["weights"]["times"].size();
    EXPECT_GT(frames, 20u);
    for (const auto& row : p["weights"]["values"]) EXPECT_EQ(row.size(), frames);
    EXPECT_TRUE(p["audio"].get<std::string>().starts_with("data:audio/wav;base64,UklGR"));
    EXPECT_GT(p["duration"].get<double>(), 0.3);
}

double mostOpen(const json& preview) {
    const auto poses = preview["weights"]["poses"].get<std::vector<std::string>>();
    const auto at = std::find(poses.begin(), poses.end(), "open") - poses.begin();
    double most = 0;
    for (const auto& v : preview["weights"]["values"][at]) most = std::max(most, v.get<double>());
    return most;
}

TEST(EditorApi, PreviewPlaysTheUnsavedCurves) {
    const auto dir = scratchDir("editor_preview_edit");
    Editor e(dir / "crab.json");
    const std::string say = R"({"text": "What fun", "constraints": false})";
    const auto before = mostOpen(body(e.call("POST", "/api/preview", say)));
    auto curves = body(e.call("GET", "/api/bigrams/f/ah"))["poses"];
    for (auto& point : curves["open"])
        if (point[0] > 0.6 && point[0] < 0.8) point[1] = 1.0;
    ASSERT_EQ(e.call("PUT", "/api/bigrams/f/ah", json{{"poses", curves}}.dump()).status, 200);
    const auto after = mostOpen(body(e.call("POST", "/api/preview", say)));
    EXPECT_GT(after, before + 0.15);
    EXPECT_FALSE(std::filesystem::exists(e.character));
}

TEST(EditorApi, PreviewRejectsWhatItCannotDoClearly) {
    const auto dir = scratchDir("editor_preview_bad");
    Editor e(dir / "crab.json");
    EXPECT_EQ(e.call("POST", "/api/preview", R"({"text": ""})").status, 400);
    EXPECT_EQ(e.call("POST", "/api/preview", R"({"text": "hi", "voice": "../../x"})").status, 400);
    EXPECT_EQ(e.call("POST", "/api/preview", R"({"text": "hi", "voice": "zz-nope"})").status, 422);
    EXPECT_EQ(e.call("POST", "/api/preview", R"({"text": "hi", "constraints": "no"})").status, 400);
    EXPECT_EQ(e.call("GET", "/api/preview").status, 405);
}

// A recording as the page sends it: the file's bytes in a data: URI, made here from speech.
struct Recording {
    std::string wav;  // the file's bytes
    double seconds = 0;
};
Recording recordingOf(const std::string& text) {
    const auto spoken = speech().synthesize({text, "en-us"});
    const auto uri = wavDataUri(spoken.samples, spoken.sampleRate);
    return {*decodeBase64(uri), static_cast<double>(spoken.samples.size()) / spoken.sampleRate};
}
std::string uploadOf(const std::string& bytes) {
    return "data:audio/wav;base64," + encodeBase64(bytes);
}

std::vector<std::string> phonemesOf(const json& preview) {
    std::vector<std::string> out;
    for (const auto& s : preview["schedule"]) out.push_back(s["phoneme"]);
    return out;
}
bool has(const std::vector<std::string>& list, const std::string& item) {
    return std::find(list.begin(), list.end(), item) != list.end();
}

TEST(EditorApi, ARecordingWithItsWordsIsAlignedAndAnimatedLikeTypedText) {
    const auto dir = scratchDir("editor_recording");
    Editor e(dir / "crab.json");
    const auto rec = recordingOf("Fine fast father");
    const auto r = e.call("POST", "/api/preview",
                          json{{"wav", uploadOf(rec.wav)}, {"text", "Fine fast father"}}.dump());
    ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
    const auto p = body(r);
    EXPECT_EQ(p["source"], "aligned") << p["warnings"];
    ASSERT_EQ(p["words"].size(), 3u);
    for (const auto& w : p["words"]) EXPECT_TRUE(w["placed"].get<bool>()) << w;
    EXPECT_LT(p["words"][0]["start"].get<double>(), p["words"][2]["start"].get<double>());
    // The words' phonemes in the common set's classes (fine: f ay d; fast: f ah z d; father:
    // f aa th er).
    const auto phonemes = phonemesOf(p);
    for (const auto* ph : {"f", "ay", "d", "z", "aa", "th"}) EXPECT_TRUE(has(phonemes, ph)) << ph;
    EXPECT_EQ(std::count(phonemes.begin(), phonemes.end(), "f"), 3) << json(phonemes);
    const auto pairs = p["pairs"].get<std::vector<std::string>>();
    EXPECT_TRUE(has(pairs, "f-ay"));
    EXPECT_NEAR(p["duration"].get<double>(), rec.seconds, 1e-3);
    EXPECT_TRUE(p["audio"].get<std::string>().starts_with("data:audio/wav;base64,UklGR"));
    const auto frames = p["weights"]["times"].size();
    EXPECT_NEAR(static_cast<double>(frames), rec.seconds * 100, 10);
    for (const auto& row : p["weights"]["values"]) EXPECT_EQ(row.size(), frames);
    EXPECT_GT(mostOpen(p), 0.2) << "the mouth opens for the vowels";
}

TEST(EditorApi, ARecordingWithoutWordsIsAnalysedFromTheAudioAndSaysSo) {
    const auto dir = scratchDir("editor_recording_plain");
    Editor e(dir / "crab.json");
    const auto rec = recordingOf("Fine fast father");
    const auto r = e.call("POST", "/api/preview", json{{"wav", uploadOf(rec.wav)}}.dump());
    ASSERT_EQ(r.status, 200) << r.body.substr(0, 400);
    const auto p = body(r);
    EXPECT_EQ(p["source"], "audio-only");
    EXPECT_FALSE(p.contains("words"));
    ASSERT_EQ(p["warnings"].size(), 1u);
    EXPECT_NE(p["warnings"][0].get<std::string>().find("no words given"), std::string::npos);
    EXPECT_GE(p["schedule"].size(), 5u);
    // Words the voice cannot read: the aligner is not used, and the reply says why.
    const auto odd = body(
        e.call("POST", "/api/preview", json{{"wav", uploadOf(rec.wav)}, {"text", "  "}}.dump()));
    EXPECT_EQ(odd["source"], "audio-only");
}

TEST(EditorApi, ABadRecordingIsAClear400AndNoPathIsEverOpened) {
    const auto dir = scratchDir("editor_recording_bad");
    Editor e(dir / "crab.json");
    const auto rec = recordingOf("Fine fast father");
    struct Case {
        json wav;
        std::string message;
    };
    const std::vector<Case> cases{
        {uploadOf(rec.wav.substr(0, rec.wav.size() / 2)), "wav: truncated: its RIFF header"},
        {uploadOf(rec.wav.substr(0, 30)), "wav: truncated"},
        {uploadOf("not audio at all, just some words"), "cannot decode audio"},
        {"/etc/passwd", "cannot decode audio"},  // base64 digits, 8 bytes of nonsense
        {"data:audio/wav;base64,%%%%", "wav: not base64"},
        {"data:audio/wav,RIFF", "wav: not base64"},
        {"", "wav: empty"},
        {42, "not a path"},
    };
    for (const auto& c : cases) {
        const auto r = e.call("POST", "/api/preview", json{{"wav", c.wav}}.dump());
        EXPECT_EQ(r.status, 400) << c.wav.dump().substr(0, 80) << " -> " << r.body;
        EXPECT_NE(errorOf(r).find(c.message), std::string::npos) << r.body;
        EXPECT_EQ(errorOf(r).find("/proc/"), std::string::npos) << r.body;
    }
    EXPECT_EQ(
        e.call("POST", "/api/preview", json{{"wav", uploadOf(rec.wav)}, {"text", 3}}.dump()).status,
        400);
}

TEST(EditorApi, ARecordingOverTheLimitsIs413) {
    const auto dir = scratchDir("editor_recording_big");
    const auto rec = recordingOf("Fine fast father");
    PreviewSettings small;
    small.maxUploadBytes = rec.wav.size() / 2;
    Editor bytes(dir / "crab.json", small);
    const auto r = bytes.call("POST", "/api/preview", json{{"wav", uploadOf(rec.wav)}}.dump());
    EXPECT_EQ(r.status, 413);
    EXPECT_NE(errorOf(r).find("wav: more than"), std::string::npos) << r.body;
    PreviewSettings brief;
    brief.maxRecordingSeconds = rec.seconds / 2;
    Editor seconds(dir / "crab.json", brief);
    const auto s = seconds.call("POST", "/api/preview", json{{"wav", uploadOf(rec.wav)}}.dump());
    EXPECT_EQ(s.status, 413);
    EXPECT_NE(errorOf(s).find("the editor previews at most"), std::string::npos) << s.body;
}

TEST(EditorApi, PerformingNeedsAPuppet) {
    const auto dir = scratchDir("editor_perform");
    Editor e(dir / "crab.json");
    const auto r = e.call("POST", "/api/perform", R"({"from": 0})");
    EXPECT_EQ(r.status, 409);
    EXPECT_NE(errorOf(r).find("--socket"), std::string::npos) << r.body;
    EXPECT_TRUE(body(e.call("GET", "/api/bigrams"))["puppet"].is_null());
}

TEST(EditorApi, Base64RoundTripsAndRefusesWhatIsNot) {
    for (const auto& bytes :
         std::vector<std::string>{"", "a", "ab", "abc", "abcd", std::string("\0\xff\x10", 3)})
        EXPECT_EQ(decodeBase64(encodeBase64(bytes)), bytes) << bytes;
    EXPECT_FALSE(decodeBase64("a"));
    EXPECT_FALSE(decodeBase64("ab c"));
    EXPECT_FALSE(decodeBase64("data:text/plain,abcd"));
}

TEST(EditorApi, TokensAreRandomAndLong) {
    const auto a = randomToken(), b = randomToken();
    EXPECT_EQ(a.size(), 32u);
    EXPECT_NE(a, b);
}

}  // namespace
}  // namespace lipsyncd::editor
