#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <lipsyncd/dsp.hpp>

using namespace lipsyncd;

namespace {
const auto& set() {
    return PhonemeSet::common();
}
int id(const std::string& name) {
    return static_cast<int>(*set().find(name));
}

// A model over the whole common set: uniform transitions, `minFrames` for every class.
dsp::TransitionModel uniformModel(int minFrames) {
    dsp::TransitionModel m;
    for (const auto& c : set().classes()) m.classes.push_back(c.name);
    const auto n = m.classes.size();
    m.minFrames.assign(n, minFrames);
    m.logProb.assign(n, std::vector<float>(n, std::log(1.0f / static_cast<float>(n - 1))));
    return m;
}

// Frames whose nearest class is the given one, 3 dB nearer than every other class.
struct Frame {
    dsp::FrameLabel label;
    std::vector<float> distances;
};
std::vector<Frame> frames(const std::vector<std::pair<std::string, int>>& runs) {
    std::vector<Frame> out;
    for (const auto& [name, count] : runs)
        for (int i = 0; i < count; ++i) {
            Frame f;
            f.label.time = 0.005 + 0.01 * static_cast<double>(out.size());
            f.label.phoneme = id(name);
            f.label.silent = name == "sil";
            f.distances.assign(set().size(), 7.0f);
            f.distances[static_cast<std::size_t>(id(name))] = 4.0f;
            out.push_back(f);
        }
    return out;
}

std::vector<std::string> decodeWith(const std::vector<Frame>& in, const dsp::DecoderConfig& config,
                                    int minFrames = 3) {
    dsp::ViterbiDecoder decoder(uniformModel(minFrames), set(), 0.01, config);
    std::vector<std::string> out;
    for (const auto& f : in)
        for (const auto& l : decoder.push(f.label, f.distances))
            out.push_back(set()[static_cast<std::size_t>(l.phoneme)].name);
    for (const auto& l : decoder.finish())
        out.push_back(set()[static_cast<std::size_t>(l.phoneme)].name);
    return out;
}

std::vector<std::string> decode(const std::vector<Frame>& in, double lag, int minFrames = 3) {
    dsp::DecoderConfig config;
    config.lagSeconds = lag;
    return decodeWith(in, config, minFrames);
}

std::vector<std::string> names(const std::vector<std::pair<std::string, int>>& runs) {
    std::vector<std::string> out;
    for (const auto& [name, count] : runs) out.insert(out.end(), count, name);
    return out;
}
}  // namespace

TEST(ViterbiDecoder, AFrameShorterThanTheMinimumDoesNotBecomeARun) {
    const auto in = frames({{"sil", 10}, {"aa", 8}, {"ih", 1}, {"aa", 8}, {"sil", 10}});
    EXPECT_EQ(decode(in, -1), names({{"sil", 10}, {"aa", 17}, {"sil", 10}}));
}

TEST(ViterbiDecoder, RunsAsLongAsTheMinimumSurvive) {
    const auto runs = std::vector<std::pair<std::string, int>>{
        {"sil", 10}, {"bmp", 4}, {"aa", 12}, {"z", 5}, {"sil", 10}};
    EXPECT_EQ(decode(frames(runs), -1), names(runs));
}

TEST(ViterbiDecoder, FixedLagDecidesEveryFrameOnceAndAgreesWithOfflineOnClearInput) {
    const auto runs = std::vector<std::pair<std::string, int>>{
        {"sil", 10}, {"h", 4}, {"eh", 9}, {"l", 4}, {"ow", 15}, {"sil", 10}};
    const auto in = frames(runs);
    for (double lag : {0.05, 0.1, 0.3}) {  // longer than the minimum runs
        const auto out = decode(in, lag);
        ASSERT_EQ(out.size(), in.size()) << "lag " << lag;
        EXPECT_EQ(out, decode(in, -1)) << "lag " << lag;
    }
    dsp::DecoderConfig config;
    config.lagSeconds = 0.12;
    dsp::ViterbiDecoder decoder(uniformModel(3), set(), 0.01, config);
    EXPECT_EQ(decoder.lagFrames(), 12);
    EXPECT_NEAR(decoder.delaySeconds(), 0.12, 1e-9);
    // Nothing comes out before the lag has passed, then one label per frame, in order.
    const auto in2 = frames({{"aa", 30}});
    for (std::size_t i = 0; i < in2.size(); ++i) {
        const auto out = decoder.push(in2[i].label, in2[i].distances);
        ASSERT_EQ(out.size(), i < 12 ? 0u : 1u) << "frame " << i;
        if (!out.empty()) {
            EXPECT_DOUBLE_EQ(out[0].time, in2[i - 12].label.time);
        }
    }
    EXPECT_EQ(decoder.finish().size(), 12u);
}

