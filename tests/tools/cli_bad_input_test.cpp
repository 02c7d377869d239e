// The bad-input suite of issue 7 through the `meshstream` binary (MESHSTREAM_BINARY): bad files
// give exit 1, a `meshstream: error: <file>...` line and no output file; NaN and degenerate
// triangles are kept by convert and sort and dropped with counted warnings by --clean and
// decimate (errors for decimate with --strict); Ctrl-C during convert,
// sort and decimate leaves no temporary or partial file; a file-size limit (a full disk for
// the process) gives a clear error instead of death by SIGXFSZ.
#include "format_util.hpp"
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

using cli_test::binary_stl;
using cli_test::CliRun;
using cli_test::grid;
using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

// Replaces every `token` in `text` by `value`, scanning forward. Tokens are braced: a bare
// OUT replaced by a temporary directory that happened to be named ...-jOUT2b looped forever.
std::string expand(std::string text, const std::string& token, const std::string& value) {
    for (size_t at = 0; (at = text.find(token, at)) != std::string::npos; at += value.size())
        text.replace(at, token.size(), value);
    return text;
}

void write_file(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

TEST(CliBadInput, RandomBytesUnderEachExtensionExit1WithNoOutput) {
    TempDir dir;
    std::mt19937 rng(11);
    std::string bytes(8192, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    std::vector<std::string> exts = meshstream::test::readable_extensions();
    exts.push_back("stl.gz");
    for (const std::string& ext : exts) {
        const std::string in = dir / ("random." + ext);
        write_file(in, bytes);
        for (const char* cmd : {"convert", "sort --axis x", "decimate"}) {
            CliRun r = run(std::string(cmd) + " " + in + " " + dir / "out.ply");
            EXPECT_EQ(r.code, 1) << cmd << " " << ext << ": " << r.err;
            EXPECT_EQ(r.err.rfind("meshstream: error: " + in, 0), 0u) << r.err;
            EXPECT_EQ(listing(dir.path()), std::vector<std::string>{fs::path(in).filename().string()})
                << cmd << " " << ext;
        }
        fs::remove(in);
    }
}

TEST(CliBadInput, TruncatedAndLyingFilesExit1WithNoOutput) {
    TempDir dir;
    std::string stl = binary_stl(grid(4));
    write_file(dir / "cut.stl", stl.substr(0, stl.size() - 20));
    std::string lie = stl;
    lie[80] = char(lie[80] + 1);  // one triangle more than present
    write_file(dir / "lie.stl", lie);
    for (const char* in : {"cut.stl", "lie.stl"}) {
        for (const char* cmd : {"convert", "sort --axis x", "decimate"}) {
            CliRun r = run(std::string(cmd) + " " + dir / in + " " + dir / "out.obj");
            EXPECT_EQ(r.code, 1) << cmd << " " << in;
            EXPECT_NE(r.err.find(dir / in + ": byte 84: header promises"), std::string::npos) << r.err;
            EXPECT_FALSE(fs::exists(dir / "out.obj"));
        }
    }
    EXPECT_EQ(listing(dir.path()).size(), 2u);
}

// --report re-reads both files, so it cannot work with '-': refused before anything is read
// or written (not after the output has been written).
TEST(CliBadInput, DecimateReportWithAPipeIsRefusedBeforeAnyOutput) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    CliRun r = run("decimate --report -r 0.5 - " + dir / "out.stl" + " < " + dir / "in.stl");
    EXPECT_EQ(r.code, 2) << r.err;  // a command line that cannot work
    EXPECT_EQ(r.err.rfind("meshstream: decimate: <stdin>: --report needs to re-read both files", 0), 0u) << r.err;
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"});
    CliRun w = run("decimate --report -r 0.5 --to stl " + dir / "in.stl" + " -");
    EXPECT_EQ(w.code, 2) << w.err;
    EXPECT_EQ(w.err.rfind("meshstream: decimate: <stdout>: --report", 0), 0u) << w.err;
}

// issue 21 §4: an output that is an input (the same path, a symbolic link to it, a hard link:
// one device and inode) is refused with exit 2 before anything is written, by every command
// that writes; so is stdout redirected into an input, for info and compare too.
TEST(CliBadInput, AnOutputThatIsAnInputIsRefusedBeforeAnythingIsWritten) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    const std::string before = slurp(dir / "in.stl");
    fs::create_symlink(dir / "in.stl", dir / "link.stl");
    fs::create_hard_link(dir / "in.stl", dir / "hard.stl");
    const std::vector<std::string> entries = listing(dir.path());
    for (const std::string cmd :
         {"convert", "sort --axis x", "decimate -r 0.5", "decimate --report -r 0.5", "convert --to stream"}) {
        for (const std::string out : {"in.stl", "link.stl", "hard.stl"}) {
            CliRun r = run(cmd + " " + dir / "in.stl" + " " + dir / out);
            EXPECT_EQ(r.code, 2) << cmd << " > " << out << ": " << r.err;
            const std::string name = cmd.substr(0, cmd.find(' '));
            EXPECT_EQ(
                r.err.rfind("meshstream: " + name + ": " + dir / out + ": would overwrite the input " + dir / "in.stl",
                            0),
                0u)
                << r.err;
            EXPECT_EQ(r.err.find("through a link") != std::string::npos, out != "in.stl") << r.err;
            EXPECT_EQ(slurp(dir / "in.stl"), before) << cmd;
            EXPECT_EQ(listing(dir.path()), entries) << cmd;
        }
        if (cmd.find("--report") != std::string::npos || cmd.find("--to") != std::string::npos) continue;
        // stdout appended to the input: `meshstream ... - >> in.stl`.
        CliRun piped = run(cmd + " --to stl " + dir / "in.stl" + " - >> " + dir / "in.stl");
        EXPECT_EQ(piped.code, 2) << cmd << ": " << piped.err;
        EXPECT_NE(piped.err.find("<stdout>: would overwrite the input " + dir / "in.stl"), std::string::npos)
            << piped.err;
        EXPECT_EQ(slurp(dir / "in.stl"), before) << cmd;
    }
    for (const std::string& cmd : {"info " + dir / "in.stl", "compare " + dir / "in.stl" + " " + dir / "link.stl",
                                   "convert --to stl - " + dir / "out.stl < " + dir / "in.stl"}) {
        if (cmd.starts_with("convert")) {
            // stdin from the input, stdout elsewhere: nothing is overwritten.
            EXPECT_EQ(run(cmd).code, 0) << cmd;
            fs::remove(dir / "out.stl");
            continue;
        }
        CliRun r = run(cmd + " >> " + dir / "hard.stl");
        EXPECT_EQ(r.code, 2) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("<stdout>: would overwrite the input "), std::string::npos) << r.err;
        EXPECT_EQ(slurp(dir / "in.stl"), before) << cmd;
    }
    // Side files: a .gltf output whose .bin would be the input, and an output over the buffer
    // file an input .gltf reads.
    write_file(dir / "mesh.bin", binary_stl(grid(4)));
    CliRun side = run("convert --no-draco " + dir / "mesh.bin" + " " + dir / "mesh.gltf");
    EXPECT_EQ(side.code, 2) << side.err;
    EXPECT_NE(side.err.find(dir / "mesh.gltf: its side file " + dir / "mesh.bin" + " would overwrite the input " +
                            dir / "mesh.bin"),
              std::string::npos)
        << side.err;
    EXPECT_FALSE(fs::exists(dir / "mesh.gltf"));
    ASSERT_EQ(run("convert --no-draco " + dir / "in.stl" + " " + dir / "scene.gltf").code, 0);
    const std::string buffer = slurp(dir / "scene.bin");
    CliRun over = run("convert --to stl " + dir / "scene.gltf" + " " + dir / "scene.bin");
    EXPECT_EQ(over.code, 2) << over.err;
    EXPECT_NE(over.err.find(dir / "scene.bin: would overwrite " + dir / "scene.bin" + ", which the input " +
                            dir / "scene.gltf" + " reads"),
              std::string::npos)
        << over.err;
    EXPECT_EQ(slurp(dir / "scene.bin"), buffer);
    // stdin and stdout the same file.
    CliRun both = run("convert --to stl - - < " + dir / "in.stl" + " >> " + dir / "link.stl");
    EXPECT_EQ(both.code, 2) << both.err;
    EXPECT_NE(both.err.find("<stdout>: would overwrite the input <stdin>"), std::string::npos) << both.err;
    EXPECT_EQ(slurp(dir / "in.stl"), before);
}

