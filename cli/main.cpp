// lipsync: the command-line tool. Exit codes: 0 ok, 1 runtime error, 2 usage error.
#include <iostream>
#include <lipsyncd/core.hpp>

#include "Commands.hpp"

int main(int argc, char** argv) {
    CLI::App app{
        "lipsync: speech to a puppet's mouth.\n"
        "Audio or text becomes a timed phoneme schedule (linear prediction, or espeak-ng's own\n"
        "timings), the schedule becomes mouth-pose weights, the weights drive actuators.\n"
        "Run 'lipsync COMMAND --help' for each command's options.",
        "lipsync"};
    app.set_version_flag("--version", std::string("lipsync ") + LIPSYNCD_VERSION);
    app.require_subcommand(1);
    app.fallthrough(false);

    using namespace lipsyncd::cli;
    addAnalyzeCommand(app);
    addAlignCommand(app);
    addEvalCommand(app);
    addTrainCommand(app);
    addCalibrateCommand(app);
    addSayCommand(app);
    addAnimateCommand(app);
    addCurvesCommand(app);
    addPlotCommand(app);
    addDriveCommands(app);
    addCtlCommand(app);
    addEditCommand(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version arrive here too, with exit code 0.
        const int rc = app.exit(e);
        return rc == 0 ? 0 : 2;
    } catch (const lipsyncd::InputError& e) {
        std::cerr << "lipsync: " << e.what() << '\n';
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "lipsync: " << e.what() << '\n';
        return 1;
    }
    return 0;
}
