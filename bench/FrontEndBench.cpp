// Front-end benchmarks (issue 2): whole-file analysis as a multiple of real time, the cost per
// frame of each stage, and the memory of a long stream. Speech is espeak-ng's, made in-process.
//
//   build/bench/frontend_bench                      # everything
//   build/bench/frontend_bench --benchmark_filter=WholeFile
//
// Counters: x_realtime = seconds of audio analysed per second of CPU; per-frame stages report
// their time per frame (one iteration = one frame, or one 10 ms block for the resampler).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cmath>
#include <map>

#include "ProcessUsage.hpp"
#include "TestSpeech.hpp"

namespace {

using namespace lipsyncd;

// ~30 s of speech at `rate`, from the test sentence said several times.
const std::vector<float>& speechAt(int rate) {
    static std::map<int, std::vector<float>> cache;
    auto& out = cache[rate];
    if (out.empty()) {
        const auto& s = test::testSpeech();
        const auto once = test::resampleOffline(s.samples, s.rate, rate);
        while (out.size() < static_cast<std::size_t>(30 * rate))
            out.insert(out.end(), once.begin(), once.end());
    }
    return out;
}

std::vector<dsp::FrameFeatures> featuresOf(const std::vector<float>& audio,
                                           const dsp::AnalysisConfig& config) {
    dsp::FrameStream stream(config, 10000);
    std::vector<dsp::FrameFeatures> out;
    stream.push(audio, [&](const dsp::FrameFeatures& f) { out.push_back(f); });
    stream.finish([&](const dsp::FrameFeatures& f) { out.push_back(f); });
    return out;
}

void WholeFile16kHz(benchmark::State& state) {
    const auto& audio = speechAt(16000);
    const auto file =
        test::writeAudio("bench16k.wav", audio, 16000, SF_FORMAT_WAV | SF_FORMAT_PCM_16);
    const auto templates = dsp::TemplateSet::loadDefault();
    dsp::FrontEndConfig config;  // Arg 1: Viterbi decoding (the default); 0: frame by frame
    config.decoder.enabled = state.range(0) == 1;
    state.SetLabel(config.decoder.enabled ? "decoder on" : "decoder off");
    for (auto _ : state) {
        auto result = dsp::analyzeFile(file, templates, PhonemeSet::common(), config);
        benchmark::DoNotOptimize(result.schedule.data());
    }
    state.counters["x_realtime"] = benchmark::Counter(
        static_cast<double>(audio.size()) / 16000, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(WholeFile16kHz)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();

void FrameAnalysis(benchmark::State& state) {
    dsp::AnalysisConfig config;
    config.spectrumByFft = state.range(0) == 1;
    state.SetLabel(config.spectrumByFft ? "spectrum by FFT" : "spectrum evaluated directly");
    const auto& audio = speechAt(10000);
    dsp::FrameAnalyzer analyzer(config);
    auto features = analyzer.makeFeatures();
    const auto window = static_cast<std::size_t>(config.windowSamples());
    const auto hop = static_cast<std::size_t>(config.hopSamples());
    std::size_t at = 0;
    for (auto _ : state) {
        analyzer.analyze(std::span<const float>(audio).subspan(at, window), features);
        benchmark::DoNotOptimize(features.spectrum.data());
        at = at + hop + window < audio.size() ? at + hop : 0;
    }
}
BENCHMARK(FrameAnalysis)->Arg(0)->Arg(1);

void LevinsonDurbin(benchmark::State& state) {
    const int order = static_cast<int>(state.range(0));
    dsp::AnalysisConfig config;
    config.order = order;
    // The recursion's cost depends only on the order: a damped cosine, shaped like the
    // autocorrelation of a voiced frame, stands in for real frames.
    std::vector<float> r(static_cast<std::size_t>(order) + 1);
    for (int i = 0; i <= order; ++i)
        r[static_cast<std::size_t>(i)] = std::pow(0.9f, static_cast<float>(i)) * std::cos(0.3f * i);
    for (auto _ : state) benchmark::DoNotOptimize(dsp::levinsonDurbin(r, order));
}
BENCHMARK(LevinsonDurbin)->Arg(12)->Arg(24);

void Classify(benchmark::State& state) {
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto frames = featuresOf(speechAt(10000), templates.analysis);
    dsp::FrameClassifier classifier(templates, PhonemeSet::common());
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(classifier.classify(frames[i]));
        i = i + 1 < frames.size() ? i + 1 : 0;
    }
}
BENCHMARK(Classify);

void Resample10ms(benchmark::State& state) {
    const int rate = static_cast<int>(state.range(0));
    const auto& audio = speechAt(rate);
    dsp::StreamResampler resampler(rate, 10000, dsp::ResamplerQuality::Medium, 8192);
    const auto block = static_cast<std::size_t>(rate / 100);
    std::size_t at = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            resampler.process(std::span<const float>(audio).subspan(at, block)).data());
        at = at + 2 * block < audio.size() ? at + block : 0;
    }
    state.counters["delay_ms"] = 1000 * resampler.delaySeconds();
}
BENCHMARK(Resample10ms)->Arg(16000)->Arg(44100)->Arg(48000);