// A text file cut inside its last number reads as valid: the warning names the file.
TEST(CliBadInput, TextInputWithoutAFinalLineEndIsWarnedAbout) {
    TempDir dir;
    write_file(dir / "cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3");
    for (const std::string command : {"convert", "sort --axis x", "decimate"}) {
        CliRun r = run(command + " " + dir / "cut.obj" + " " + dir / "out.stl");
        EXPECT_EQ(r.code, 0) << command << ": " << r.err;
        // (sort used to look at the header as it was before the input was read)
        EXPECT_NE(
            r.err.find("warning: " + dir / "cut.obj" +
                       ": the last line has no line end: the file may be cut short inside it (a truncated download "
                       "or pipe?): check its last face"),
            std::string::npos)
            << command << ": " << r.err;
    }
}

// Write options that do nothing for the output are named, not dropped in silence.
TEST(CliBadInput, GzipLevelForAnOutputThatIsNotGzipIsNoted) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    CliRun r = run("convert --gzip-level 9 " + dir / "in.stl" + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: --gzip-level applies to outputs named *.gz: ignored for " + dir / "out.stl"),
              std::string::npos)
        << r.err;
    CliRun piped = run("convert --gzip-level 1 --to stl " + dir / "in.stl" + " - > " + dir / "piped.stl");
    EXPECT_NE(piped.err.find("ignored for <stdout> (pipe it through gzip)"), std::string::npos) << piped.err;
    CliRun gz = run("convert --gzip-level 9 " + dir / "in.stl" + " " + dir / "out.stl.gz");
    EXPECT_EQ(gz.err.find("--gzip-level"), std::string::npos) << gz.err;
}

namespace {

// A command line that must be refused: the option added, the exit code, a part of the message.
struct Refusal {
    const char* option;
    int code;
    const char* message;
};

// Runs `command IN OUT OPTION` for each refusal (IN = dir/in.stl): the exit code and message
// as expected, and nothing written beside the input.
void expect_refusals(const TempDir& dir, const std::string& command, std::initializer_list<Refusal> refusals) {
    for (const Refusal& c : refusals) {
        CliRun r = run(command + " " + dir / "in.stl" + " " + dir / "out.stl " + c.option);
        EXPECT_EQ(r.code, c.code) << c.option << ": " << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.option << ": " << r.err;
        EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"}) << c.option;
    }
}

}  // namespace

