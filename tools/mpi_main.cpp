// `meshstream-mpi decimate IN OUT ...`, run by mpirun: one decimation spread over the ranks of
// MPI_COMM_WORLD, one range of the input per rank (tools/mpi_processes.hpp). Rank 0 plans, runs
// the last range and the seam pass, writes the output and says everything the command says;
// the other ranks say nothing (their failures reach rank 0, which reports them). Same options as
// `meshstream decimate` but --threads; the output is the one `meshstream decimate --threads K`
// writes for K ranks.
#include "io/byte_stream.hpp"
#include "tools/cli_main.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"
#include "tools/mpi_processes.hpp"

#include <mpi.h>

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
    using namespace meshstream;
    int provided = 0;
    if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
        std::fprintf(stderr, "meshstream-mpi: error: MPI_Init_thread failed\n");
        return 1;
    }
    int code = 1;
    {
        tools::MpiProcesses processes;
        const bool first = processes.rank() == 0;
        CLI::App app{"decimate one mesh on the ranks of an MPI job (mpirun -n K), one range of the input each",
                     "meshstream-mpi"};
        tools::use_help_formatter(app);
        app.add_flag("-q,--quiet", tools::global().quiet, "no progress bar and no summary (warnings and errors stay)");
        app.set_version_flag("--version", std::string("meshstream-mpi ") + MESHSTREAM_VERSION, "print the version");
        app.require_subcommand(1);
        app.fallthrough();
        tools::add_decimate(app, &processes);
        app.footer(
            "  mpirun -n 4 meshstream-mpi decimate scan.ply scan.glb -r 0.01\n"
            "  (each rank opens IN by its name; rank 0 writes OUT; docs/cli.md has the details)");
        tools::global().program = "meshstream-mpi";
        // Rank 0 shows the progress and prints --help and --json.
        if (!first) tools::global().quiet = true;
        if (first || std::freopen("/dev/null", "w", stdout) != nullptr) {
            io::install_cleanup_handlers();
            code = tools::run_command_line(app, "meshstream-mpi", argc, argv, first);
        }
        // Rank 0 failed after handing out ranges and before releasing their ranks (which wait
        // for it): MPI_Finalize would wait for them for ever. Its output is already removed.
        if (processes.others_waiting()) MPI_Abort(MPI_COMM_WORLD, code != 0 ? code : 1);
    }
    MPI_Finalize();
    return code;
}
