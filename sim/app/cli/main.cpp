// sonarbench: the command-line front end, one file per command (sim/app/*_command.cpp). Exit
// status: 0 success, 1 a scenario's criteria failed, 2 bad input or the machine's refusal, 3 an
// internal error.
#include <filesystem>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/sim/report/report.hpp"

int main(int argc, char** argv) {
  namespace app = sonarbench::app;
  CLI::App cli{
      "sonarbench: simulate a mechanical scanning imaging sonar, map its beams into an OctoMap, "
      "and score the map against ground truth."};
  cli.require_subcommand(1);
  cli.set_version_flag("--version", std::string("sonarbench ") + sonarbench::sim::kVersion);
  const std::vector<app::Command> commands = {
      app::AddRunCommand(cli),       app::AddMapCommand(cli),      app::AddScoreCommand(cli),
      app::AddFidelityCommand(cli),  app::AddSimulateCommand(cli), app::AddSweepCommand(cli),
      app::AddDetectorsCommand(cli), app::AddImportCommand(cli),   app::AddExportCommand(cli)};
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A missing or unknown command is named, with the commands there are.
    if (cli.get_subcommands().empty() && (argc == 1 || argv[1][0] != '-')) {
      std::string names;
      for (const app::Command& command : commands) {
        names += (names.empty() ? "" : ", ") + command.cli->get_name();
      }
      std::cerr << "sonarbench: error: "
                << (argc == 1 ? std::string("a command is required")
                              : "unknown command '" + std::string(argv[1]) + "'")
                << "; the commands are " << names << " (sonarbench --help)\n";
      return app::kExitBadInput;
    }
    if (e.get_exit_code() == 0) return cli.exit(e);  // --help, --version
    std::cerr << app::ParseErrorMessage(cli, e, argc, argv) << "\n";
    return app::kExitBadInput;
  }
  try {
    for (const app::Command& command : commands) {
      if (*command.cli) return command.run();
    }
  } catch (const sonarbench::InputError& e) {
    std::cerr << "sonarbench: error: " << e.what() << "\n";
    return app::kExitBadInput;
  } catch (const std::bad_alloc&) {
    // The readers and the budgets refuse what would not fit before allocating; this is the
    // machine's refusal of what is left (a memory limit set lower than the budgets assume).
    std::cerr << "sonarbench: error: out of memory: the machine refused an allocation (lower "
                 "--max-triangles, --max-cells or --max-beams, or raise the memory limit)\n";
    return app::kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // The machine's refusal (a read-only or full disk, no permission), with the OS's reason.
    std::cerr << "sonarbench: error: " << e.what() << "\n";
    return app::kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "sonarbench: internal error: " << e.what() << "\n";
    return app::kExitInternalError;
  }
  return app::kExitInternalError;
}