TEST(CliBadInput, DecimateOptionValuesOutOfRangeAreRefusedClearly) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));  // 32 triangles
    expect_refusals(
        dir, "decimate",
        {
            {"--ratio 0", 2, "--ratio: must be a number in (0, 1], found '0'"},
            {"--ratio 1.5", 2, "--ratio: must be a number in (0, 1], found '1.5'"},
            {"--target 0", 2,
             "--target: must be a whole number of triangles from 1 to 18446744073709551615, found '0'"},
            {"--target -3", 2,
             "--target: must be a whole number of triangles from 1 to 18446744073709551615, found '-3'"},
            // used to be clamped to 2^64 - 1 and named as such
            {"--target 18446744073709551616", 2, "found '18446744073709551616'"},
            // used to wrap to 2^64 - 1, and larger ones were clamped to it
            {"--seed -1", 2, "--seed: must be a whole number from 0 to 18446744073709551615, found '-1'"},
            {"--seed 18446744073709551616", 2, "--seed: must be a whole number from 0 to 18446744073709551615"},
            // used to weld on a grid of 1 (a decimal comma) or of 1 (a unit)
            {"--weld 1,5", 2, "--weld: expected a number or a percentage, found '1,5'"},
            {"--weld 1mm", 2, "--weld: expected a number or a percentage, found '1mm'"},
            {"--weld 0.5.5%", 2, "--weld: expected a number or a percentage, found '0.5.5%'"},
            {"--target 33", 2, "in.stl: --target 33 is more than the 32 triangles of the input"},
            {"--sorted-axis w", 2, "--sorted-axis: must be x, y or z (or 0, 1, 2), found 'w'"},
        });
    // Axes by name (any case) or number; the target may equal the input count.
    for (const char* ok : {"--sorted-axis z", "--sorted-axis Y", "--sorted-axis 0 --target 32"}) {
        CliRun r = run("decimate " + dir / "in.stl" + " " + dir / "out.stl " + ok);
        EXPECT_EQ(r.code, 0) << ok << ": " << r.err;
    }
}

// info --order judges only what decimate can run; compare's and the generator's seeds are
// whole numbers as decimate's.
TEST(CliBadInput, InfoCompareAndGenOptionValuesOutOfRangeAreRefusedClearly) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
             // used to print "needs about 9223372036854775808", exit 0
             {"info --order --ratio nan " + dir / "in.stl", "--ratio: must be a number in (0, 1], found 'nan'"},
             {"info --order --ratio 0 " + dir / "in.stl", "--ratio: must be a number in (0, 1], found '0'"},
             {"info --order --buffer 0 " + dir / "in.stl", "--buffer: Value 0 not in range 16 to"},
             {"compare --seed -1 " + dir / "in.stl" + " " + dir / "in.stl", "--seed: must be a whole number from 0"}}) {
        CliRun r = run(args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    }
    const int gen =
        std::system((std::string(MESHSTREAM_GEN_BINARY) + " --seed -1 " + dir / "g.stl" + " 2>/dev/null").c_str());
    EXPECT_EQ(WEXITSTATUS(gen), 2);
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"});
}

TEST(CliBadInput, MemoryBudgetsThatAreNotSizesOrTooSmallAreRefusedClearly) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    expect_refusals(
        dir, "sort --axis x",
        {
            {"--memory nan", 2, "--memory: expected a size like 64M or 1G, got 'nan'"},
            {"--memory -5M", 2, "--memory: expected a size like 64M or 1G, got '-5M'"},
            {"--memory 12Q", 2, "--memory: unknown size suffix in '12Q'"},
            // used to be "out of memory" (a run buffer of the budget's size)
            {"--memory 100T", 2, "--memory: 100T is more than this machine's memory ("},
            // past 2^64 bytes: used to wrap round to "too small" (or a tiny budget)
            {"--memory 99999999999999999999", 2, "--memory: 99999999999999999999 is more than this machine's memory ("},
            {"--memory 16777216T", 2, "--memory: 16777216T is more than this machine's memory ("},
            // used to be "out of memory"
            {"--memory 1", 2, "in.stl: --memory 1 is too small to sort: give at least 97K"},
            {"--memory 96K", 2, "in.stl: --memory 96K is too small to sort: give at least 97K"},
        });
    CliRun ok = run("sort --axis x --memory 97K " + dir / "in.stl" + " " + dir / "out.stl");  // the least, exactly
    EXPECT_EQ(ok.code, 0) << ok.err;
    for (const std::string& cmd :
         {"info --topology " + dir / "in.stl", "compare " + dir / "in.stl" + " " + dir / "in.stl",
          "convert " + dir / "in.stl" + " " + dir / "o.ply"}) {
        for (const std::string size : {"100T", "1e30"}) {
            CliRun r = run(cmd + " --memory " + size);
            EXPECT_EQ(r.code, 2) << cmd;
            EXPECT_NE(r.err.find("--memory: " + size + " is more than this machine's memory"), std::string::npos)
                << r.err;
        }
    }
    CliRun order = run("info --order --memory 99999999999999999999 " + dir / "in.stl");
    EXPECT_EQ(order.code, 2) << order.err;
}

TEST(CliBadInput, InputWithoutTrianglesGivesAnEmptyOutputAndAWarning) {
    TempDir dir;
    write_file(dir / "none.obj", "# no faces\nv 0 0 0\n");
    for (const char* cmd : {"convert", "sort --axis x", "decimate"}) {
        CliRun r = run(std::string(cmd) + " " + dir / "none.obj" + " " + dir / "out.stl");
        EXPECT_EQ(r.code, 0) << cmd << ": " << r.err;
        EXPECT_NE(r.err.find("meshstream: warning: the input holds no triangles\n"), std::string::npos)
            << cmd << ": " << r.err;
        EXPECT_EQ(fs::file_size(dir / "out.stl"), 84u) << cmd;  // a valid STL of 0 triangles
        fs::remove(dir / "out.stl");
    }
}

