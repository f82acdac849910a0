// lipsync plot: pose weights (and the schedule under them) as an SVG chart.
#include <optional>

#include "Commands.hpp"
#include "Corpus.hpp"
#include "NumberOption.hpp"
#include "Output.hpp"
#include "PoseTrackSvg.hpp"

namespace lipsyncd::cli {

void addPlotCommand(CLI::App& app) {
    struct Options {
        std::string weights, schedule, labels = "auto", output;
        SvgChartOptions chart;
    };
    auto o = std::make_shared<Options>();
    auto* cmd =
        app.add_subcommand("plot", "Draw pose weights over time, phonemes underneath, as SVG");
    cmd->add_option("--weights", o->weights, "Pose weights (CSV from animate/analyze/say)")
        ->required();
    cmd->add_option("--schedule", o->schedule, "Phoneme schedule to show under the curves");
    cmd->add_option("--labels", o->labels, "Schedule alphabet (as for animate)")
        ->capture_default_str();
    cmd->add_option("-o,--output", o->output, "SVG file to write ('-' for stdout)")->required();
    addNumberOption(*cmd, "--pixels-per-second", o->chart.pixelsPerSecond, "Horizontal scale", 10.0,
                    5000.0);
    cmd->callback([o] {
        const auto track = readPoseTrackCsvFile(o->weights);
        std::optional<PhonemeSchedule> schedule;
        if (!o->schedule.empty()) schedule = readLabels(o->schedule, o->labels);
        withOutputStream(o->output, [&](std::ostream& out) {
            writePoseTrackSvg(out, track, schedule ? &*schedule : nullptr, o->chart);
        });
    });
}

}  // namespace lipsyncd::cli
