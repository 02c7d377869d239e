// The `meshstream` command: parses the command line, runs one subcommand, and turns every
// failure into one diagnostic line and an exit code (0 ok, 1 failed, 2 bad command line).
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
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
    app.footer(
        "  meshstream decimate scan.ply scan.glb -r 0.01\n"
        "  meshstream COMMAND --help   (the command's options; docs/cli.md has the details)");

    io::install_cleanup_handlers();
    // The command: the first argument that is no option (the program's own options take no
    // value). CLI11 reports an unknown one as "A subcommand is required": name it instead.
    std::string names, command;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.empty() || arg[0] == '-') continue;
        const auto subs = app.get_subcommands([&arg](const CLI::App* sub) { return sub->get_name() == arg; });
        if (subs.empty()) {
            std::fprintf(stderr, "meshstream: unknown command '%s' (one of: %s); see meshstream --help\n", arg.c_str(),
                         names.c_str());
            return 2;
        }
        command = arg;
        break;
    }
    if (const std::string unknown = tools::first_unknown_option(app, command, argc, argv); !unknown.empty()) {
        std::fprintf(stderr, "%s\n",
                     tools::usage_error_line("meshstream", command, "unknown option " + unknown).c_str());
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() != 0) {
            if (command.empty() && dynamic_cast<const CLI::RequiredError*>(&e) != nullptr)
                std::fprintf(stderr, "meshstream: no command given (one of: %s); see meshstream --help\n",
                             names.c_str());
            else
                std::fprintf(stderr, "%s\n", tools::parse_error_line(app, e, "meshstream", command).c_str());
            return 2;
        }
        app.exit(e);  // --help, --help-all, --version: on stdout, checked below
    } catch (const tools::UsageError& e) {
        std::fprintf(stderr, "meshstream: %s: %s\n", command.c_str(), e.what());
        return 2;
    } catch (const meshstream::io::Error& e) {
        std::fprintf(stderr, "meshstream: error: %s\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "meshstream: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "meshstream: error: %s\n", e.what());
        return 1;
    }
    // Reports and summaries printed to stdout (info, compare, --help) are output too: a full
    // disk or a closed pipe must not end in exit 0.
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
        std::fprintf(stderr, "meshstream: error: <stdout>: write failed: %s\n", std::strerror(errno));
        return 1;
    }
    return 0;
}