// Unsorted input overflowing a small buffer: the decimator force-writes, and says how many
// triangles that cost and what to do about it (once, not as a counted event).
TEST(CliBadInput, ForcedWritesEndWithAWarningThatAdvisesSort) {
    TempDir dir;
    std::vector<float> tris = grid(24);  // 1152 triangles
    std::vector<size_t> order(tris.size() / 9);
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), std::mt19937(5));
    std::vector<float> shuffled;
    for (size_t i : order) shuffled.insert(shuffled.end(), tris.begin() + 9 * i, tris.begin() + 9 * i + 9);
    write_file(dir / "shuffled.stl", binary_stl(shuffled));
    CliRun r = run("decimate --sort never --buffer 64 -r 0.1 " + dir / "shuffled.stl" + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    const size_t at = r.err.find("meshstream: warning: buffer full of undecimatable triangles: ");
    ASSERT_NE(at, std::string::npos) << r.err;
    const std::string line = r.err.substr(at, r.err.find('\n', at) - at);
    EXPECT_NE(line.find("triangles force-written at full resolution ("), std::string::npos) << line;
    EXPECT_NE(line.find("near them a few triangles may come out twice, back to back)"), std::string::npos) << line;
    // So far out of order that written vertices are evicted: the cracks are owned up to.
    EXPECT_NE(line.find(" of their vertices were evicted from the weld table to make room, so triangles read later at "
                        "those positions are not joined to them (the output has cracks there)"),
              std::string::npos)
        << line;
    EXPECT_NE(
        line.find("either the input is not in streaming order (without --sort never decimate sorts it first; or "
                  "run `meshstream sort` on it) or the buffer is too small for it at this ratio (raise --buffer): "
                  "`meshstream info --order --ratio 0.1 --buffer 64` tells which"),
        std::string::npos)
        << line;
    EXPECT_NE(line.back(), ')') << line;  // no event count appended

    // Sorted input (here in row order, said by --sorted-axis) in a buffer below its width:
    // sorting again would not help, a larger buffer would.
    write_file(dir / "rows.stl", binary_stl(tris));
    CliRun s = run("decimate --buffer 40 --sorted-axis y -r 0.1 " + dir / "rows.stl" + " " + dir / "out2.stl");
    EXPECT_EQ(s.code, 0) << s.err;
    EXPECT_NE(s.err.find("; the input is sorted, so the buffer is too small for it at this ratio: raise --buffer "
                         "(`meshstream info --order --ratio 0.1 --buffer 40` estimates the buffer it needs)"),
              std::string::npos)
        << s.err;
    EXPECT_EQ(s.err.find("run `meshstream sort`"), std::string::npos) << s.err;
}

// A sorted axis the sweep cannot use is named: one the triangles never move along (the sweep
// never starts; raising --buffer, the advice for sorted input, would not help), and one that
// overrides the axis the file gives.
TEST(CliBadInput, ASortedAxisTheSweepCannotUseIsNamed) {
    TempDir dir;
    write_file(dir / "rows.stl", binary_stl(grid(24)));  // row order: sorted along y
    CliRun z = run("decimate --buffer 40 --sorted-axis z -r 0.1 " + dir / "rows.stl" + " " + dir / "out.stl");
    EXPECT_EQ(z.code, 0) << z.err;
    EXPECT_NE(
        z.err.find("; the input is said to be sorted along z, but its triangles never moved along it by more than "
                   "three of their lengths, so the sweep that finalizes hole boundaries never started: check the "
                   "axis (`meshstream info --order --ratio 0.1 --buffer 40` counts the key descents along each)"),
        std::string::npos)
        << z.err;
    EXPECT_EQ(z.err.find("raise --buffer"), std::string::npos) << z.err;
    EXPECT_NE(z.err.find("instead of the target 115 (the triangles force-written at full resolution, above, count "
                         "against it)"),
              std::string::npos)
        << z.err;

    ASSERT_EQ(run("sort --axis y " + dir / "rows.stl" + " " + dir / "y.stl").code, 0);
    CliRun x = run("decimate --buffer 40 --sorted-axis x -r 0.1 " + dir / "y.stl" + " " + dir / "out.stl");
    EXPECT_EQ(x.code, 0) << x.err;
    EXPECT_NE(x.err.find("meshstream: warning: --sorted-axis x was given, but " + dir / "y.stl" +
                         " says it is sorted along y: the sweep used x, as given\n"),
              std::string::npos)
        << x.err;
    EXPECT_NE(x.err.find("; --sorted-axis overrode the axis the file gives (see below)"), std::string::npos) << x.err;
    EXPECT_NE(x.err.find("leave out --sorted-axis to use the file's own axis"), std::string::npos) << x.err;
    EXPECT_EQ(x.err.find("meshstream sort"), std::string::npos) << x.err;
    // The file's own axis: no such warnings.
    CliRun y = run("decimate --buffer 40 -r 0.1 " + dir / "y.stl" + " " + dir / "out.stl");
    EXPECT_EQ(y.code, 0) << y.err;
    EXPECT_EQ(y.err.find("--sorted-axis"), std::string::npos) << y.err;
}

