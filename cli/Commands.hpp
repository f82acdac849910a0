// The `lipsync` tool's subcommands. Each registers itself on the app and runs from a callback;
// errors are thrown (InputError: bad input, exit 1) and reported by main.
#pragma once

#include <CLI/CLI.hpp>

namespace lipsyncd::cli {

void addSayCommand(CLI::App& app);
void addAnalyzeCommand(CLI::App& app);
void addAlignCommand(CLI::App& app);
void addEvalCommand(CLI::App& app);
void addTrainCommand(CLI::App& app);
void addCalibrateCommand(CLI::App& app);
void addAnimateCommand(CLI::App& app);
void addCurvesCommand(CLI::App& app);
void addPlotCommand(CLI::App& app);
void addDriveCommands(CLI::App& app);  // drive, check, devices
void addCtlCommand(CLI::App& app);
void addEditCommand(CLI::App& app);

}  // namespace lipsyncd::cli
