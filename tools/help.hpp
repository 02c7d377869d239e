// The help screens and command-line errors of `meshstream` and `meshstream-gen`.
//
// `CMD --help` fits a screen: the command's one-line description, its usage, the options in
// the group "Options" one line each (value name, first line of the description), the example
// (the command's footer) and the names of the other options; `--help-all` adds those options,
// grouped, with the rest of their descriptions. Value names are the ones set with type_name()
// (SIZE, N, FMT), never a parser's type ("UINT:N >= 0"); defaults are written in the
// descriptions. The usage line names the program, never the path it was run by.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <string_view>

namespace meshstream::tools {

// Options in this group are listed by --help-all only (by --help by name).
inline constexpr const char* kMoreOptions = "More options";
// Draco and glTF output options: a group of their own, listed by --help-all.
inline constexpr const char* kWebOptions = "Draco and glTF output";

// The line under the usage of the commands that read IN and write OUT.
inline const std::string kInOutText =
    "IN, OUT: mesh files, '-' for stdin/stdout; formats by content, then extension; *.gz is gzip";

class HelpFormatter : public CLI::Formatter {
public:
    std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override;
};

// Gives `app` (and the subcommands added after) the formatter above, -h/--help and --help-all.
void use_help_formatter(CLI::App& app);

// The first argument that looks like an option (starts with '-', is not '-' alone, comes before
// any "--") and that neither the program nor `command` (empty: none) knows, or "" when there is
// none. Checked before parsing, so that an unknown option is named even when a required
// argument is missing too.
std::string first_unknown_option(const CLI::App& app, const std::string& command, int argc, const char* const* argv);

// The one line printed for a command line that cannot be parsed, without the line end:
// "<program>: [<command>: ]<what>; see <program> [<command> ]--help". `command` is empty for an
// error before any command. An argument CLI11 did not expect is named as an unknown option
// (it starts with '-') or an unexpected argument.
std::string parse_error_line(const CLI::App& app, const CLI::ParseError& error, const std::string& program,
                             const std::string& command);
// "<program>: [<command>: ]<what>; see <program> [<command> ]--help".
std::string usage_error_line(const std::string& program, const std::string& command, const std::string& what);

}  // namespace meshstream::tools
