// Forced-alignment speed (issue 11: ≥ 500× real time on one core): the aligner alone on the
// front end's per-frame distances, the whole of `lipsync align` over a file (a level pass,
// decoding, resampling, LPC analysis, classification and the aligner), and the aligner as it
// follows a live line (LineFollower, 100 ms behind: what a live tick adds per frame). Speech is
// espeak-ng's, made in-process: a line said over and over, about 30 s.
//
//   build/bench/align_bench
//
// Counters: x_realtime = seconds of audio aligned per second of CPU; frames_held = the most
// frames of back-pointers the aligner held at once (its memory bound); per_frame = CPU seconds per
// 10 ms frame.
#include <benchmark/benchmark.h>

#include <lipsyncd/dsp.hpp>
#include <lipsyncd/tts.hpp>

#include "TestSpeech.hpp"

namespace {

using namespace lipsyncd;

constexpr char kLine[] = "Hello puppet, please open your mouth wide and say something funny.";

struct Material {
    std::vector<float> audio;
    int rate = 0;
    std::vector<dsp::ScriptWord> script;
    std::filesystem::path file;
    // Per frame: time, distances, silent.
    std::vector<double> times;
    std::vector<std::vector<float>> distances, full;
    std::vector<bool> silent;
    std::vector<dsp::FrameLabel> labels;
};

const Material& material() {
    static const Material m = [] {
        Material out;
        EspeakSynthesizer synth;  // one for the process: espeak-ng cannot start twice
        const auto speech = synth.synthesize({kLine, "en-us", 0, -1});
        out.rate = speech.sampleRate;
        std::string text;
        while (out.audio.size() < static_cast<std::size_t>(30 * out.rate)) {
            for (auto v : speech.samples) out.audio.push_back(v / 32768.0f);
            text += std::string(kLine) + " ";
        }
        out.script = scriptForText(synth, text, "en-us", espeakMapForVoice("en-us"), nullptr);
        out.file = test::writeAudio("align_bench.wav", out.audio, out.rate,
                                    SF_FORMAT_WAV | SF_FORMAT_PCM_16);
        const auto templates = dsp::TemplateSet::loadDefault();
        dsp::StreamingAnalyzer analyzer(templates, PhonemeSet::common(), out.rate);
        analyzer.onFrame([&](const dsp::StreamingAnalyzer::Frame& f) {
            out.times.push_back(f.label.time);
            const auto d = analyzer.templateDistances();
            out.distances.emplace_back(d.begin(), d.end());
            const auto full = analyzer.distances();
            out.full.emplace_back(full.begin(), full.end());
            out.silent.push_back(f.label.silent);
            out.labels.push_back(f.label);
        });
        analyzer.push(out.audio);
        analyzer.finish();
        return out;
    }();
    return m;
}

void AlignerOnly(benchmark::State& state) {
    const auto& m = material();
    std::size_t held = 0;
    for (auto _ : state) {
        dsp::ForcedAligner aligner(m.script, PhonemeSet::common(), 0.01);
        for (std::size_t i = 0; i < m.times.size(); ++i)
            aligner.push(m.times[i], m.distances[i], m.silent[i]);
        benchmark::DoNotOptimize(aligner.finish());
        held = aligner.peakFramesHeld();
    }
    const double seconds = static_cast<double>(m.audio.size()) / m.rate;
    state.counters["x_realtime"] = benchmark::Counter(
        seconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["frames_held"] = static_cast<double>(held);
}
BENCHMARK(AlignerOnly)->Unit(benchmark::kMillisecond);

void WholeFile(benchmark::State& state) {
    const auto& m = material();
    const auto templates = dsp::TemplateSet::loadDefault();
    for (auto _ : state)
        benchmark::DoNotOptimize(dsp::alignFile(m.file, m.script, templates, PhonemeSet::common()));
    const double seconds = static_cast<double>(m.audio.size()) / m.rate;
    state.counters["x_realtime"] = benchmark::Counter(
        seconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(WholeFile)->Unit(benchmark::kMillisecond);

void FollowedLine(benchmark::State& state) {
    const auto& m = material();
    std::size_t segments = 0;
    for (auto _ : state) {
        dsp::LineFollower follower(m.script, PhonemeSet::common(), 0.01, 0.1);
        follower.onSegment([&](const PhonemeSegment&) { ++segments; });
        for (std::size_t i = 0; i < m.labels.size(); ++i)
            follower.push(m.labels[i], m.distances[i], m.full[i]);
        follower.finish();
    }
    benchmark::DoNotOptimize(segments);
    const double seconds = static_cast<double>(m.audio.size()) / m.rate;
    const auto runs = static_cast<double>(state.iterations());
    state.counters["x_realtime"] = benchmark::Counter(seconds * runs, benchmark::Counter::kIsRate);
    state.counters["per_frame"] =
        benchmark::Counter(static_cast<double>(m.labels.size()) * runs,
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(FollowedLine)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
