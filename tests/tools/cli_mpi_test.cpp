// `mpirun -n K meshstream-mpi decimate` (MESHSTREAM_MPI_BINARY, run through MESHSTREAM_MPIEXEC
// with --oversubscribe: more ranks than cores is fine here): one decimation spread over MPI ranks,
// one range each (tools/mpi_processes.hpp). Its output is what `meshstream decimate --threads K`
// writes, byte for byte, since the ranges and the seam pass are the same wherever they run; errors
// are said once, by rank 0, with the exit codes of meshstream.
#include "compare/topology.hpp"
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace {

using cli_test::CliRun;
using cli_test::edges_of;
using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;
using cli_test::triangles_of;
using namespace meshstream;

// Runs `mpirun -n RANKS meshstream-mpi ARGS` through /bin/sh, stdout to /dev/null unless ARGS
// redirects it, stderr captured. Root may run it (the CI machine's user). `rank0` runs first in
// rank 0's shell (a ulimit for it alone; the ranks then talk over TCP on the loopback
// interface, whose setup writes no file as shared memory's does). A job that does not end
// within two minutes is killed (exit 124): a rank waiting for ever fails the test.
CliRun run_mpi(int ranks, const std::string& args, const std::string& rank0 = "") {
    char err_path[] = "/tmp/meshstream_mpi_err-XXXXXX";
    const int fd = ::mkstemp(err_path);
    ::close(fd);
    // Under AddressSanitizer the ranks leave leak checking out: OpenMPI does not free what
    // MPI_Init allocates (in libmpi and its dlopen'd components); meshstream's own code is
    // leak-checked through the meshstream binary, which runs the same ranges and seam pass.
    std::string cmd = std::string("exec >/dev/null; OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ") +
                      "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" " + "timeout -k 5 120 " +
                      MESHSTREAM_MPIEXEC + " --oversubscribe -n " + std::to_string(ranks) + " ";
    if (rank0.empty())
        cmd += std::string(MESHSTREAM_MPI_BINARY) + " " + args;
    else
        cmd += "--mca btl self,tcp --mca btl_tcp_if_include lo sh -c 'if [ \"$OMPI_COMM_WORLD_RANK\" = 0 ]; then " +
               rank0 + "; fi; exec " + MESHSTREAM_MPI_BINARY + " \"$@\"' sh " + args;
    const int status = std::system((cmd + " 2> " + err_path).c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(err_path)};
    ::unlink(err_path);
    return r;
}

size_t count_of(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// A closed generated mesh of about 200 k triangles.
const std::string& mesh() { return cli_test::generated_mesh(200000); }

}  // namespace

TEST(MpiDecimate, KRanksWriteWhatKThreadsWrite) {
    TempDir dir;
    ASSERT_EQ(edges_of(mesh()).boundary_edges, 0u);
    for (const auto& [ranks, options] :
         {std::pair{2, "-r 0.1"}, std::pair{3, "-r 0.01"}, std::pair{2, "--target 5000"}}) {
        const std::string common = "decimate --buffer 20000 " + std::string(options) + " " + mesh() + " ";
        const CliRun r = run_mpi(ranks, common + dir / "mpi.stl");
        ASSERT_EQ(r.code, 0) << options << ": " << r.err;
        EXPECT_NE(r.err.find("processes " + std::to_string(ranks) + ": " + std::to_string(ranks) +
                             " ranges decimated at once by MPI ranks"),
                  std::string::npos)
            << r.err;
        EXPECT_EQ(count_of(r.err, " -> "), 1u) << "one summary, rank 0's: " << r.err;
        ASSERT_EQ(run("-q " + common + "--threads " + std::to_string(ranks) + " " + dir / "threads.stl").code, 0);
        EXPECT_EQ(slurp(dir / "mpi.stl"), slurp(dir / "threads.stl")) << ranks << " ranks, " << options;
        if (std::strstr(options, "--target") != nullptr) {
            EXPECT_EQ(triangles_of(dir / "mpi.stl"), 5000u);
        }
        EXPECT_EQ(edges_of(dir / "mpi.stl").boundary_edges, 0u) << "a closed mesh stays closed";
    }
}

TEST(MpiDecimate, RanksSendTheColoursTheyCarry) {
    TempDir dir;
    const std::string coloured = dir / "coloured.ply";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q --color -n 60000 " + coloured).c_str()), 0);
    const std::string common = "decimate --buffer 16384 -r 0.1 " + coloured + " ";
    const CliRun r = run_mpi(2, common + dir / "mpi.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    ASSERT_EQ(run("-q " + common + "--threads 2 " + dir / "threads.ply").code, 0);
    const std::string mpi = slurp(dir / "mpi.ply");
    EXPECT_NE(mpi.find("property uchar red"), std::string::npos);
    EXPECT_EQ(mpi, slurp(dir / "threads.ply"));
}

TEST(MpiDecimate, JsonIsOneObjectFromRankZero) {
    TempDir dir;
    const CliRun r = run_mpi(
        2, "decimate --json --buffer 20000 -r 0.1 " + mesh() + " " + dir / "out.stl" + " > " + dir / "out.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(dir / "out.json"));  // throws on a second object
    EXPECT_EQ(j["decimate"]["processes"], 2);
    EXPECT_EQ(j["decimate"]["threads"], 1);
    EXPECT_EQ(j["triangles_out"], triangles_of(dir / "out.stl"));
}

TEST(MpiDecimate, AnInputTooSmallToCutIsDecimatedByRankZeroAlone) {
    TempDir dir;
    const std::string bunny = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";
    const CliRun r = run_mpi(2, "decimate -r 0.1 " + bunny + " " + dir / "mpi.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("ranges decimated at once"), std::string::npos) << r.err;
    ASSERT_EQ(run("decimate -q --threads 1 -r 0.1 " + bunny + " " + dir / "one.stl").code, 0);
    EXPECT_EQ(slurp(dir / "mpi.stl"), slurp(dir / "one.stl"));
}

TEST(MpiDecimate, UnsortedInputIsSortedFirstAsByThreads) {
    // A shuffled mesh: a range meets a forced write, every range stops, and rank 0 sorts the
    // input and decimates it alone, as `--threads 2` does.
    TempDir dir;
    const std::string shuffled = dir / "shuffled.stl";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q -n 100000 --shuffle " + shuffled).c_str()), 0);
    const std::string common = "decimate --buffer 20000 -r 0.02 " + shuffled + " ";
    const CliRun r = run_mpi(2, common + dir / "mpi.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("sorted along"), std::string::npos) << r.err;
    ASSERT_EQ(run("-q " + common + "--threads 2 " + dir / "threads.stl").code, 0);
    EXPECT_EQ(slurp(dir / "mpi.stl"), slurp(dir / "threads.stl"));
    // On the target: 2 % of the triangles the read loop passed (it skips degenerate ones).
    const std::smatch m = [&] {
        std::smatch found;
        std::regex_search(r.err, found, std::regex("out (\\d+) \\(target (\\d+),"));
        return found;
    }();
    ASSERT_EQ(m.size(), 3u) << r.err;
    EXPECT_EQ(m[1].str(), m[2].str()) << r.err;
    EXPECT_EQ(std::to_string(triangles_of(dir / "mpi.stl")), m[1].str());
}

TEST(MpiDecimate, BadInputInAnotherRanksRangeIsSaidOnceByRankZero) {
    // A vertex index out of range a quarter into a binary PLY: in the range of rank 1 (and read
    // past by rank 0's); exit 1, one thread's message once, no output left.
    TempDir dir;
    std::filesystem::create_directories(dir / "in");
    std::filesystem::create_directories(dir / "out");
    const std::string in = dir / "in/bad.ply", out = dir / "out/o.ply";
    const uint64_t bad = cli_test::write_ply_with_bad_index(mesh(), in, 0.25).bad_face;
    const CliRun one = run("decimate --threads 1 --buffer 20000 -r 0.1 " + in + " " + out);
    ASSERT_EQ(one.code, 1);
    const std::string message = one.err.substr(one.err.find("error: "));
    ASSERT_NE(message.find("item " + std::to_string(bad)), std::string::npos) << message;
    const CliRun r = run_mpi(2, "decimate --buffer 20000 -r 0.1 " + in + " " + out);
    EXPECT_NE(r.code, 0) << r.err;
    EXPECT_EQ(count_of(r.err, "meshstream-mpi: " + message), 1u) << r.err;
    EXPECT_TRUE(listing(dir / "out").empty());
}

TEST(MpiDecimate, AFailureOnRankZeroEndsEveryRank) {
    // A file-size limit (as a full disk): rank 0 cannot spool what rank 1 sends, nor write its
    // own range's output. Every rank ends, rank 0 says why once, exit 1, no output left.
    TempDir dir;
    std::filesystem::create_directories(dir / "o");
    const CliRun r =
        run_mpi(2, "decimate --buffer 20000 -r 0.9 --tmpdir " + dir / "o" + " " + mesh() + " " + dir / "o/out.stl",
                "ulimit -f 256");  // 128 KiB (dash counts 512-byte blocks)
    EXPECT_NE(r.code, 0) << r.err;
    EXPECT_NE(r.code, 124) << "a rank did not end: " << r.err;
    EXPECT_EQ(count_of(r.err, "meshstream-mpi: error: "), 1u) << r.err;
    EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
    EXPECT_TRUE(listing(dir / "o").empty());
}

TEST(MpiDecimate, CommandLineErrorsAreSaidOnce) {
    TempDir dir;
    const std::string out = dir / "out.stl";
    for (const std::string& args : {"decimate --threads 2 " + mesh() + " " + out, "decimate - " + out + " < " + mesh(),
                                    "decimate --sort always " + mesh() + " " + out}) {
        const CliRun r = run_mpi(2, args);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_EQ(count_of(r.err, "meshstream-mpi: decimate: "), 1u) << args << ": " << r.err;
        EXPECT_TRUE(listing(dir.path()).empty()) << args;
    }
    const CliRun help = run_mpi(2, "decimate --help > " + dir / "help.txt");
    EXPECT_EQ(help.code, 0) << help.err;
    const std::string text = slurp(dir / "help.txt");
    EXPECT_EQ(count_of(text, "Usage:"), 1u) << text;
    EXPECT_EQ(text.find("--threads"), std::string::npos) << text;
}