// Whole-mesh outputs (Draco, glTF) whose known size cannot fit --memory are refused before
// any work, not part way through a long decimation.
TEST(CliBadInput, WholeMeshOutputTooBigForTheBudgetIsRefusedUpFront) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(24)));  // 1152 triangles
    for (const char* out : {"out.drc", "out.glb"}) {
        CliRun r = run("decimate -r 1 --memory 100K " + dir / "in.stl" + " " + dir / out);
        EXPECT_EQ(r.code, 1) << out << ": " << r.err;
        EXPECT_NE(r.err.find(dir / out + ": "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("the 1152 triangles to be written need at least"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("over the memory budget of 100 KiB; give --memory 1M or more"), std::string::npos)
            << r.err;
        EXPECT_EQ(r.err.find("decimated "), std::string::npos) << "refused after the work: " << r.err;
        EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"}) << out;
    }
    CliRun c = run("convert --memory 100K " + dir / "in.stl" + " " + dir / "out.drc");
    EXPECT_EQ(c.code, 1) << c.err;
    EXPECT_NE(c.err.find("the 1152 triangles to be written need at least"), std::string::npos) << c.err;
    // Where it fits, it is written.
    CliRun ok = run("decimate -r 0.1 --memory 100K " + dir / "in.stl" + " " + dir / "out.drc");
    EXPECT_EQ(ok.code, 0) << ok.err;
}

// Draco's entropy coder takes about 4 bytes per quantized value (2^bits of them, 11 at levels
// 9-10): --draco-qp 28 took 1 GB on the bunny and 29 at level 10 5.8 GB, whatever --memory said.
TEST(CliBadInput, DracoBitCountsWhoseTablesPassTheBudgetAreRefusedUpFront) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    for (const char* out : {"out.drc", "out.glb"}) {
        for (const auto& [flags, message] : std::vector<std::pair<std::string, std::string>>{
                 {"--draco-qp 28 --memory 256M",
                  "Draco's coding tables for --draco-qp 28 at --draco-cl 7 take about 1 GiB (they "
                  "double with each bit), over the memory budget of 256 MiB: give fewer bits (float "
                  "positions hold 24) or --memory 1025M or more"},
                 {"--draco-qp 24 --draco-cl 10 --memory 150M", "take about 192 MiB"},
                 {"--normals --draco-qn 27 --memory 256M",
                  "Draco's coding tables for --draco-qp 14 and --draco-qn 27 at --draco-cl 7"},
             }) {
            CliRun r = run("convert " + flags + " " + dir / "in.stl" + " " + dir / out);
            EXPECT_EQ(r.code, 1) << flags << " " << out << ": " << r.err;
            EXPECT_NE(r.err.find(dir / out + ": " + (message[0] == 'D' ? message : "")), std::string::npos) << r.err;
            EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
            EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"}) << out;
        }
        CliRun ok = run("convert --draco-qp 24 " + dir / "in.stl" + " " + dir / out);
        EXPECT_EQ(ok.code, 0) << ok.err;
        fs::remove(dir / out);
    }
}

// --weld P% on a format without a stated bounding box (STL): a regular file is read twice,
// the box first; a stream cannot be, and says so.
TEST(CliBadInput, WeldPercentReadsTheBoxFirstOrRefusesAStream) {
    TempDir dir;
    const std::vector<float> tris = grid(6);
    write_file(dir / "in.stl", binary_stl(tris));
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t i = 0; i < tris.size(); ++i) {
        lo[i % 3] = std::min(lo[i % 3], tris[i]);
        hi[i % 3] = std::max(hi[i % 3], tris[i]);
    }
    double diag2 = 0;
    for (int a = 0; a < 3; ++a) diag2 += (double(hi[a]) - lo[a]) * (double(hi[a]) - lo[a]);
    char expected[64];
    std::snprintf(expected, sizeof expected, "  weld %.6g: ", 0.5 / 100 * std::sqrt(diag2));

    CliRun r = run("decimate -r 0.5 --weld 0.5% " + dir / "in.stl" + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << expected << " in: " << r.err;
    EXPECT_EQ(r.err.find("coarser than the mesh"), std::string::npos) << r.err;
    // A weld coarser than the triangles collapses most of them: said plainly.
    CliRun coarse = run("decimate -r 0.5 --weld 30% " + dir / "in.stl" + " " + dir / "coarse.stl");
    EXPECT_EQ(coarse.code, 0) << coarse.err;
    EXPECT_NE(coarse.err.find("warning: --weld 30% welded the corners of "), std::string::npos) << coarse.err;
    // Those triangles are gone, counted, and not in the summary's count (they used to pass
    // through: counted out, then dropped by Draco and glTF writers).
    EXPECT_NE(coarse.err.find("warning: triangles dropped because --weld merged their corners ("), std::string::npos)
        << coarse.err;
    const uint64_t written = (fs::file_size(dir / "coarse.stl") - 84) / 50;  // binary STL
    const size_t out_at = coarse.err.find(", out ");
    ASSERT_NE(out_at, std::string::npos) << coarse.err;
    EXPECT_EQ(std::stoull(coarse.err.substr(out_at + 6)), written) << coarse.err;
    CliRun glb = run("decimate -r 0.5 --weld 30% " + dir / "in.stl" + " " + dir / "coarse.glb");
    ASSERT_EQ(glb.code, 0) << glb.err;
    CliRun info = run("info " + dir / "coarse.glb" + " > " + dir / "info.txt");
    EXPECT_NE(slurp(dir / "info.txt").find("triangles:   " + std::to_string(written) + "\n"), std::string::npos)
        << slurp(dir / "info.txt");
    EXPECT_NE(coarse.err.find("it is coarser than the mesh; weld on a smaller size\n"), std::string::npos)
        << coarse.err;
    CliRun p = run("decimate -r 0.5 --weld 0.5% - " + dir / "piped.stl" + " < " + dir / "in.stl");
    EXPECT_EQ(p.code, 2) << p.err;
    EXPECT_NE(p.err.find("<stdin>: --weld 0.5% needs the bounding box"), std::string::npos) << p.err;
    EXPECT_FALSE(fs::exists(dir / "piped.stl"));
}

// A surface whose triangles share no corner (every corner moved a little, as float round-off
// or a triangle-by-triangle export leaves them) decimates to its count by eating surface from
// every crack: said, with the way out. The same surface welded says nothing of the kind.
TEST(CliBadInput, AnUnweldedSurfaceIsSaidToBeOne) {
    TempDir dir;
    std::vector<float> tris = grid(20);
    write_file(dir / "welded.stl", binary_stl(tris));
    for (size_t t = 0; t < tris.size() / 9; ++t)
        for (int k = 0; k < 3; ++k) tris[9 * t + 3 * k + 2] += 1e-6f * float(t + 1);
    write_file(dir / "cracked.stl", binary_stl(tris));
    CliRun cracked = run("decimate -r 0.1 " + dir / "cracked.stl" + " " + dir / "out.stl");
    EXPECT_EQ(cracked.code, 0) << cracked.err;
    EXPECT_NE(cracked.err.find("warning: 2400 edges had no partner, 3.0 per triangle: the triangles share few corners "
                               "exactly (an unwelded surface?)"),
              std::string::npos)
        << cracked.err;
    CliRun welded = run("decimate -r 0.1 " + dir / "welded.stl" + " " + dir / "out.stl");
    EXPECT_EQ(welded.code, 0) << welded.err;
    EXPECT_EQ(welded.err.find("had no partner"), std::string::npos) << welded.err;
    EXPECT_NE(cracked.err.find("--weld EPS snaps corners to a grid of EPS\n"), std::string::npos) << cracked.err;
}

