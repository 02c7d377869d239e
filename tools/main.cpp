// The `meshstream` command: its subcommands, run by run_command_line (one diagnostic line and an
// exit code for every failure: 0 ok, 1 failed, 2 bad command line).
#include "io/byte_stream.hpp"
#include "tools/cli_main.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"

#include <string>

int main(int argc, char** argv) {
    using namespace meshstream;
    CLI::App app{"convert, sort and decimate triangle meshes larger than memory, in one streaming pass", "meshstream"};
    tools::use_help_formatter(app);
    app.add_flag("-q,--quiet", tools::global().quiet, "no progress bar and no summary (warnings and errors stay)");
    app.set_version_flag("--version", std::string("meshstream ") + MESHSTREAM_VERSION, "print the version");
    app.require_subcommand(1);
    // Subcommands pass options they do not know to the app, so -q works after the command too.
    app.fallthrough();
    tools::add_info(app);
    tools::add_convert(app);
    tools::add_decimate(app);
    tools::add_sort(app);
    tools::add_compare(app);
#if MESHSTREAM_WITH_GLTF
    tools::add_tiles(app);
#endif
    app.footer(
        "  meshstream decimate scan.ply scan.glb -r 0.01\n"
        "  meshstream COMMAND --help   (the command's options; docs/cli.md has the details)");

    io::install_cleanup_handlers();
    return tools::run_command_line(app, "meshstream", argc, argv);
}
