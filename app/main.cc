// kincal: measure how accurately a robot moves, find out why it is wrong, and
// fix its model. One binary, each subcommand a thin layer over the libraries.

#include <glog/logging.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>

#include "app/command.h"
#include "data/error.h"
#include "data/provenance.h"
#include "kincal_commit.h"  // generated: KINCAL_COMMIT (app/commit.cmake)

namespace kincal::app {

void PrintJson(nlohmann::json result) {
  result["command"] = CommandLine();
  result["kincal_version"] = ToolVersion();
  std::cout << result.dump() << std::endl;
}

// Ceres logs through glog (e.g. one "Residual and Jacobian evaluation
// failed" warning per frame when no tool pose fits): kincal's own message
// says what went wrong and what to do, so glog prints only fatal errors,
// unless KINCAL_SOLVER_LOG is set to a non-empty value other than 0 (then
// every glog line, INFO included, goes to stderr).
void RouteSolverLogs(const char* argv0) {
  const char* env = std::getenv("KINCAL_SOLVER_LOG");
  const bool show = env && *env && std::strcmp(env, "0") != 0;
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = show ? google::GLOG_INFO : google::GLOG_FATAL;
  google::InitGoogleLogging(argv0);
}

}  // namespace kincal::app

int main(int argc, char** argv) {
  // The fits allocate and free Jacobians of tens of MB many times (UR10
  // series C: 8319 rows x ~350 candidate columns). By default glibc serves
  // each from a fresh mmap, returns it on free, and every page faults again
  // on first touch (~95,000 page faults, a quarter of the run in the
  // kernel). Serving up to 32 MB (glibc's maximum) from the heap and keeping
  // freed memory until exit: 20,000 page faults and `diagnose model` on series
  // C a quarter faster (docs/DIAGNOSE.md). A command-line tool
  // that exits after one job loses nothing by holding its peak.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  kincal::SetCommandLine(argc, argv);
  kincal::app::RouteSolverLogs(argv[0]);
  CLI::App app{
      "kincal: robot accuracy measurement, calibration and diagnosis.\n"
      "Units at every interface: mm, degrees, seconds."};
  app.require_subcommand(1);
  app.footer(
      "Solver messages (Ceres, through glog) are hidden; set "
      "KINCAL_SOLVER_LOG=1 to see them on stderr.");
  app.option_defaults()->always_capture_default();  // --help shows defaults
  app.set_version_flag("--version",
                       kincal::ToolVersion() + " (commit " KINCAL_COMMIT ")");
  kincal::app::Runner run;
  kincal::app::AddSimulateCommand(app, &run);
  kincal::app::AddCalibrateCommand(app, &run);
  kincal::app::AddEvaluateCommand(app, &run);
  kincal::app::AddSensitivityCommand(app, &run);
  kincal::app::AddDiagnoseCommand(app, &run);
  kincal::app::AddCamcalCommand(app, &run);
  kincal::app::AddTrackCommand(app, &run);
  kincal::app::AddImportCommand(app, &run);
  kincal::app::AddCaptureCommand(app, &run);
  kincal::app::AddExportCommand(app, &run);
  kincal::app::AddReportCommand(app, &run);
  kincal::app::AddPlanCommand(app, &run);
  kincal::app::AddBundleCommand(app, &run);
  kincal::app::AddTargetCommand(app, &run);
  kincal::app::AddPrintCommand(app, &run);
  kincal::app::AddCompensateCommand(app, &run);
  kincal::app::AddIso9283Command(app, &run);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and usage
    return 2;
  } catch (const kincal::InputError& e) {
    std::cerr << "kincal: error: " << e.what() << std::endl;
    return 2;
  }
  if (!run) {
    std::cerr << "kincal: error: no command given (see kincal --help)\n";
    return 2;
  }
  try {
    return run();
  } catch (const kincal::InputError& e) {
    std::cerr << "kincal: error: " << e.what() << std::endl;
    return 2;
  } catch (const CLI::ParseError& e) {
    std::cerr << "kincal: error: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "kincal: failure: " << e.what() << std::endl;
    return 1;
  }
}
