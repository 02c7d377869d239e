// The `meshstream` command: parses the command line, runs one subcommand, and turns every
// failure into one diagnostic line and an exit code (0 ok, 1 failed, 2 bad command line).
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

int main(int argc, char** argv) {
    using namespace meshstream;
    CLI::App app{"meshstream: convert, sort and decimate triangle meshes larger than memory, in one streaming pass"};
    app.set_help_all_flag("--help-all", "Show help for every command");
    app.add_flag("-q,--quiet", tools::global().quiet, "No progress bar and no summary (warnings and errors stay)");
    app.set_version_flag("--version", std::string("meshstream ") + MESHSTREAM_VERSION);
    app.require_subcommand(1);
    // Subcommands pass options they do not know to the app, so -q works after the command too.
    app.fallthrough();
    tools::add_info(app);
    tools::add_convert(app);
    tools::add_decimate(app);
    tools::add_sort(app);
    tools::add_compare(app);

    io::install_cleanup_handlers();
    // CLI11 reports an unknown command as "A subcommand is required"; name it instead.
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.empty() || arg[0] == '-') continue;
        std::string names;
        bool known = false;
        for (const CLI::App* sub : app.get_subcommands({})) {
            known |= sub->get_name() == arg;
            names += (names.empty() ? "" : ", ") + sub->get_name();
        }
        if (!known) {
            std::fprintf(stderr, "meshstream: unknown command '%s' (one of: %s; see --help)\n", arg.c_str(),
                         names.c_str());
            return 2;
        }
        break;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        int code = app.exit(e);  // prints help (code 0) or the parse error
        return code == 0 ? 0 : 2;
    } catch (const tools::UsageError& e) {
        std::fprintf(stderr, "meshstream: error: %s\n", e.what());
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
