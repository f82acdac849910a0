// Where whole-file analysis spends its time and memory (issue 10): the cost per frame of each
// stage of `lipsync analyze`, whole-file analysis as a multiple of real time on one core, and
// peak memory for 8 and 60 minutes of input. A program, not a benchmark: it prints one report.
//
//   build/bench/frontend_profile [--corpus DIR] [--minutes 8] [--long-minutes 60]
//                                [--templates SET]  (default: the shipped set)
//
// Input: the espeak-ng dev corpus (every WAV under DIR, default /work/data/corpus/dev, made by
// scripts/make-corpus.sh; without it, espeak-ng speech made in-process) resampled to 16 kHz and
// concatenated, looped to length, written to temporary WAV files (16-bit) and removed at exit.
// Times are CPU time of this thread (one core); memory is the peak resident set (VmHWM) of a
// child process that only analyses the file, as `lipsync analyze` does.
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>

#include "../dsp/src/FrameKernels.hpp"
#include "../dsp/src/LpcSpectrum.hpp"
#include "ProcessUsage.hpp"
#include "TestSpeech.hpp"

extern char** environ;

namespace {

using namespace lipsyncd;

// Peak resident set of this process, MiB.
double peakRssMiB() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024;
    return 0;
}

std::vector<float> corpusAt16k(const std::filesystem::path& dir) {
    std::vector<float> out;
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(dir))
        for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
            if (e.path().extension() == ".wav") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
        const auto audio = dsp::readAudioFile(f);
        const auto at16k = test::resampleOffline(audio.samples, audio.sampleRate, 16000);
        out.insert(out.end(), at16k.begin(), at16k.end());
    }
    if (out.empty()) {
        std::cerr << "frontend_profile: no WAV files under " << dir
                  << "; using espeak-ng speech made here\n";
        const auto& s = test::testSpeech();
        out = test::resampleOffline(s.samples, s.rate, 16000);
    }
    return out;
}

