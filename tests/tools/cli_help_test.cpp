// The help screens and command-line errors of `meshstream` (MESHSTREAM_BINARY) and
// `meshstream-gen` (MESHSTREAM_GEN_BINARY), for every command: --help fits a screen (at most 30
// lines, one line an option, an example), --help-all holds the options --help leaves out, no
// parser type noise and no binary path, and every command-line error is one line that starts
// with the program and the command, with exit code 2.
#include "cli_util.hpp"

#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace cli_test;

const char* const kCommands[] = {"info", "convert", "decimate", "sort", "compare"};

// The positional arguments each command takes.
int positionals(const std::string& cmd) { return cmd == "info" ? 1 : 2; }

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

struct Output {
    int code;
    std::string out, err;
};

// Runs `binary args` with stdout captured.
Output run_with_stdout(const std::string& binary, const std::string& args) {
    TempDir dir;
    const std::string cmd = binary + " " + args + " > " + dir / "out" + " 2> " + dir / "err";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(dir / "out"), slurp(dir / "err")};
}

// CLI11's own value names and annotations ("UINT:N >= 0=1", "TEXT:FILE", "REQUIRED", ...).
const std::regex kParserNoise(
    R"(\b(TEXT|UINT|INT|FLOAT|BOOLEAN|REQUIRED|Excludes|Needs)\b|\[Option Group|Positionals:|=[0-9]|>= [0-9]|in \[)");

// What a --help screen must be: `title` first, `usage` next, at most 30 lines of at most 100
// characters, no parser noise, no path of the binary, an example running `example_start`.
void expect_screen(const std::string& help, const std::string& binary, const std::string& title,
                   const std::string& usage, const std::string& example_start) {
    const std::vector<std::string> lines = lines_of(help);
    ASSERT_GE(lines.size(), 4u) << help;
    EXPECT_LE(lines.size(), 30u) << help;
    EXPECT_EQ(lines[0].rfind(title, 0), 0u) << help;
    EXPECT_EQ(lines[1].rfind(usage, 0), 0u) << help;
    for (const std::string& line : lines) EXPECT_LE(line.size(), 100u) << line;
    EXPECT_FALSE(std::regex_search(help, kParserNoise)) << help;
    EXPECT_EQ(help.find(binary), std::string::npos) << help;
    const size_t example = help.find("\nExample:\n");
    ASSERT_NE(example, std::string::npos) << help;
    EXPECT_EQ(help.compare(example + 10, example_start.size(), example_start), 0) << help;
}

// The option lines of a help screen, one an option: "  -r, --ratio P  description".
std::vector<std::string> option_lines(const std::string& help) {
    std::vector<std::string> out;
    for (const std::string& line : lines_of(help))
        if (line.rfind("  -", 0) == 0) out.push_back(line);
    return out;
}

TEST(CliHelp, EveryCommandsHelpFitsAScreenAndHelpAllHasTheRest) {
    for (const std::string cmd : kCommands) {
        SCOPED_TRACE(cmd);
        const Output help = run_with_stdout(MESHSTREAM_BINARY, cmd + " --help");
        ASSERT_EQ(help.code, 0) << help.err;
        EXPECT_EQ(help.err, "");
        expect_screen(help.out, MESHSTREAM_BINARY, "meshstream " + cmd + ": ",
                      "Usage: meshstream " + cmd + " [OPTIONS] ", "  meshstream " + cmd + " ");
        // The options section: each option on one line (no continuation lines), with -q and
        // --help, which says where the rest is.
        const size_t options = help.out.find("\nOptions:\n");
        ASSERT_NE(options, std::string::npos) << help.out;
        const std::string section = help.out.substr(options + 10, help.out.find("\n\n", options + 1) - options - 10);
        for (const std::string& line : lines_of(section)) EXPECT_EQ(line.rfind("  -", 0), 0u) << line;
        EXPECT_NE(section.find("  -q, --quiet "), std::string::npos) << section;
        EXPECT_NE(section.find("  -h, --help "), std::string::npos) << section;
        EXPECT_NE(section.find("--help-all"), std::string::npos) << section;
        EXPECT_NE(section.find("  --memory SIZE "), std::string::npos) << section;
        EXPECT_NE(section.find("(default 256M"), std::string::npos) << section;

        // --help-all: every option --help lists, every one it names under "More options", and
        // the details of their descriptions.
        const Output all = run_with_stdout(MESHSTREAM_BINARY, cmd + " --help-all");
        ASSERT_EQ(all.code, 0) << all.err;
        EXPECT_FALSE(std::regex_search(all.out, kParserNoise)) << all.out;
        EXPECT_EQ(all.out.find(MESHSTREAM_BINARY), std::string::npos) << all.out;
        for (const std::string& line : option_lines(section)) {
            const std::string label = line.substr(0, line.find("  ", 2));
            EXPECT_NE(all.out.find(label), std::string::npos) << label;
        }
        const size_t more = help.out.find("\nMore options (meshstream " + cmd + " --help-all): ");
        ASSERT_NE(more, std::string::npos) << help.out;
        std::istringstream names(help.out.substr(help.out.find("): ", more) + 3));
        int hidden = 0;
        for (std::string name; names >> name;) {
            if (name.back() == ',') name.pop_back();
            EXPECT_NE(all.out.find("\n  " + name + " "), std::string::npos) << name << "\n" << all.out;
            EXPECT_EQ(help.out.find("\n  " + name + " "), std::string::npos) << name;
            ++hidden;
        }
        EXPECT_GE(hidden, 3);
        EXPECT_EQ(all.out.find("More options ("), std::string::npos);
        // And the rest of the descriptions, under their first lines.
        EXPECT_GT(lines_of(all.out).size(), lines_of(help.out).size() + hidden + 5) << all.out;
    }
}