// A mesh with faces wound against their neighbours keeps far more than its target; the
// warning blamed "too little left that could be decimated" instead of the frozen edges.
TEST(CliBadInput, AMissedTargetNamesTheFrozenEdgesThatCausedIt) {
    TempDir dir;
    std::vector<float> tris = grid(300);              // 180 000 triangles: too many at the end for a full scan
    for (size_t t = 0; t < tris.size() / 9; t += 97)  // one in 97 wound the other way
        std::swap_ranges(&tris[9 * t + 3], &tris[9 * t + 6], &tris[9 * t + 6]);
    write_file(dir / "in.stl", binary_stl(tris));
    CliRun r = run("decimate -r 0.01 " + dir / "in.stl" + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find(" non-manifold, duplicate or mis-oriented edges above are frozen with their vertices: faces "
                         "wound against their neighbours join none of them)"),
              std::string::npos)
        << r.err;
}

TEST(CliBadInput, CommandLinesThatCannotWorkExit2BeforeAnyWork) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    write_file(dir / "in.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const std::string in = dir / "in.stl", out = dir / "out.stl";
    const struct {
        std::string args;
        const char* message;
    } cases[] = {
        {"convert " + in + " " + out + " --to foo", "--to: unknown output format 'foo' (one of: draco, glb"},
        // used to do the whole job, then fail to rename "<input>: … .tmp-XXXXXX into place" (exit 1)
        {"convert " + in + " '' --to glb", "the output name is empty"},
        {"convert " + in + " " + out + " --from foo", "--from: unknown input format 'foo'"},
        {"convert " + in + " -", "<stdout>: writing to stdout needs --to unless it is a pipe (one of: draco"},
        {"decimate -r 0.5 " + in + " -", "<stdout>: writing to stdout needs --to"},
        {"sort --axis x " + in + " -", "<stdout>: writing to stdout needs --to"},
        {"sort - " + out + " < " + in, "<stdin>: --axis auto reads the input twice"},
        {"compare - - < " + in, "compare cannot read both A and B from stdin or pipes"},
        {"decimate --report -r 0.5 " + in + " /dev/null --to stl", "/dev/null: --report needs to re-read both files"},
        {"decimate --target 1 - " + out + " < " + dir / "in.obj",
         "<stdin>: --target needs the input triangle count, which obj does not state up front"},
        {"sort --axis x " + in + " " + dir / "s.glb", "s.glb: Draco compression reorders triangles"},
        {"sort --axis x " + in + " - --to draco", "<stdout>: Draco compression reorders triangles"},
        {"convert --draco-qn 1 " + in + " " + dir / "c.drc", "--draco-qn: Value 1 not in range 2 to 30"},
    };
    for (const auto& c : cases) {
        CliRun r = run(c.args);
        EXPECT_EQ(r.code, 2) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
        EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"in.obj", "in.stl"})) << c.args;
    }
}

TEST(CliBadInput, CompareHoldsAMeshFromAPipe) {
    // A pipe cannot be opened once for its count and then again: it is the held mesh, as '-'.
    TempDir dir;
    write_file(dir / "small.stl", binary_stl(grid(2)));
    write_file(dir / "big.stl", binary_stl(grid(6)));
    ASSERT_EQ(::mkfifo((dir / "pipe").c_str(), 0600), 0);
    for (const bool pipe_is_a : {false, true}) {
        const std::string a = pipe_is_a ? dir / "pipe" : dir / "small.stl";
        const std::string b = pipe_is_a ? dir / "small.stl" : dir / "pipe";
        CliRun r = run("compare --json --samples 1000 " + a + " " + b + " > " + dir / "r.json",
                       "cat " + dir / "big.stl" + " > " + dir / "pipe" + " &");
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string json = slurp(dir / "r.json");
        EXPECT_NE(json.find("\"triangles\": 72"), std::string::npos) << json;  // the piped mesh, whole
    }
}

TEST(CliBadInput, StdoutWriteFailuresExit1) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    for (const std::string& cmd :
         {std::string("info --json "), "compare --json --samples 1000 " + dir / "in.stl" + " "}) {
        CliRun r = run(cmd + dir / "in.stl" + " > /dev/full");
        EXPECT_EQ(r.code, 1) << cmd << r.err;
        EXPECT_NE(r.err.find("meshstream: error: <stdout>: write failed: No space left on device"), std::string::npos)
            << cmd << r.err;
    }
}

TEST(CliBadInput, ABufferTheSystemCannotReserveIsNamedWithItsSize) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves terabytes of shadow memory: no address-space limit possible";
#else
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(4)));
    // 1 GiB of address space; --buffer 10000000 reserves about 5 GB.
    CliRun r = run("decimate --buffer 10000000 -r 0.5 " + dir / "in.stl" + " " + dir / "out.stl", "ulimit -v 1048576;");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("meshstream: error: --buffer 10000000 reserves 5."), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("which this system refused: give a smaller --buffer (the default 400000 reserves 233.5 MB)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.stl"});
#endif
}

TEST(CliBadInput, UnknownCommandIsNamedAndVersionIsPrinted) {
    CliRun r = run("decimat in.stl out.stl");
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err,
              "meshstream: unknown command 'decimat' (one of: info, convert, decimate, sort, compare, tiles); see meshstream "
              "--help\n");
    TempDir dir;
    CliRun v = run("--version > " + dir / "version.txt");
    EXPECT_EQ(v.code, 0) << v.err;
    EXPECT_EQ(slurp(dir / "version.txt").rfind("meshstream ", 0), 0u) << slurp(dir / "version.txt");
}

