// Curve sets, character files and pose sets as data: the shipped ones load and are reproducible;
// malformed ones are refused with the bigram, pose or line at fault.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "RuntimeTestSupport.hpp"

namespace lipsyncd::test {
namespace {

namespace fs = std::filesystem;

fs::path writeTemp(const std::string& name, const std::string& text) {
    const auto path =
        fs::temp_directory_path() / ("lipsyncd_" + std::to_string(::getpid()) + "_" + name);
    std::ofstream(path) << text;
    return path;
}

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string errorLoading(const std::string& json) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto path = writeTemp("curves.json", json);
    try {
        lipsync::BigramCurveSet::load(path, poses);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

const std::string kHead =
    R"({"format": "lipsyncd-curves", "version": 1, "name": "bad", "pose_set": "facefx", "bigrams": )";

TEST(CurveFiles, TheShippedSetCoversEveryPair) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::BigramCurveSet::named("english", poses);
    EXPECT_EQ(set.classes(), 22u);
    // Lips close fully for bmp; silence pairs bring the mouth to rest.
    const auto* close = set.curve(cls("aa"), cls("bmp"), *poses.find("pbm"));
    ASSERT_NE(close, nullptr);
    EXPECT_NEAR(close->at(0.75), 1.0, 0.01);
    EXPECT_EQ(set.curve(cls("sil"), cls("sil"), *poses.find("open")), nullptr);
}

TEST(CurveFiles, RegeneratingTheShippedSetGivesTheCommittedFile) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::generateCurveSet(findDataFile("curves/english-rules.toml"), poses);
    const auto out =
        fs::temp_directory_path() / ("lipsyncd_english_" + std::to_string(::getpid()) + ".json");
    set.save(out, poses, PhonemeSet::common());
    EXPECT_EQ(slurp(out), slurp(findDataFile("curves/english.json")))
        << "config/curves/english.json is stale: run scripts/make-curves.sh";
    const auto& mandarin = PhonemeSet::named("mandarin");
    const auto additions =
        lipsync::generateCurveSet(findDataFile("curves/mandarin-rules.toml"), poses, mandarin);
    additions.saveAdditions(out, "english", *mandarin.find("yu"), poses, mandarin);
    EXPECT_EQ(slurp(out), slurp(findDataFile("curves/mandarin.json")))
        << "config/curves/mandarin.json is stale: run scripts/make-curves.sh";
}

TEST(CurveFiles, MandarinAddsOneClassWithItsPairsOnTopOfEnglish) {
    // Paper 000, section 4.4: the common set plus one phoneme, and only that phoneme's pairs new.
    const auto& mandarin = PhonemeSet::named("mandarin");
    ASSERT_EQ(mandarin.size(), PhonemeSet::common().size() + 1);
    const auto yu = *mandarin.find("yu");
    EXPECT_EQ(mandarin[yu].group, "rounded");
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto set = lipsync::BigramCurveSet::named("mandarin", poses, mandarin);
    const auto english = lipsync::BigramCurveSet::named("english", poses);
    const auto w = *poses.find("w");
    ASSERT_NE(set.curve(*mandarin.find("d"), yu, w), nullptr);  // a new pair: ü rounds the lips
    EXPECT_GT(set.curve(*mandarin.find("d"), yu, w)->at(0.75), 0.7f);
    const auto* mine =
        set.curve(cls("ow"), cls("bmp"), *poses.find("pbm"));  // an English pair, reused
    const auto* theirs = english.curve(cls("ow"), cls("bmp"), *poses.find("pbm"));
    ASSERT_TRUE(mine && theirs);
    EXPECT_TRUE(std::equal(mine->polygon().begin(), mine->polygon().end(),
                           theirs->polygon().begin(), theirs->polygon().end()));
    // The additions file holds exactly the 2·23 − 1 = 45 pairs that involve ü.
    const auto text = slurp(findDataFile("curves/mandarin.json"));
    std::size_t pairs = 0;
    for (auto at = text.find("\n  \""); at != std::string::npos; at = text.find("\n  \"", at + 1)) {
        const auto key = text.substr(at + 4, text.find('"', at + 4) - at - 4);
        EXPECT_TRUE(key.rfind("yu-", 0) == 0 || key.ends_with("-yu")) << key;
        ++pairs;
    }
    EXPECT_EQ(pairs, 45u);
    // And pinyin maps onto it: ü and its finals to the new class, the rest to the common ones.
    const auto pinyin = PhonemeMap::named("pinyin");
    EXPECT_EQ(pinyin.phonemeSet(), "mandarin");
    EXPECT_EQ(pinyin.map("ü3")->phoneme, "yu");
    EXPECT_EQ(pinyin.map("ue")->phoneme, "yu");    // xue = x + ue
    EXPECT_EQ(pinyin.map("ang4")->phoneme, "aa");  // tones stripped
    EXPECT_EQ(pinyin.map("zh")->phoneme, "sh");
    EXPECT_FALSE(pinyin.map("qq").has_value());
}

TEST(CurveFiles, ErrorsNameTheBigramAndPose) {
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"chin": [[0,0],[1,0]]}}})")
                  .find("bigrams.aa-bmp.chin: unknown pose"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0,0],[0.6,0.2],[0.5,0.1],[1,0]]}}})")
                  .find("bigrams.aa-bmp.open[2]: times must increase"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0,0],[0.5,1.5],[1,0]]}}})")
                  .find("bigrams.aa-bmp.open[1]: value must be in [0, 1]"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-zz": {}}})").find("bigrams.aa-zz: not a pair"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {}}})").find("missing pair 'sil-sil'"),
              std::string::npos);
    EXPECT_NE(errorLoading(kHead + R"({"aa-bmp": {"open": [[0.1,0],[1,0]]}}})")
                  .find("from time 0 to time 1"),
              std::string::npos);
    EXPECT_NE(
        errorLoading(R"({"format": "lipsyncd-curves", "version": 2, "name": "x"})").find("version"),
        std::string::npos);
    EXPECT_NE(errorLoading("{").find("not valid JSON"), std::string::npos);
}

