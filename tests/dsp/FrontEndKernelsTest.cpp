// The front end's fast kernels (autocorrelation, Levinson–Durbin, LPC spectrum, nearest
// templates) against plain double-precision computations written straight from the formulas
// (Lewis, "linear prediction speech model"; Makhoul 1975): speed work must not change what the
// analysis says. bench/compare-analysis.sh checks the whole program byte for byte against an
// older build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "../../dsp/src/ClassEntry.hpp"
#include "TestSpeech.hpp"

using namespace lipsyncd;

namespace {
// The shipped templates without their class network: the kernels' search alone is checked.
const dsp::TemplateSet& templates() {
    static const auto t = [] {
        auto set = dsp::TemplateSet::loadDefault();
        set.classNetwork.reset();  // the templates' distances alone: neither the network's term
        set.classBiasDb.clear();   // nor the class bias
        return set;
    }();
    return t;
}

// Speech at the analysis rate in three levels (quiet speech has the least numerical headroom),
// with a little noise so that no frame is exactly silent.
std::vector<std::vector<float>> speechAtAnalysisRate() {
    const auto& s = test::testSpeech();
    const auto speech = test::resampleOffline(s.samples, s.rate, templates().analysis.analysisRate);
    std::vector<std::vector<float>> out;
    for (float gain : {1.0f, 0.1f, 0.003f}) {
        std::vector<float> v(speech.size());
        std::uint32_t seed = 7;
        for (std::size_t i = 0; i < v.size(); ++i) {
            seed = seed * 1664525u + 1013904223u;
            v[i] = gain * speech[i] + 1e-5f * (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f);
        }
        out.push_back(std::move(v));
    }
    return out;
}

// Every frame of `audio` the way FrameStream cuts them (hop by hop from the start).
std::vector<std::span<const float>> framesOf(const std::vector<float>& audio,
                                             const dsp::AnalysisConfig& c) {
    std::vector<std::span<const float>> out;
    const auto window = static_cast<std::size_t>(c.windowSamples());
    for (std::size_t at = 0; at + window <= audio.size(); at += c.hopSamples())
        out.push_back(std::span<const float>(audio).subspan(at, window));
    return out;
}

struct ReferenceFrame {
    double energyDb = -120, normalizedError = 1;
    bool valid = false;
    std::vector<double> spectrum;
};

// One frame from the formulas, in double precision.
ReferenceFrame referenceAnalysis(std::span<const float> x, const dsp::AnalysisConfig& c) {
    ReferenceFrame out;
    const std::size_t n = x.size();
    double energy = 0;
    for (float v : x) energy += static_cast<double>(v) * v;
    const double rms = std::sqrt(energy / static_cast<double>(n));
    out.energyDb = rms > 0 ? std::max(20 * std::log10(rms), -120.0) : -120.0;
    std::vector<double> y(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double hamming =
            0.54 - 0.46 * std::cos(2 * std::numbers::pi * static_cast<double>(i) /
                                   static_cast<double>(n - 1));
        y[i] = (x[i] - c.preEmphasis * x[i > 0 ? i - 1 : 0]) * hamming;
    }
    const int p = c.order;
    std::vector<double> r(static_cast<std::size_t>(p) + 1);
    for (int k = 0; k <= p; ++k) {
        for (std::size_t i = static_cast<std::size_t>(k); i < n; ++i) r[k] += y[i] * y[i - k];
        const double w = 2 * std::numbers::pi * c.lagWindowHz * k / c.analysisRate;
        r[k] *= std::exp(-0.5 * w * w);
    }
    r[0] = r[0] * (1 + c.whiteNoiseCorrection) + 1e-9;
    // Levinson–Durbin (Makhoul 1975, eqs. 38a–38e).
    std::vector<double> a(static_cast<std::size_t>(p) + 1, 0.0), previous;
    a[0] = 1;
    double error = r[0];
    for (int i = 1; i <= p; ++i) {
        double acc = r[i];
        for (int j = 1; j < i; ++j) acc += a[j] * r[i - j];
        const double k = -acc / error;
        if (!(std::abs(k) < 1)) return out;  // unstable: not valid
        previous = a;
        for (int j = 1; j < i; ++j) a[j] = previous[j] + k * previous[i - j];
        a[i] = k;
        error *= 1 - k * k;
    }
    out.normalizedError = error / r[0];
    out.valid = out.energyDb > -100;
    for (int m = 0; m < c.spectrumBins; ++m) {
        const double w = std::numbers::pi * m / c.spectrumBins;
        double re = 0, im = 0;
        for (int i = 0; i <= p; ++i) re += a[i] * std::cos(w * i), im -= a[i] * std::sin(w * i);
        out.spectrum.push_back(-10 * std::log10(std::max(re * re + im * im, 1e-10)));
    }
    return out;
}
}  // namespace