// convert and sort keep every triangle (issue 21: a converter does not edit geometry unasked);
// --clean drops NaN/inf and degenerate ones with counted warnings, and decimate, which cannot
// use them, skips them the same way (an error with --strict).
TEST(CliBadInput, NanAndDegenerateTrianglesAreKeptOrDroppedWithCountedWarnings) {
    TempDir dir;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::vector<float> tris = grid(3);  // 18 good triangles
    tris.insert(tris.end(), {0, 0, 0, 1, 0, 0, nan, 1, 0});
    tris.insert(tris.end(), {0, 0, 0, inf, 0, 0, 0, 1, 0});
    tris.insert(tris.end(), {0, 0, 0, 1, 0, 0, 1, 0, 0});      // two corners at one position
    tris.insert(tris.end(), {-0.0f, 0, 0, 0, 0, 0, 5, 5, 5});  // -0 == +0: also degenerate
    write_file(dir / "bad.stl", binary_stl(tris));

    // Lossless by default: the same 22 triangles, bit for bit (only the zero normals differ).
    CliRun kept = run("convert " + dir / "bad.stl" + " " + dir / "kept.stl");
    ASSERT_EQ(kept.code, 0) << kept.err;
    EXPECT_EQ(kept.err.find("warning"), std::string::npos) << kept.err;
    ASSERT_EQ(fs::file_size(dir / "kept.stl"), 84u + 50u * 22u);
    const std::string in_bytes = slurp(dir / "bad.stl"), kept_bytes = slurp(dir / "kept.stl");
    for (size_t t = 0; t < 22; ++t)
        EXPECT_EQ(kept_bytes.substr(84 + 50 * t + 12, 36), in_bytes.substr(84 + 50 * t + 12, 36)) << "triangle " << t;
    CliRun sorted_all = run("sort --axis x " + dir / "bad.stl" + " " + dir / "sorted_all.stl");
    ASSERT_EQ(sorted_all.code, 0) << sorted_all.err;
    EXPECT_EQ(fs::file_size(dir / "sorted_all.stl"), 84u + 50u * 22u);

    CliRun c = run("convert --clean " + dir / "bad.stl" + " " + dir / "out.stl");
    ASSERT_EQ(c.code, 0) << c.err;
    EXPECT_NE(c.err.find("warning: triangles with a NaN or infinite coordinate removed (--clean) (2)"),
              std::string::npos)
        << c.err;
    EXPECT_NE(c.err.find("warning: degenerate triangles (two corners at the same position) removed (--clean) (2)"),
              std::string::npos)
        << c.err;
    EXPECT_EQ(fs::file_size(dir / "out.stl"), 84u + 50u * 18u);  // header count patched to 18
    // To stdout nothing can be patched: formats with a count first spool until they know it.
    for (const char* to : {"stl", "ply"}) {
        CliRun p = run("convert --clean " + dir / "bad.stl" + " - --to " + to + " > " + dir / "piped");
        ASSERT_EQ(p.code, 0) << to << ": " << p.err;
        CliRun back = run("convert --from " + std::string(to) + " " + dir / "piped" + " " + dir / "back.stl");
        ASSERT_EQ(back.code, 0) << back.err;
        EXPECT_EQ(slurp(dir / "back.stl"), slurp(dir / "out.stl")) << to;
    }
    fs::remove(dir / "piped");
    fs::remove(dir / "back.stl");

    CliRun s = run("sort --clean --axis x " + dir / "bad.stl" + " " + dir / "sorted.stl");
    ASSERT_EQ(s.code, 0) << s.err;
    EXPECT_NE(s.err.find("removed (--clean) (2)"), std::string::npos) << s.err;
    EXPECT_EQ(fs::file_size(dir / "sorted.stl"), 84u + 50u * 18u);

    CliRun d = run("decimate --ratio 0.5 " + dir / "bad.stl" + " " + dir / "dec.stl");
    ASSERT_EQ(d.code, 0) << d.err;
    EXPECT_NE(d.err.find("warning: triangles with a NaN or infinite coordinate skipped (2)"), std::string::npos)
        << d.err;
    EXPECT_NE(d.err.find("triangles in 18,"), std::string::npos) << d.err;

    // decimate --strict: the first one is an error naming the file and the triangle; nothing
    // is written. convert and sort --strict keep them (an STL holds them).
    CliRun r = run("decimate --strict " + dir / "bad.stl" + " " + dir / "strict.stl");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("meshstream: error: " + dir / "bad.stl" +
                         ": triangle 19 has a NaN or infinite coordinate (--strict)"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "strict.stl"));
    for (const char* cmd : {"convert", "sort --axis x"}) {
        CliRun k = run(std::string(cmd) + " --strict " + dir / "bad.stl" + " " + dir / "strict.stl");
        EXPECT_EQ(k.code, 0) << cmd << ": " << k.err;
        EXPECT_EQ(fs::file_size(dir / "strict.stl"), 84u + 50u * 22u) << cmd;
    }
    // info and compare report the file as it is; --strict makes the same triangle an error.
    for (const std::string& cmd : {"info " + dir / "bad.stl", "compare " + dir / "bad.stl" + " " + dir / "bad.stl"}) {
        EXPECT_EQ(run(cmd).code, 0) << cmd;
        CliRun e = run(cmd + " --strict");
        EXPECT_EQ(e.code, 1) << cmd;
        EXPECT_NE(e.err.find(dir / "bad.stl" + ": triangle 19 has a NaN or infinite coordinate (--strict)"),
                  std::string::npos)
            << e.err;
    }
}

