// An hour through the service's live path (issue 10: memory bounded on an hour of input; the
// live mode listens for hours, mostly to a quiet room): the bundled example line, then room
// noise, fed to lipsyncd's live input (ClipMaker::startLive: front end, causal runtime, heard
// jaw and loudness) 10 ms at a time, as the tick feeds it. A program, not a benchmark: it
// prints the CPU time a tick and the resident memory for each stretch of the hour, and the last
// stretch's cost against the first's. A pause is one open segment as long as the pause, so a
// path whose work grows with the open segment slows down as the pause goes on (an hour's pause
// once cost 25 us a tick more every minute); a bounded one keeps the ratio near 1.
//
//   build/bench/live_hour [--minutes 60] [--every SECONDS] [--report 10]
//
// --every: the line again every this many seconds (a show), instead of once at the start.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lipsyncd/daemon.hpp>
#include <lipsyncd/dsp.hpp>
#include <random>
#include <string>

#include "ProcessUsage.hpp"

namespace {

using namespace lipsyncd;
using bench::residentKiB;
using bench::threadCpuSeconds;

struct Options {
    double minutes = 60, every = 0, report = 10;  // every 0: the line once, at the start
};

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        double* target = a == "--minutes"  ? &o.minutes
                         : a == "--every"  ? &o.every
                         : a == "--report" ? &o.report
                                           : nullptr;
        if (!target || i + 1 == argc) {
            std::fprintf(stderr,
                         "usage: live_hour [--minutes 60] [--every SECONDS] [--report 10]\n");
            std::exit(2);
        }
        *target = std::atof(argv[++i]);
        if (!(*target > 0) && target != &o.every) {
            std::fprintf(stderr, "live_hour: %s must be above 0\n", a.c_str());
            std::exit(2);
        }
    }
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    const auto o = parse(argc, argv);
    const auto line = dsp::readAudioFile(findDataFile("examples/hello.wav"));
    daemon::DaemonConfig config;
    config.hardware = false;
    config.adaptSpeaker = false;
    const daemon::ClipMaker maker(config);
    auto live = maker.startLive(line.sampleRate);
    PoseTrack out;
    out.poses = maker.poseNames();

    const auto block = static_cast<std::size_t>(line.sampleRate / 100);
    const auto ticks = static_cast<long>(o.minutes * 6000);
    const auto lineEvery = o.every > 0 ? static_cast<long>(o.every * 100) : ticks;
    const auto reportEvery = static_cast<long>(o.report * 6000);
    std::vector<float> samples(block);
    std::mt19937 rng(1);
    std::normal_distribution<float> room(0, 3e-4f);  // about -70 dBFS
    std::printf("%ld ticks of 10 ms: 'examples/hello.wav' (%.1f s) ", ticks,
                double(line.samples.size()) / line.sampleRate);
    if (o.every > 0)
        std::printf("every %.0f s, room noise between\n", o.every);
    else
        std::printf("once, then room noise\n");
    double first = 0, stretch = 0, started = threadCpuSeconds();
    for (long tick = 0; tick < ticks; ++tick) {
        const auto at = static_cast<std::size_t>(tick % lineEvery) * block;
        for (std::size_t i = 0; i < block; ++i)
            samples[i] = at + i < line.samples.size() ? line.samples[at + i] : room(rng);
        out.times.clear();  // the tick keeps only the newest frame
        out.values.clear();
        live->push(samples, out);
        if ((tick + 1) % reportEvery == 0 || tick + 1 == ticks) {
            const double now = threadCpuSeconds();
            const long n = (tick % reportEvery) + 1;
            stretch = 1e6 * (now - started) / static_cast<double>(n);
            if (first == 0) first = stretch;
            std::printf("minute %6.1f: %6.2f us a tick, %7.0f x real time, resident %ld KiB\n",
                        static_cast<double>(tick + 1) / 6000, stretch, 1e4 / stretch,
                        residentKiB());
            std::fflush(stdout);
            started = now;
        }
    }
    std::printf("last stretch against the first: %.2f x the CPU time a tick\n", stretch / first);
    return 0;
}
