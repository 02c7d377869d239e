// One command line, parsed and run: see cli_main.hpp.
#include "tools/cli_main.hpp"

#include "io/error.hpp"
#include "tools/common.hpp"
#include "tools/help.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>

namespace meshstream::tools {

int run_command_line(CLI::App& app, const std::string& program, int argc, char** argv, bool report) {
    const char* p = program.c_str();
    auto say = [report](const std::string& line) {
        if (report) std::fprintf(stderr, "%s\n", line.c_str());
    };
    // The command: the first argument that is no option (the program's own options take no
    // value). CLI11 reports an unknown one as "A subcommand is required": name it instead.
    std::string names, command;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.empty() || arg[0] == '-') continue;
        const auto subs = app.get_subcommands([&arg](const CLI::App* sub) { return sub->get_name() == arg; });
        if (subs.empty()) {
            say(program + ": unknown command '" + arg + "' (one of: " + names + "); see " + program + " --help");
            return 2;
        }
        command = arg;
        break;
    }
    if (const std::string unknown = first_unknown_option(app, command, argc, argv); !unknown.empty()) {
        say(usage_error_line(program, command, "unknown option " + unknown));
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() != 0) {
            if (command.empty() && dynamic_cast<const CLI::RequiredError*>(&e) != nullptr)
                say(program + ": no command given (one of: " + names + "); see " + program + " --help");
            else
                say(parse_error_line(app, e, program, command));
            return 2;
        }
        if (report) app.exit(e);  // --help, --help-all, --version: on stdout, checked below
    } catch (const UsageError& e) {
        say(program + ": " + command + ": " + e.what());
        return 2;
    } catch (const io::OptionError& e) {  // a setting the libraries cannot work with: a bad command line
        say(program + ": " + command + ": " + e.describe(flag_name));
        return 2;
    } catch (const meshstream::Error& e) {  // io::Error and the rest of the libraries' failures
        say(program + ": error: " + e.describe(flag_name));
        return 1;
    } catch (const std::bad_alloc&) {
        say(program + ": error: out of memory");
        return 1;
    } catch (const std::exception& e) {
        say(program + ": error: " + describe_error(e));
        return 1;
    }
    // Reports and summaries printed to stdout (info, compare, --help) are output too: a full
    // disk or a closed pipe must not end in exit 0.
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
        if (report) std::fprintf(stderr, "%s: error: <stdout>: write failed: %s\n", p, std::strerror(errno));
        return 1;
    }
    return 0;
}

}  // namespace meshstream::tools