TEST(CliBadInput, HelpDescribesTheSkipPolicy) {
    auto help_of = [](const char* cmd) {
        char out_path[] = "/tmp/cli_bad_input_help-XXXXXX";
        ::close(::mkstemp(out_path));
        std::system((std::string(MESHSTREAM_BINARY) + " " + cmd + " --help-all > " + out_path).c_str());
        std::string help = slurp(out_path);
        ::unlink(out_path);
        return help;
    };
    {
        const std::string help = help_of("decimate");
        // Long descriptions are wrapped; look for the key words.
        EXPECT_NE(help.find("--strict"), std::string::npos);
        EXPECT_NE(help.find("NaN/inf"), std::string::npos) << help;
        EXPECT_NE(help.find("skipped with a"), std::string::npos) << help;
    }
    for (const char* cmd : {"convert", "sort"}) {  // lossless: only --clean drops
        const std::string help = help_of(cmd);
        EXPECT_NE(help.find("--clean"), std::string::npos) << cmd;
        EXPECT_NE(help.find("every triangle is kept"), std::string::npos) << cmd << help;
        EXPECT_EQ(help.find("skipped with a"), std::string::npos) << cmd << help;
    }
    for (const char* cmd : {"info", "compare"}) {  // no skipping there: --strict only adds errors
        const std::string help = help_of(cmd);
        EXPECT_NE(help.find("--strict"), std::string::npos) << cmd;
        EXPECT_EQ(help.find("skipped with a"), std::string::npos) << cmd << help;
        EXPECT_NE(help.find("an error"), std::string::npos) << cmd << help;
    }
}

// Ctrl-C while the command is mid-stream: the input comes through a pipe that the test holds
// open, so the command is provably still running (blocked reading) when SIGINT arrives.
TEST(CliBadInput, SigintDuringConvertSortDecimateLeavesNoFiles) {
    const std::string stl = binary_stl(grid(200));  // 80000 triangles, 4 MB
    for (const char* args :
         {"convert --from stl - {OUT}/out.ply", "sort --from stl --axis x --memory 1M --tmpdir {OUT} - {OUT}/out.stl",
          "decimate --from stl --ratio 0.2 - {OUT}/out.stl"}) {
        TempDir dir;
        const std::string cmdline = expand(args, "{OUT}", dir.path().string());
        int fds[2];
        ASSERT_EQ(::pipe(fds), 0);
        pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            ::dup2(fds[0], 0);
            ::close(fds[0]);
            ::close(fds[1]);
            int devnull = ::open("/dev/null", O_WRONLY);
            ::dup2(devnull, 2);
            std::string full = std::string("exec ") + MESHSTREAM_BINARY + " -q " + cmdline;
            ::execl("/bin/sh", "sh", "-c", full.c_str(), static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(fds[0]);
        // Three quarters of the input, then wait until the command has created its files.
        const size_t part = stl.size() * 3 / 4;
        for (size_t done = 0; done < part;) {
            ssize_t n = ::write(fds[1], stl.data() + done, part - done);
            ASSERT_GT(n, 0);
            done += size_t(n);
        }
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (listing(dir.path()).empty() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        EXPECT_FALSE(listing(dir.path()).empty()) << args << ": no temporary file appeared";
        ::kill(pid, SIGINT);
        int status = 0;
        ::waitpid(pid, &status, 0);
        ::close(fds[1]);
        EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << args << ": status " << status;
        EXPECT_EQ(listing(dir.path()), std::vector<std::string>{}) << args;
    }
}

// A reader that stops early (`| head`) kills the command with SIGPIPE, mid-output: like Ctrl-C,
// that must remove the temporary files (a stdout spool, the PLY writer's corner table, sort
// runs), and the command still dies quietly by the signal, as UNIX filters do.
TEST(CliBadInput, ClosedOutputPipeLeavesNoTemporaryFiles) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(200)));  // 80000 triangles, 4 MB
    fs::create_directory(dir / "t");
    for (const char* args : {"convert {IN} - --to stl", "convert {IN} - --to ply",
                             "sort --axis x --memory 1M --tmpdir {T} {IN} - --to stl"}) {
        const std::string cmdline = expand(expand(args, "{IN}", dir / "in.stl"), "{T}", dir / "t");
        const std::string status = dir / "status";
        const std::string sh = "{ TMPDIR=" + dir / "t" + " " + MESHSTREAM_BINARY + " -q " + cmdline +
                               " 2>/dev/null; echo $? > " + status + "; } | head -c 100 > /dev/null";
        ASSERT_EQ(std::system(sh.c_str()), 0) << sh;
        EXPECT_EQ(slurp(status), "141\n") << args;  // 128 + SIGPIPE
        EXPECT_EQ(listing(dir / "t"), std::vector<std::string>{}) << args;
    }
}

// A file-size limit makes write() fail as on a full disk. SIGXFSZ would kill the process and
// leave the temporary file; meshstream ignores it, so write() returns EFBIG and the command
// reports it.
TEST(CliBadInput, FileSizeLimitGivesAClearErrorAndNoFiles) {
    TempDir dir;
    write_file(dir / "in.stl", binary_stl(grid(100)));  // 20000 triangles, 1 MB
    for (const char* args : {"convert {IN} {OUT}/out.ply", "convert {IN} {OUT}/out.stl",
                             "sort --axis x {IN} {OUT}/out.stl", "decimate --ratio 0.9 {IN} {OUT}/out.stl"}) {
        fs::create_directory(dir / "o");
        const std::string cmdline = expand(expand(args, "{OUT}", dir / "o"), "{IN}", dir / "in.stl");
        CliRun r = run(cmdline, "ulimit -f 256;");  // 128 KiB (dash counts 512-byte blocks)
        EXPECT_EQ(r.code, 1) << args << ": " << r.err;
        EXPECT_NE(r.err.find("meshstream: error: "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("File too large"), std::string::npos) << args << ": " << r.err;
        EXPECT_EQ(listing(dir / "o"), std::vector<std::string>{}) << args;
        fs::remove_all(dir / "o");
    }
}
