#ifndef KINCAL_APP_COMMAND_H_
#define KINCAL_APP_COMMAND_H_

#include <CLI/CLI.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace kincal::app {

// What a subcommand leaves behind after parsing: the function to run. Each
// Add*Command registers its options and, in its callback, sets *run. Commands
// return the process exit code (0 ok, 1 failure); bad input throws
// InputError, which main() turns into exit code 2.
using Runner = std::function<int()>;

void AddSimulateCommand(CLI::App& app, Runner* run);
void AddCalibrateCommand(CLI::App& app, Runner* run);
void AddEvaluateCommand(CLI::App& app, Runner* run);
void AddSensitivityCommand(CLI::App& app, Runner* run);
void AddDiagnoseCommand(CLI::App& app, Runner* run);
void AddCamcalCommand(CLI::App& app, Runner* run);
void AddTrackCommand(CLI::App& app, Runner* run);
void AddImportCommand(CLI::App& app, Runner* run);
void AddCaptureCommand(CLI::App& app, Runner* run);
void AddExportCommand(CLI::App& app, Runner* run);
void AddReportCommand(CLI::App& app, Runner* run);
void AddPlanCommand(CLI::App& app, Runner* run);
void AddBundleCommand(CLI::App& app, Runner* run);
void AddTargetCommand(CLI::App& app, Runner* run);
void AddPrintCommand(CLI::App& app, Runner* run);
void AddCompensateCommand(CLI::App& app, Runner* run);
void AddIso9283Command(CLI::App& app, Runner* run);

// Prints a result object as one line of JSON on stdout, with the command line
// and tool version added ("command", "kincal_version").
void PrintJson(nlohmann::json result);

}  // namespace kincal::app

#endif  // KINCAL_APP_COMMAND_H_