// Making a resampler: the service makes one for each clip it plays, so its setup (the FIR's
// design, the delay measured on a twin) is time before the mouth moves.
void ResamplerSetup(benchmark::State& state) {
    const auto rate = static_cast<double>(state.range(0));
    for (auto _ : state) {
        dsp::StreamResampler resampler(rate, 10000, dsp::ResamplerQuality::Medium, 4096);
        benchmark::DoNotOptimize(resampler.delaySeconds());
    }
}
BENCHMARK(ResamplerSetup)
    ->Arg(16000)
    ->Arg(22050)
    ->Arg(44100)
    ->Arg(48000)
    ->Unit(benchmark::kMillisecond);

// 4096-sample blocks as analyzeFile reads them: as a whole file (1: the FIR up to 16 kHz, libsoxr
// with its own DFT block sizes above) or as live input (0: the FIR at every rate).
void ResampleFile(benchmark::State& state) {
    const int rate = static_cast<int>(state.range(0));
    const auto& audio = speechAt(rate);
    const auto use = state.range(1) ? dsp::ResamplerUse::WholeFile : dsp::ResamplerUse::Live;
    dsp::StreamResampler resampler(rate, 10000, dsp::ResamplerQuality::Medium, 4096, use);
    constexpr std::size_t kBlock = 4096;
    std::size_t at = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(
            resampler.process(std::span<const float>(audio).subspan(at, kBlock)).data());
        at = at + 2 * kBlock < audio.size() ? at + kBlock : 0;
    }
    // Per 10 ms analysis frame, as bench/frontend_profile reports its stages.
    state.counters["per_frame"] =
        benchmark::Counter(static_cast<double>(state.iterations()) * kBlock / rate * 100,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["delay_ms"] = 1000 * resampler.delaySeconds();
}
BENCHMARK(ResampleFile)->ArgsProduct({{16000, 22050, 44100}, {0, 1}});

void Segment(benchmark::State& state) {
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto frames = featuresOf(speechAt(10000), templates.analysis);
    dsp::FrameClassifier classifier(templates, PhonemeSet::common());
    std::vector<dsp::FrameLabel> labels;
    for (const auto& f : frames) labels.push_back(classifier.classify(f));
    dsp::Segmenter segmenter(PhonemeSet::common(), 0.01);
    std::size_t i = 0;
    double offset = 0;
    for (auto _ : state) {
        auto l = labels[i];
        l.time += offset;
        benchmark::DoNotOptimize(segmenter.push(l).size());
        if (++i == labels.size()) i = 0, offset += labels.back().time + 0.01;
    }
}
BENCHMARK(Segment);

// One frame through the Viterbi decoder at its default lag (cost per frame).
void Decode(benchmark::State& state) {
    const auto templates = dsp::TemplateSet::loadDefault();
    const auto frames = featuresOf(speechAt(10000), templates.analysis);
    dsp::FrameClassifier classifier(templates, PhonemeSet::common());
    std::vector<dsp::FrameLabel> labels;
    std::vector<std::vector<float>> distances;
    for (const auto& f : frames) {
        labels.push_back(classifier.classify(f));
        distances.emplace_back(classifier.distances().begin(), classifier.distances().end());
    }
    dsp::ViterbiDecoder decoder(dsp::TransitionModel::loadDefault(), PhonemeSet::common(), 0.01);
    std::size_t i = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(decoder.push(labels[i], distances[i]).size());
        i = i + 1 < labels.size() ? i + 1 : 0;
    }
}
BENCHMARK(Decode);

// One hour of 16 kHz audio streamed in 10 ms blocks: memory must stay flat (bounded buffers).
void StreamOneHour(benchmark::State& state) {
    const auto& audio = speechAt(16000);
    const auto templates = dsp::TemplateSet::loadDefault();
    const long before = bench::residentKiB();
    std::size_t segments = 0;
    for (auto _ : state) {
        dsp::StreamingAnalyzer analyzer(templates, PhonemeSet::common(), 16000);
        analyzer.onSegment([&](const PhonemeSegment&) { ++segments; });
        const std::size_t total = 3600 * 16000, block = 160;
        for (std::size_t done = 0, at = 0; done < total; done += block) {
            analyzer.push(std::span<const float>(audio).subspan(at, block));
            at = at + 2 * block < audio.size() ? at + block : 0;
        }
        analyzer.finish();
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    state.counters["rss_growth_MiB"] = static_cast<double>(bench::residentKiB() - before) / 1024;
    state.counters["peak_rss_MiB"] = static_cast<double>(usage.ru_maxrss) / 1024;
    state.counters["segments"] = static_cast<double>(segments);
    state.counters["x_realtime"] =
        benchmark::Counter(3600, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(StreamOneHour)->Iterations(1)->Unit(benchmark::kSecond)->MeasureProcessCPUTime();

}  // namespace

BENCHMARK_MAIN();
