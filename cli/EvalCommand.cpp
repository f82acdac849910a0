// lipsync eval: how well `analyze` agrees with reference labels, over a corpus.
#include <iomanip>
#include <iostream>
#include <lipsyncd/dsp.hpp>
#include <nlohmann/json.hpp>
#include <sstream>

#include "Commands.hpp"
#include "Corpus.hpp"
#include "FrontEndOptions.hpp"
#include "Output.hpp"

namespace lipsyncd::cli {

namespace {
struct EvalOptions {
    std::string corpus;
    std::string labels = "auto";
    std::string json;
    double minAccuracy = 0, minGroupAccuracy = 0;
    bool perFile = true;
    FrontEndOptions frontEnd;
};

struct FileScore {
    std::string name;
    dsp::ScheduleScore score;
};

void printReport(std::ostream& out, const std::vector<FileScore>& files,
                 const dsp::ScheduleScore& total, const PhonemeSet& set, bool perFile) {
    out << std::fixed << std::setprecision(1);
    if (perFile) {
        out << std::left << std::setw(32) << "file" << std::right << std::setw(8) << "frames"
            << std::setw(10) << "accuracy" << std::setw(8) << "group" << '\n';
        for (const auto& f : files)
            out << std::left << std::setw(32) << f.name << std::right << std::setw(8)
                << f.score.frames << std::setw(9) << 100 * f.score.accuracy() << '%' << std::setw(7)
                << 100 * f.score.groupAccuracy() << "%\n";
        out << '\n';
    }
    out << "per class (reference): frames, recall, most often taken for\n";
    for (std::size_t r = 0; r < set.size(); ++r) {
        std::size_t n = 0, worst = r;
        for (std::size_t h = 0; h < set.size(); ++h) {
            n += total.confusion[r][h];
            if (h != r && total.confusion[r][h] > (worst == r ? 0 : total.confusion[r][worst]))
                worst = h;
        }
        if (n == 0) continue;
        out << "  " << std::left << std::setw(5) << set[r].name << std::right << std::setw(7) << n
            << std::setw(8) << 100.0 * total.confusion[r][r] / n << '%';
        if (worst != r)
            out << "   " << set[worst].name << " (" << 100.0 * total.confusion[r][worst] / n
                << "%)";
        out << '\n';
    }
    out << "\nfiles " << files.size() << ", frames " << total.frames << ": accuracy "
        << 100 * total.accuracy() << "% (common set), " << 100 * total.groupAccuracy()
        << "% (visual groups)\n";
}

nlohmann::json toJson(const std::vector<FileScore>& files, const dsp::ScheduleScore& total,
                      const PhonemeSet& set) {
    nlohmann::json j;
    j["frames"] = total.frames;
    j["accuracy"] = total.accuracy();
    j["group_accuracy"] = total.groupAccuracy();
    for (const auto& f : files)
        j["files"].push_back({{"name", f.name},
                              {"frames", f.score.frames},
                              {"accuracy", f.score.accuracy()},
                              {"group_accuracy", f.score.groupAccuracy()}});
    for (std::size_t r = 0; r < set.size(); ++r)
        for (std::size_t h = 0; h < set.size(); ++h)
            if (total.confusion[r][h] > 0)
                j["confusion"][set[r].name][set[h].name] = total.confusion[r][h];
    return j;
}

void runEval(const EvalOptions& o) {
    const auto& set = PhonemeSet::common();
    const auto templates = o.frontEnd.loadTemplates();
    std::vector<std::string> skipped;
    const auto items = listCorpus(o.corpus, &skipped);
    for (const auto& s : skipped) std::cerr << "lipsync eval: skipped " << s << '\n';
    std::vector<FileScore> files;
    dsp::ScheduleScore total;
    for (const auto& item : items) {
        const auto reference = readLabels(item.labels, o.labels);
        const auto result = dsp::analyzeFile(item.audio, templates, set, o.frontEnd.config(),
                                             o.frontEnd.decode(), std::nullopt);
        files.push_back({item.name, dsp::scoreSchedule(result.schedule, reference, set)});
        total.add(files.back().score);
    }
    printReport(std::cout, files, total, set, o.perFile);
    if (!o.json.empty())
        withOutputStream(
            o.json, [&](std::ostream& out) { out << toJson(files, total, set).dump(1) << '\n'; });
    if (total.accuracy() < o.minAccuracy || total.groupAccuracy() < o.minGroupAccuracy) {
        std::ostringstream msg;
        msg << std::fixed << std::setprecision(1) << "accuracy " << 100 * total.accuracy()
            << "% / group " << 100 * total.groupAccuracy() << "% is below the floor "
            << 100 * o.minAccuracy << "% / " << 100 * o.minGroupAccuracy << '%';
        throw std::runtime_error(msg.str());
    }
}
}  // namespace

void addEvalCommand(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    auto* cmd = app.add_subcommand(
        "eval",
        "Score 'analyze' against reference labels on every NAME.wav + NAME.lab in a folder");
    cmd->add_option("--corpus", o->corpus, "Folder of NAME.wav + NAME.lab")->required();
    cmd->add_option("--labels", o->labels,
                    "Label alphabet: auto, common, arpabet, or a map name/file")
        ->capture_default_str();
    cmd->add_option("--json", o->json, "Also write the figures as JSON ('-' for stdout)");
    cmd->add_option("--min-accuracy", o->minAccuracy,
                    "Exit 1 when frame accuracy (0..1) falls below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--min-group-accuracy", o->minGroupAccuracy,
                    "Exit 1 when visual-group accuracy (0..1) falls below this")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_flag("!--no-per-file", o->perFile, "Leave out the per-file table");
    o->frontEnd.addTo(*cmd);
    cmd->callback([o] { runEval(*o); });
}

}  // namespace lipsyncd::cli
