// Runtime benchmarks (issue 3): phonemes per second through the phone-bigram runtime (offline,
// streaming, causal) and the viseme filter, and the latency of the streaming modes: from a
// phoneme's start in the audio to the first weight frame after its start that goes out knowing
// the phoneme, with each segment handed over the moment it ends (the front end's own latency,
// which `lipsync analyze` reports, comes on top for the live path).
//
//   build/bench/runtime_bench
#include <benchmark/benchmark.h>

#include <lipsyncd/lipsync.hpp>
#include <random>

namespace {

using namespace lipsyncd;

struct Shipped {
    lipsync::PoseSet poses = lipsync::PoseSet::named("facefx");
    lipsync::BigramCurveSet curves = lipsync::BigramCurveSet::named("english", poses);
};
const Shipped& shipped() {
    static const Shipped s;
    return s;
}

// Speech-like: 40–160 ms phonemes, occasional pauses.
PhonemeSchedule schedule(std::size_t n) {
    std::mt19937 rng(42);
    const auto& set = PhonemeSet::common();
    std::uniform_int_distribution<std::size_t> pick(1, set.size() - 1);
    std::uniform_real_distribution<double> length(0.04, 0.16);
    PhonemeSchedule s;
    double t = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double d = i % 25 == 0 ? 0.3 : length(rng);
        s.push_back({t, t + d, i % 25 == 0 ? "sil" : set[pick(rng)].name, 1});
        t += d;
    }
    return s;
}

void Offline(benchmark::State& state) {
    const auto s = schedule(1000);
    for (auto _ : state)
        benchmark::DoNotOptimize(
            lipsync::animate(s, shipped().curves, shipped().poses).values.data());
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 1000);
    state.SetLabel("items = phonemes");
}
BENCHMARK(Offline)->Unit(benchmark::kMillisecond);

void Filter(benchmark::State& state) {
    const auto s = schedule(1000);
    for (auto _ : state)
        benchmark::DoNotOptimize(
            lipsync::animateFilter(s, shipped().curves, shipped().poses).values.data());
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 1000);
}
BENCHMARK(Filter)->Unit(benchmark::kMillisecond);

// Arg: delay in ms (0 = causal).
void Streaming(benchmark::State& state) {
    const double delay = static_cast<double>(state.range(0)) / 1000;
    const auto s = schedule(1000);
    double latencySum = 0, latencyMax = 0;
    for (auto _ : state) {
        lipsync::StreamingRuntime stream(shipped().curves, shipped().poses, delay);
        PoseTrack out;
        std::size_t next = 0;  // the next phoneme whose start frame has not gone out yet
        latencySum = latencyMax = 0;
        for (std::size_t k = 0; k < s.size(); ++k) {
            const auto& seg = s[k];
            stream.push(seg, out);
            // Pushed at seg.end: phonemes up to k are known; those whose first frame after their
            // start is now out waited until here.
            while (next <= k && static_cast<double>(out.frames()) / 100 > s[next].start + 0.01) {
                const double wait = seg.end - s[next].start;
                latencySum += wait;
                latencyMax = std::max(latencyMax, wait);
                ++next;
            }
        }
        stream.finish(out);
        benchmark::DoNotOptimize(out.values.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 1000);
    state.counters["latency_mean_ms"] = 1000 * latencySum / 1000;
    state.counters["latency_max_ms"] = 1000 * latencyMax;
}
BENCHMARK(Streaming)->Arg(0)->Arg(150)->Arg(300)->Arg(1200)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
