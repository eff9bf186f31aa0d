#include "app/command.h"

namespace kincal::app {

// Not built yet: registers the subcommand so usage is stable; exits 1.
void AddCaptureCommand(CLI::App& app, Runner* run) {
  CLI::App* sub = app.add_subcommand("capture", "(not implemented yet)");
  sub->allow_extras();
  sub->callback([run] {
    *run = [] {
      std::fprintf(stderr, "kincal capture: not implemented yet\n");
      return 1;
    };
  });
}

}  // namespace kincal::app