TEST(FrontEndKernels, FrameFeaturesMatchAPlainDoublePrecisionAnalysis) {
    // The LPC analysis alone: a set's running mean spectrum (channel normalisation) is
    // SpectrumNormaliser's, tested on its own.
    auto c = templates().analysis;
    c.spectrumMean.clear();
    std::size_t compared = 0;
    double worst = 0;
    for (const auto& audio : speechAtAnalysisRate()) {
        dsp::FrameAnalyzer analyzer(c);
        auto features = analyzer.makeFeatures();
        for (const auto frame : framesOf(audio, c)) {
            analyzer.analyze(frame, features);
            const auto ref = referenceAnalysis(frame, c);
            ASSERT_NEAR(features.energyDb, ref.energyDb, 1e-3);
            ASSERT_EQ(features.valid, ref.valid) << "at " << compared;
            if (!ref.valid) continue;
            ASSERT_NEAR(features.normalizedError, ref.normalizedError,
                        1e-4 + 1e-3 * ref.normalizedError);
            for (int m = 0; m < c.spectrumBins; ++m)
                worst = std::max(worst, std::abs(features.spectrum[m] - ref.spectrum[m]));
            if (c.errorFeature) {
                ASSERT_NEAR(features.spectrum[c.spectrumBins],
                            std::max(-40.0, 10 * std::log10(ref.normalizedError)), 0.01);
            }
            ++compared;
        }
    }
    EXPECT_GT(compared, 300u);
    // Float against double: peaky vowel spectra amplify rounding in the recursion (0.026 dB at
    // worst when this test was written); templates are stored to a thousandth of a dB and
    // classes lie dB apart.
    EXPECT_LT(worst, 0.05);
}

namespace {
// Classifies speech with `t` and checks every frame's class distances and label against a plain
// nearest-template search in double precision; returns the number of frames compared.
std::size_t checkDistancesAndLabels(const dsp::TemplateSet& t) {
    const auto& set = PhonemeSet::common();
    const auto features = t.binWeights.size();
    std::size_t compared = 0;
    for (const auto& audio : speechAtAnalysisRate()) {
        dsp::FrameAnalyzer analyzer(t.analysis);
        dsp::FrameClassifier classifier(t, set);
        auto f = analyzer.makeFeatures();
        for (const auto frame : framesOf(audio, t.analysis)) {
            analyzer.analyze(frame, f);
            const auto label = classifier.classify(f);
            if (!f.valid) continue;
            // Weighted RMS distance in dB to each class's nearest template.
            std::vector<double> expected(set.size(), std::numeric_limits<double>::infinity());
            for (const auto& cls : t.classes) {
                double& best = expected[*set.find(cls.phoneme)];
                for (const auto& spectrum : cls.spectra) {
                    double sum = 0;
                    for (std::size_t b = 0; b < features; ++b) {
                        const double d = f.spectrum[b] - spectrum[b];
                        sum += t.binWeights[b] * d * d;
                    }
                    best = std::min(best, std::sqrt(sum / static_cast<double>(features)));
                }
            }
            const auto distances = classifier.distances();
            EXPECT_EQ(distances.size(), expected.size());
            std::vector<std::pair<double, int>> order;
            for (std::size_t k = 0; k < expected.size(); ++k) {
                if (std::isinf(expected[k])) {
                    EXPECT_TRUE(std::isinf(distances[k])) << "class " << k;
                    continue;
                }
                EXPECT_NEAR(distances[k], expected[k], 1e-4 * expected[k] + 1e-5) << "class " << k;
                order.emplace_back(expected[k], static_cast<int>(k));
            }
            std::sort(order.begin(), order.end());
            // The label is the nearest class (unless the gate called the frame silent) wherever
            // the runner-up is not within rounding of it.
            if (!label.silent && order.size() > 1 && order[1].first - order[0].first > 1e-3) {
                EXPECT_EQ(label.phoneme, order[0].second) << "at " << label.time;
            }
            ++compared;
        }
    }
    return compared;
}
}  // namespace

