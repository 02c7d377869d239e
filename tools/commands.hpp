// One add_<cmd>(CLI::App&) per subcommand file (CLI11's examples/subcom_in_files). Each
// registers its options and a callback that runs the command and throws io::Error on failure.
#pragma once

#include <CLI/CLI.hpp>

namespace meshstream::engine {
class RangeProcesses;
}

namespace meshstream::tools {

using engine::RangeProcesses;

void add_info(CLI::App& app);
void add_convert(CLI::App& app);
// `processes`: meshstream-mpi's, the input cut into one range per process (no --threads).
void add_decimate(CLI::App& app, RangeProcesses* processes = nullptr);
void add_sort(CLI::App& app);
void add_compare(CLI::App& app);
void add_tiles(CLI::App& app);

}  // namespace meshstream::tools