TEST(ViterbiDecoder, FramesTheEnergyGateCallsSilentDecodeAsSilence) {
    auto in = frames({{"aa", 10}, {"sil", 12}, {"aa", 10}});
    for (std::size_t i = 10; i < 22; ++i) {  // the classifier's best guess is a consonant
        in[i].distances.assign(set().size(), 5.0f);
        in[i].distances[static_cast<std::size_t>(id("z"))] = 4.0f;
    }
    EXPECT_EQ(decode(in, 0.1), names({{"aa", 10}, {"sil", 12}, {"aa", 10}}));
}

TEST(ViterbiDecoder, TheTransitionModelDecidesBetweenEquallyCloseClasses) {
    // After silence, 'aa' and 'ng'-like 'd' are equally close; the model says d never follows sil.
    auto model = uniformModel(2);
    const auto sil = static_cast<std::size_t>(id("sil")), d = static_cast<std::size_t>(id("d"));
    model.logProb[sil][d] = std::log(1e-6f);
    auto in = frames({{"sil", 5}, {"aa", 6}});
    for (std::size_t i = 5; i < 11; ++i) in[i].distances[d] = 4.0f;
    dsp::ViterbiDecoder decoder(model, set(), 0.01, {});
    std::vector<int> out;
    for (const auto& f : in)
        for (const auto& l : decoder.push(f.label, f.distances)) out.push_back(l.phoneme);
    for (const auto& l : decoder.finish()) out.push_back(l.phoneme);
    ASSERT_EQ(out.size(), in.size());
    for (std::size_t i = 5; i < out.size(); ++i) EXPECT_EQ(out[i], id("aa")) << "frame " << i;
}

TEST(TransitionModel, TheShippedModelLoadsAndCoversTheCommonSet) {
    const auto m = dsp::TransitionModel::loadDefault();
    EXPECT_EQ(m.classes.size(), set().size());
    for (std::size_t i = 0; i < m.classes.size(); ++i) {
        double total = 0;
        for (std::size_t k = 0; k < m.classes.size(); ++k)
            if (k != i) total += std::exp(m.logProb[i][k]);
        EXPECT_NEAR(total, 1.0, 1e-3) << m.classes[i];
    }
}

TEST(TransitionModel, BadFilesAreRefusedNamingTheField) {
    const auto path = std::filesystem::temp_directory_path() / "lipsyncd_test_transitions.json";
    auto errorOf = [&](const std::string& text) -> std::string {
        std::ofstream(path) << text;
        try {
            dsp::TransitionModel::load(path);
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    const std::string head = R"({"format": "lipsyncd-transitions", "version": 1, )";
    EXPECT_NE(errorOf(head + R"("classes": ["sil", "aa"], "min_frames": [1, 2], )"
                             R"("log_prob": [[0, -0.1], [-0.1]]})")
                  .find("log_prob[1] has 1 values, expected 2"),
              std::string::npos);
    EXPECT_NE(errorOf(head + R"("classes": ["sil", "xx"], "min_frames": [1, 2], )"
                             R"("log_prob": [[0, 0], [0, 0]]})")
                  .find("'xx' is not a class"),
              std::string::npos);
    EXPECT_NE(errorOf(head + R"("classes": ["sil", "aa"], "min_frames": [1, 0], )"
                             R"("log_prob": [[0, 0], [0, 0]]})")
                  .find("min_frames[1] = 0"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"format": "other", "version": 1})").find("format"), std::string::npos);
    std::filesystem::remove(path);
}

TEST(ViterbiDecoder, AFrameShowsTheVisualGroupItsClassesTogetherFavour) {
    // The rounded 'ao' is nearest, but two open vowels lie just behind it: together the open
    // group is likelier, and the mouth should open.
    auto in = frames({{"sil", 5}, {"ao", 12}, {"sil", 5}});
    for (std::size_t i = 5; i < 17; ++i) {
        in[i].distances.assign(set().size(), 9.0f);
        in[i].distances[static_cast<std::size_t>(id("ao"))] = 4.0f;
        in[i].distances[static_cast<std::size_t>(id("aa"))] = 4.2f;
        in[i].distances[static_cast<std::size_t>(id("ah"))] = 4.4f;
    }
    const auto run = [&](float groupShare) {
        dsp::DecoderConfig config;
        config.groupShare = groupShare;
        return decodeWith(in, config);
    };
    EXPECT_EQ(run(dsp::DecoderConfig{}.groupShare), names({{"sil", 5}, {"aa", 12}, {"sil", 5}}));
    EXPECT_EQ(run(0), names({{"sil", 5}, {"ao", 12}, {"sil", 5}}));  // the nearest class alone
}

TEST(ViterbiDecoder, AGroupSpreadOfZeroIsRefused) {
    dsp::DecoderConfig config;
    config.groupSpreadDb = 0;
    EXPECT_THROW(dsp::ViterbiDecoder(uniformModel(3), set(), 0.01, config), InputError);
}