TEST(FrontEndKernels, ClassDistancesAndLabelsMatchAPlainNearestTemplateSearch) {
    EXPECT_GT(checkDistancesAndLabels(templates()), 300u);
}

TEST(FrontEndKernels, ClassesOfAnySizeAndFeatureCountsOfAnyLengthAreSearchedCompletely) {
    // Templates are matched eight at a time and features eight at a time: classes of 1..11
    // templates (padded blocks) and the spectrum alone (no extra features) must come out the
    // same as the plain search, and a class left without templates stays out of reach.
    auto t = templates();
    for (std::size_t i = 0; i < t.classes.size(); ++i)
        t.classes[i].spectra.resize(std::min(t.classes[i].spectra.size(), i % 11 + 1));
    t.classes.erase(t.classes.begin() + 3);
    EXPECT_GT(checkDistancesAndLabels(t), 300u);
    t.analysis.errorFeature = t.analysis.levelFeature = false;
    const auto bins = static_cast<std::size_t>(t.analysis.spectrumBins);
    t.binWeights.resize(bins);
    for (auto& c : t.classes)
        for (auto& s : c.spectra) s.resize(bins);
    EXPECT_GT(checkDistancesAndLabels(t), 300u);
}

TEST(FrontEndKernels, TheBestEntryIntoEachClassIsTheFirstCheapestAsInAPlainLoop) {
    // dsp::bestEntries against the loop it replaces in ViterbiDecoder::step, with many ties
    // (costs on a coarse grid) and scores at the unreachable cap.
    constexpr float kUnreachable = 1e9f;
    std::uint32_t seed = 3;
    auto next = [&](int range) {
        seed = seed * 1664525u + 1013904223u;
        return static_cast<int>((seed >> 8) % static_cast<std::uint32_t>(range));
    };
    for (std::size_t classes : {1u, 7u, 8u, 9u, 22u, 40u}) {
        const std::size_t stride = (classes + 7) / 8 * 8;
        for (int trial = 0; trial < 50; ++trial) {
            std::vector<float> exitScore(stride, kUnreachable),
                transition(classes * stride, kUnreachable);
            for (std::size_t j = 0; j < classes; ++j)
                exitScore[j] = next(4) == 0 ? kUnreachable : static_cast<float>(next(8));
            for (std::size_t j = 0; j < classes; ++j)
                for (std::size_t to = 0; to < classes; ++to)
                    if (j != to) transition[j * stride + to] = 0.5f * static_cast<float>(next(6));
            std::vector<float> enter(stride);
            std::vector<int> from(stride);
            dsp::bestEntries(exitScore.data(), transition.data(), classes, stride, kUnreachable,
                             enter.data(), from.data());
            for (std::size_t to = 0; to < classes; ++to) {
                float best = kUnreachable;
                for (std::size_t j = 0; j < classes; ++j)
                    best = std::min(best, exitScore[j] + transition[j * stride + to]);
                int first = -1;
                for (std::size_t j = 0; j < classes && first < 0; ++j)
                    if (exitScore[j] + transition[j * stride + to] == best)
                        first = static_cast<int>(j);
                ASSERT_EQ(enter[to], best) << classes << " classes, to " << to;
                ASSERT_EQ(from[to], first) << classes << " classes, to " << to;
            }
        }
    }
}