TEST(CliHelp, ProgramHelpListsTheCommandsOneLineEach) {
    const Output help = run_with_stdout(MESHSTREAM_BINARY, "--help");
    ASSERT_EQ(help.code, 0) << help.err;
    expect_screen(help.out, MESHSTREAM_BINARY, "meshstream: ", "Usage: meshstream ", "  meshstream ");
    for (const std::string cmd : kCommands)
        EXPECT_TRUE(std::regex_search(help.out, std::regex("\n  " + cmd + " +[a-zA-Z][^\n]+\n"))) << cmd << "\n"
                                                                                                  << help.out;
    EXPECT_NE(help.out.find("  --version "), std::string::npos) << help.out;
    // --help-all: the program's help and every command's, in full.
    const Output all = run_with_stdout(MESHSTREAM_BINARY, "--help-all");
    ASSERT_EQ(all.code, 0) << all.err;
    EXPECT_EQ(all.out.rfind(help.out, 0), 0u) << all.out;
    for (const std::string cmd : kCommands)
        EXPECT_NE(all.out.find("\nUsage: meshstream " + cmd + " [OPTIONS]"), std::string::npos) << cmd;
    EXPECT_NE(all.out.find("\n  --draco-qp N "), std::string::npos);
}

TEST(CliHelp, EveryCommandLineErrorNamesTheProgramAndTheCommand) {
    TempDir dir;
    for (const std::string cmd : kCommands) {
        SCOPED_TRACE(cmd);
        const std::string see = "; see meshstream " + cmd + " --help\n";
        std::string args;  // as many files as the command takes (they are never opened)
        for (const char* name : {"f0.stl", "f1.stl"})
            if (args.empty() || positionals(cmd) == 2) {
                args += ' ';
                args += dir / name;
            }
        // An unknown option is named as such, with or without the files, before or after them,
        // and with a value attached; -q of the program is known after the command too.
        for (const std::string& line : {cmd + " --foo", cmd + args + " --foo", cmd + " --foo=3" + args,
                                        "-q " + cmd + " --foo" + args, cmd + " -q --foo" + args}) {
            CliRun r = run(line);
            EXPECT_EQ(r.code, 2) << line;
            EXPECT_EQ(r.err, "meshstream: " + cmd + ": unknown option --foo" + see) << line;
        }
        // An option's value is not taken for an unknown option ("-1"), and "-" is a file.
        CliRun value = run(cmd + " --tmpdir -1 - --bar");
        EXPECT_EQ(value.err, "meshstream: " + cmd + ": unknown option --bar" + see);
        CliRun missing = run(cmd);
        EXPECT_EQ(missing.code, 2);
        EXPECT_EQ(missing.err, "meshstream: " + cmd + ": " +
                                   (cmd == "info"      ? "FILE"
                                    : cmd == "compare" ? "A"
                                                       : "IN") +
                                   " is required" + see);
        CliRun extra = run(cmd + args + " surplus.stl");
        EXPECT_EQ(extra.code, 2);
        EXPECT_EQ(extra.err, "meshstream: " + cmd + ": unexpected argument 'surplus.stl'" + see);
        CliRun no_value = run(cmd + args + " --memory");
        EXPECT_EQ(no_value.code, 2);
        EXPECT_EQ(no_value.err, "meshstream: " + cmd + ": --memory needs a value" + see);
        CliRun bad_value = run(cmd + args + " --memory 12Q");
        EXPECT_EQ(bad_value.code, 2);
        EXPECT_EQ(bad_value.err,
                  "meshstream: " + cmd + ": --memory: unknown size suffix in '12Q' (use K, M, G or T)" + see);
    }
    CliRun excl = run("decimate -r 0.5 --target 10 a.stl b.stl");
    EXPECT_EQ(excl.code, 2);
    EXPECT_EQ(excl.err,
              "meshstream: decimate: --ratio and --target cannot be given together; see meshstream decimate --help\n");
    // A command line that cannot work, found after parsing, names the command too.
    CliRun usage = run("convert " + dir / "f.stl" + " " + dir / "out.xyz");
    EXPECT_EQ(usage.code, 2);
    EXPECT_EQ(usage.err.rfind("meshstream: convert: " + dir / "out.xyz" + ": cannot tell the output format", 0), 0u)
        << usage.err;
    // Before any command.
    CliRun unknown = run("--foo");
    EXPECT_EQ(unknown.code, 2);
    EXPECT_EQ(unknown.err, "meshstream: unknown option --foo; see meshstream --help\n");
    CliRun none = run("");
    EXPECT_EQ(none.code, 2);
    EXPECT_EQ(none.err,
              "meshstream: no command given (one of: info, convert, decimate, sort, compare, tiles); see meshstream --help\n");
    CliRun typo = run("decimat in.stl out.stl");
    EXPECT_EQ(typo.code, 2);
    EXPECT_EQ(typo.err,
              "meshstream: unknown command 'decimat' (one of: info, convert, decimate, sort, compare, tiles); see meshstream "
              "--help\n");
}