// The editor hands a client's bigram JSON straight to applyBigramsJson: every malformed shape is
// an InputError naming the source (the editor applies it to a scratch copy, so nothing is kept).
TEST(CurveFiles, MalformedBigramsFromAClientAreRefusedByName) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto& phonemes = PhonemeSet::common();
    auto set = lipsync::BigramCurveSet::named("english", poses, phonemes);
    for (const std::string bad :
         {R"({"f-ah": 3})", R"({"f-ah": {"open": "x"}})", R"({"f-ah": {"open": [["a", 1]]}})",
          R"({"f-ah": {"open": [[0, {}], [1, 0]]}})", R"({"f-ah": {"open": [[0], [1, 0]]}})",
          R"({"f-ah": {"open": [0, 1]}})", R"([1, 2])", R"({"f-ah": {"open": [[0, 1e600]]}})"}) {
        try {
            set.applyBigramsJson(bad, "PUT /api/bigrams/f/ah", poses, phonemes);
            ADD_FAILURE() << "accepted " << bad;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("PUT /api/bigrams/f/ah"), std::string::npos)
                << e.what();
        }
    }
}

TEST(CurveFiles, ACharacterReplacesSingleBigramsOnly) {
    const auto poses = lipsync::PoseSet::named("facefx");
    const auto base = lipsync::BigramCurveSet::named("english", poses);
    const auto path =
        writeTemp("crab.json", R"({"format": "lipsyncd-character", "version": 1, "name": "crab",
        "base": "english", "pose_set": "facefx",
        "bigrams": {"aa-bmp": {"w": [[0,0],[0.5,1],[1,0]]}}})");
    const auto crab = lipsync::BigramCurveSet::load(path, poses);
    EXPECT_EQ(crab.name(), "crab");
    const auto w = *poses.find("w"), pbm = *poses.find("pbm");
    ASSERT_NE(crab.curve(cls("aa"), cls("bmp"), w), nullptr);
    EXPECT_EQ(crab.curve(cls("aa"), cls("bmp"), pbm), nullptr);  // the override replaces the bigram
    // Every other bigram is the base's.
    const auto* mine = crab.curve(cls("ow"), cls("bmp"), pbm);
    const auto* theirs = base.curve(cls("ow"), cls("bmp"), pbm);
    ASSERT_TRUE(mine && theirs);
    EXPECT_TRUE(std::equal(mine->polygon().begin(), mine->polygon().end(),
                           theirs->polygon().begin(), theirs->polygon().end()));
}

TEST(PoseSetFiles, MistakesNameTheLine) {
    auto errorOf = [](const std::string& toml) {
        try {
            lipsync::PoseSet::load(writeTemp("poses.toml", toml));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\nspeed = 3\n").find(":4:"),
              std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\n[[pose]]\nname = \"open\"\n")
                  .find("defined twice"),
              std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\n[[constraint]]\nposes = [\"open\", "
                      "\"jaw\"]\nthreshold = 0.5\n")
                  .find("unknown pose 'jaw'"),
              std::string::npos);
    EXPECT_NE(errorOf("name = \"x\"\n[[pose]]\nname = \"open\"\nspeed_limit = -1\n")
                  .find("greater than 0"),
              std::string::npos);
}

}  // namespace
}  // namespace lipsyncd::test
