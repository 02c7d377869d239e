// The command line of a program made of subcommands (meshstream, meshstream-mpi): one place that
// parses it, runs the command and turns every failure into one diagnostic line and an exit code.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace meshstream::tools {

// Parses argv against `app` (its subcommands registered) and runs the command. Returns the exit
// code: 0 done, 1 failed (io::Error and every other exception: "PROGRAM: error: ..."), 2 bad
// command line ("PROGRAM: COMMAND: ...; see PROGRAM COMMAND --help", an unknown command or option
// named as such). `report` false: nothing is printed for a failure, the exit code still tells it
// (the processes of meshstream-mpi besides the first, whose first process says it once).
int run_command_line(CLI::App& app, const std::string& program, int argc, char** argv, bool report = true);

}  // namespace meshstream::tools