TEST(CliHelp, GenHasVersionHelpAndTheSameExitCodes) {
    const Output version = run_with_stdout(MESHSTREAM_GEN_BINARY, "--version");
    EXPECT_EQ(version.code, 0) << version.err;
    EXPECT_TRUE(std::regex_match(version.out, std::regex("meshstream-gen [0-9]+\\.[0-9]+\\.[0-9]+\n"))) << version.out;
    const Output mine = run_with_stdout(MESHSTREAM_BINARY, "--version");
    EXPECT_EQ(version.out.substr(version.out.find(' ')), mine.out.substr(mine.out.find(' ')));

    const Output help = run_with_stdout(MESHSTREAM_GEN_BINARY, "--help");
    ASSERT_EQ(help.code, 0) << help.err;
    expect_screen(help.out, MESHSTREAM_GEN_BINARY, "meshstream-gen: ", "Usage: meshstream-gen [OPTIONS] OUTPUT",
                  "  meshstream-gen ");
    for (const char* option : {"  -n, --triangles N ", "  --seed N ", "  --shuffle ", "  --holes ", "  --to FMT ",
                               "  --version ", "  -h, --help "})
        EXPECT_NE(help.out.find(option), std::string::npos) << option << "\n" << help.out;

    TempDir dir;
    auto gen = [](const std::string& args) { return run_with_stdout(MESHSTREAM_GEN_BINARY, args); };
    const std::string see = "; see meshstream-gen --help\n";
    Output unknown = gen("--foo " + dir / "x.stl");
    EXPECT_EQ(unknown.code, 2);
    EXPECT_EQ(unknown.err, "meshstream-gen: unknown option --foo" + see);
    Output missing = gen("-n 1000");
    EXPECT_EQ(missing.code, 2);
    EXPECT_EQ(missing.err, "meshstream-gen: OUTPUT is required" + see);
    Output no_value = gen(dir / "x.stl" + " --seed");
    EXPECT_EQ(no_value.code, 2);
    EXPECT_EQ(no_value.err, "meshstream-gen: --seed needs a value" + see);
    Output bad_to = gen("--to foo " + dir / "x.stl");
    EXPECT_EQ(bad_to.code, 2);
    EXPECT_EQ(bad_to.err.rfind("meshstream-gen: --to: unknown output format 'foo' (one of: ", 0), 0u) << bad_to.err;
    Output extension = gen("-n 1000 " + dir / "x.unknown");
    EXPECT_EQ(extension.code, 2);
    EXPECT_EQ(extension.err.rfind("meshstream-gen: " + dir / "x.unknown" + ": cannot tell the output format", 0), 0u)
        << extension.err;
    // A failure while working is exit 1 with "error:".
    Output failed = gen("-q -n 1000 " + dir / "no_such_dir/x.stl");
    EXPECT_EQ(failed.code, 1);
    EXPECT_EQ(failed.err.rfind("meshstream-gen: error: " + dir / "no_such_dir/x.stl", 0), 0u) << failed.err;
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{});
}

}  // namespace