// `minutes` of the corpus, looped, as a 16-bit 16 kHz WAV file.
std::filesystem::path writeLooped(const std::vector<float>& corpus, double minutes,
                                  const std::string& name) {
    const auto total = static_cast<std::size_t>(minutes * 60 * 16000);
    std::vector<float> audio;
    audio.reserve(total);
    while (audio.size() < total)
        audio.insert(audio.end(), corpus.begin(),
                     corpus.begin() + static_cast<std::ptrdiff_t>(
                                          std::min(corpus.size(), total - audio.size())));
    return test::writeAudio(name, audio, 16000, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
}

// Each stage in turn over blocks of frames (stage by stage, so that each one's time is its
// own), CPU time summed per stage.
class StageClock {
  public:
    explicit StageClock(std::vector<std::string> names)
        : names_(std::move(names)), seconds_(names_.size(), 0.0) {}
    template <class F>
    void time(std::size_t stage, F&& f) {
        const double t0 = bench::threadCpuSeconds();
        f();
        seconds_[stage] += bench::threadCpuSeconds() - t0;
    }
    void report(std::size_t frames) const {
        double total = 0;
        for (std::size_t i = 0; i < names_.size(); ++i) {
            std::printf("  %-34s %8.0f ns/frame\n", names_[i].c_str(),
                        1e9 * seconds_[i] / static_cast<double>(frames));
            total += seconds_[i];
        }
        std::printf("  %-34s %8.0f ns/frame\n", "sum of stages",
                    1e9 * total / static_cast<double>(frames));
    }

  private:
    std::vector<std::string> names_;
    std::vector<double> seconds_;
};

void profileStages(const std::filesystem::path& file, const dsp::TemplateSet& templates) {
    const auto& set = PhonemeSet::common();
    const auto& c = templates.analysis;
    enum {
        Decode,
        Resample,
        Level,
        Window,
        Autocorrelation,
        Levinson,
        Spectrum,
        Classify,
        Classes,
        Jaw,
        Viterbi,
        Segment
    };
    StageClock clock({"decode (libsndfile, to mono)", "resample to 10 kHz", "level (RMS, clipping)",
                      "pre-emphasis and window", "autocorrelation", "Levinson-Durbin",
                      "LPC spectrum", "template distances", "class network (likelihoods)",
                      "jaw network (heard jaw)", "Viterbi decoder (fixed lag)", "segmenter"});

    // Decode and resample the whole file in the blocks analyzeFile uses.
    auto decoder = dsp::AudioDecoder::open(file);
    dsp::StreamResampler resampler(decoder.sampleRate(), c.analysisRate,
                                   dsp::ResamplerQuality::Medium, 4096,
                                   dsp::ResamplerUse::WholeFile);
    std::vector<float> block(4096), resampled;
    for (;;) {
        std::size_t n = 0;
        clock.time(Decode, [&] { n = decoder.read(block); });
        if (n == 0) break;
        clock.time(Resample, [&] {
            const auto out = resampler.process(std::span<const float>(block.data(), n));
            resampled.insert(resampled.end(), out.begin(), out.end());
        });
    }

    // Then every frame, stage by stage over blocks of frames.
    const auto window = static_cast<std::size_t>(c.windowSamples());
    const auto hop = static_cast<std::size_t>(c.hopSamples());
    const std::size_t frames =
        resampled.size() < window ? 0 : (resampled.size() - window) / hop + 1;
    constexpr std::size_t kBlock = 256;
    std::vector<float> hamming(window);
    for (std::size_t i = 0; i < window; ++i)
        hamming[i] = static_cast<float>(
            0.54 - 0.46 * std::cos(2 * std::numbers::pi * static_cast<double>(i) /
                                   static_cast<double>(window - 1)));
    std::vector<float> lagWindow(static_cast<std::size_t>(c.order) + 1);
    for (int i = 0; i <= c.order; ++i) {
        const double x = 2 * std::numbers::pi * c.lagWindowHz * i / c.analysisRate;
        lagWindow[i] = static_cast<float>(std::exp(-0.5 * x * x));
    }
    std::vector<float> windowed(kBlock * (window + dsp::kMaxOrder), 0.0f);
    std::vector<std::array<float, dsp::kMaxOrder + 1>> r(kBlock);
    dsp::FrameAnalyzer analyzer(c);
    std::vector<dsp::FrameFeatures> features(kBlock, analyzer.makeFeatures());
    dsp::DirectLpcSpectrum spectrum(c.order, c.spectrumBins);
    const auto bins = static_cast<std::size_t>(c.spectrumBins);
    // The distances alone here; the networks (which classify() runs when the set has them)
    // are stages of their own.
    auto distancesOnly = templates;
    distancesOnly.jawNetwork.reset();
    distancesOnly.classNetwork.reset();
    const float classNetworkDb = dsp::ClassifierConfig{}.classNetworkDb;
    const float classPriorScale = dsp::ClassifierConfig{}.classPriorScale;
    std::vector<int> networkClass;
    std::vector<float> likelihoods, scratch;
    // What each network hears (the frame, or it and its slopes), made as the classifier makes
    // it; each stage makes its own, though the classifier shares one when both hear alike.
    const auto featureCount = static_cast<std::size_t>(templates.analysis.featureCount());
    dsp::NetworkInput classInput, jawInput;
    if (templates.classNetwork) {
        networkClass = templates.classNetwork->setIndices(set);
        likelihoods.resize(networkClass.size());
        scratch.resize(templates.classNetwork->hiddenUnits());
        classInput = dsp::NetworkInput(templates.classNetwork->slopeFrames, featureCount);
    }
    if (templates.jawNetwork)
        jawInput = dsp::NetworkInput(templates.jawNetwork->slopeFrames, featureCount);
    dsp::FrameClassifier classifier(distancesOnly, set);
    float jawSum = 0;  // kept, so the network's work is not optimised away
    std::vector<dsp::FrameLabel> labels(kBlock);
    std::vector<std::vector<float>> distances(kBlock);
    dsp::ViterbiDecoder viterbi(dsp::TransitionModel::loadDefault(), set, c.hopSeconds);
    std::vector<dsp::FrameLabel> decided;
    dsp::Segmenter segmenter(set, c.hopSeconds);
    std::size_t segments = 0;
    for (std::size_t first = 0; first < frames; first += kBlock) {
        const std::size_t count = std::min(kBlock, frames - first);
        auto frame = [&](std::size_t k) {
            return std::span<const float>(resampled).subspan((first + k) * hop, window);
        };
        auto y = [&](std::size_t k) {
            return windowed.data() + k * (window + dsp::kMaxOrder) + dsp::kMaxOrder;
        };
        clock.time(Level, [&] {
            for (std::size_t k = 0; k < count; ++k) {
                const auto level = dsp::kernels::measureLevel(frame(k), window);
                features[k].energyDb = level.energyDb;
            }
        });
        clock.time(Window, [&] {
            for (std::size_t k = 0; k < count; ++k)
                dsp::kernels::preEmphasizeAndWindow(frame(k), hamming,
                                                    static_cast<float>(c.preEmphasis), y(k));
        });
        clock.time(Autocorrelation, [&] {
            for (std::size_t k = 0; k < count; ++k)
                dsp::kernels::autocorrelate(y(k), window, c.order, lagWindow, r[k]);
        });
        clock.time(Levinson, [&] {
            for (std::size_t k = 0; k < count; ++k) {
                r[k][0] = r[k][0] * static_cast<float>(1.0 + c.whiteNoiseCorrection) + 1e-9f;
                features[k].lpc = dsp::levinsonDurbin(
                    std::span<const float>(r[k].data(), static_cast<std::size_t>(c.order) + 1),
                    c.order);
            }
        });
        clock.time(Spectrum, [&] {
            for (std::size_t k = 0; k < count; ++k)
                spectrum.evaluate(std::span<const float>(features[k].lpc.a.data(),
                                                         static_cast<std::size_t>(c.order) + 1),
                                  std::span<float>(features[k].spectrum).first(bins));
        });
        // The classifier's input, made as the front end makes it (not timed: the stages above
        // are its parts).
        for (std::size_t k = 0; k < count; ++k) {
            features[k].time =
                (static_cast<double>((first + k) * hop) + window / 2.0) / c.analysisRate;
            analyzer.analyze(frame(k), features[k]);
        }
        clock.time(Classify, [&] {
            for (std::size_t k = 0; k < count; ++k) {
                labels[k] = classifier.classify(features[k]);
                distances[k].assign(classifier.distances().begin(), classifier.distances().end());
            }
        });
        if (templates.classNetwork)
            clock.time(Classes, [&] {
                for (std::size_t k = 0; k < count; ++k) {
                    const auto input = classInput.push(features[k].spectrum);
                    if (!features[k].valid) continue;
                    templates.classNetwork->addToDistances(input, networkClass, classNetworkDb,
                                                           classPriorScale, distances[k],
                                                           likelihoods, scratch);
                }
            });
        if (templates.jawNetwork)
            clock.time(Jaw, [&] {
                for (std::size_t k = 0; k < count; ++k) {
                    const auto input = jawInput.push(features[k].spectrum);
                    if (!labels[k].silent) jawSum += (*templates.jawNetwork)(input);
                }
            });
        clock.time(Viterbi, [&] {
            decided.clear();
            for (std::size_t k = 0; k < count; ++k)
                for (const auto& l : viterbi.push(labels[k], distances[k])) decided.push_back(l);
        });
        clock.time(Segment, [&] {
            for (const auto& l : decided) segments += segmenter.push(l).size();
        });
    }
    std::printf("per-frame cost of each stage (%zu frames, %zu segments, mean heard jaw %.2f):\n",
                frames, segments, frames ? jawSum / static_cast<double>(frames) : 0.0);
    clock.report(frames);
}
}  // namespace

int main(int argc, char** argv) {
    std::filesystem::path corpus = "/work/data/corpus/dev";
    double minutes = 8, longMinutes = 60;
    std::string set;  // a template set's name or file; empty: the shipped one
    const auto load = [&] {
        return set.empty() ? dsp::TemplateSet::loadDefault() : dsp::TemplateSet::named(set);
    };
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string arg = argv[i];
        if (arg == "--templates")
            set = argv[i + 1];
        else if (arg == "--corpus")
            corpus = argv[i + 1];
        else if (arg == "--minutes")
            minutes = std::stod(argv[i + 1]);
        else if (arg == "--long-minutes")
            longMinutes = std::stod(argv[i + 1]);
        else if (arg == "--analyze") {  // child: analyse one file, report time and memory
            const auto templates = load();
            const double before = peakRssMiB();
            const double t0 = bench::threadCpuSeconds();
            const auto result = dsp::analyzeFile(argv[i + 1], templates, PhonemeSet::common());
            const double seconds = bench::threadCpuSeconds() - t0;
            std::printf(
                "  %6.1f min: %8.0f x real time, %6.3f s CPU, %zu segments; peak RSS "
                "%.1f MiB (%.1f MiB before the analysis)\n",
                result.durationSeconds / 60, result.durationSeconds / seconds, seconds,
                result.schedule.size(), peakRssMiB(), before);
            return 0;
        } else {
            std::cerr << "usage: frontend_profile [--corpus DIR] [--minutes M] [--long-minutes M] "
                         "[--templates SET]\n";
            return 2;
        }
    }
    const auto templates = load();
    const auto speech = corpusAt16k(corpus);
    std::printf("input: %.1f s of speech from %s, looped\n", speech.size() / 16000.0,
                corpus.c_str());
    std::vector<std::filesystem::path> files = {
        writeLooped(speech, minutes, "profile_short.wav"),
        writeLooped(speech, longMinutes, "profile_long.wav")};
    profileStages(files[0], templates);
    std::printf("whole-file analysis (dsp::analyzeFile, one core), each in its own process:\n");
    std::fflush(stdout);
    int status = 0;
    for (const auto& f : files) {
        pid_t pid = 0;
        std::string self = "/proc/self/exe", flag = "--analyze", path = f.string();
        std::string setFlag = "--templates", setName = set.empty() ? "default" : set;
        char* args[] = {self.data(), setFlag.data(), setName.data(),
                        flag.data(), path.data(),    nullptr};
        if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, args, environ) != 0 ||
            waitpid(pid, &status, 0) != pid || status != 0) {
            std::cerr << "frontend_profile: the analysis of " << f << " failed\n";
            status = 1;
        }
        std::filesystem::remove(f);
    }
    return status == 0 ? 0 : 1;
}
