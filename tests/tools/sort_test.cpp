// End-to-end tests of `meshstream sort` and `info --order` through the built binary
// (MESHSTREAM_BINARY): exit codes, messages, sorted and complete output, the recorded axis,
// stdin→stdout, multi-pass merging, and temporary files gone after success, failure and SIGINT.
#include "io/format.hpp"
#include "sort/radix.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using namespace meshstream;
using Tri = std::array<float, 9>;

namespace {

using cli_test::slurp;
using cli_test::TempDir;

size_t file_count(const std::string& dir) {
    return static_cast<size_t>(std::distance(fs::directory_iterator(dir), {}));
}

struct CliRun {
    int code;
    std::string out, err;
};

// Runs `meshstream ARGS` through the shell; `args` may contain pipes and redirections of stdin.
CliRun run(const std::string& args, const TempDir& dir) {
    std::string cmd =
        std::string(MESHSTREAM_BINARY) + " " + args + " > " + dir / "stdout.txt" + " 2> " + dir / "stderr.txt";
    int status = std::system(cmd.c_str());
    CliRun r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir / "stdout.txt"), slurp(dir / "stderr.txt")};
    fs::remove(dir / "stdout.txt");
    fs::remove(dir / "stderr.txt");
    return r;
}

std::vector<Tri> read_fixture(const std::string& name) {
    std::ifstream in(std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    uint32_t n;
    std::memcpy(&n, bytes.data() + 80, 4);
    std::vector<Tri> tris(n);
    for (uint32_t i = 0; i < n; ++i) std::memcpy(tris[i].data(), bytes.data() + 84 + 50 * size_t{i} + 12, 36);
    return tris;
}

// Binary STL written by hand (zero normals), so the input does not depend on the writer.
void write_stl(const std::string& path, const std::vector<Tri>& tris) {
    std::ofstream out(path, std::ios::binary);
    char header[80] = "sort_test input";
    out.write(header, 80);
    uint32_t n = static_cast<uint32_t>(tris.size());
    out.write(reinterpret_cast<const char*>(&n), 4);
    for (const Tri& t : tris) {
        char facet[50] = {};
        std::memcpy(facet + 12, t.data(), 36);
        out.write(facet, 50);
    }
}

struct Mesh {
    std::vector<Tri> tris;
    std::optional<int> sorted_axis;
};

Mesh read_mesh(const std::string& path) {
    io::Input in = io::open_input(path);
    Mesh m;
    m.sorted_axis = in.reader->header().sorted_axis;
    io::TriangleChunk chunk;
    while (in.reader->next(chunk)) {
        auto xyz = chunk.xyz();
        for (size_t i = 0; i < chunk.size(); ++i) std::memcpy(m.tris.emplace_back().data(), &xyz[9 * i], 36);
    }
    return m;
}

void expect_sorted_permutation(const std::vector<Tri>& out, std::vector<Tri> in, int axis) {
    ASSERT_EQ(out.size(), in.size());
    for (size_t i = 1; i < out.size(); ++i)
        ASSERT_LE(sort::triangle_key(out[i - 1].data(), axis), sort::triangle_key(out[i].data(), axis)) << "at " << i;
    std::vector<Tri> a = out;
    auto less = [](const Tri& x, const Tri& y) { return std::memcmp(x.data(), y.data(), sizeof(Tri)) < 0; };
    std::sort(a.begin(), a.end(), less);
    std::sort(in.begin(), in.end(), less);
    EXPECT_TRUE(std::memcmp(a.data(), in.data(), a.size() * sizeof(Tri)) == 0) << "triangles changed";
}

// n triangles scattered over a box 1 × 10 × 2 (longest along y), in random order.
std::vector<Tri> random_triangles(size_t n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Tri> tris(n);
    for (Tri& t : tris) {
        float x = u(rng), y = 10 * u(rng), z = 2 * u(rng);
        t = {x, y, z, x + 0.01f, y, z, x, y + 0.01f, z + 0.01f};
    }
    return tris;
}

uint64_t width_of(const std::string& info_text) {
    size_t at = info_text.find("width:");
    EXPECT_NE(at, std::string::npos) << info_text;
    return at == std::string::npos ? 0 : std::stoull(info_text.substr(at + 6));
}

}  // namespace

TEST(SortCommand, SortsShuffledFixtureAndRecordsAxis) {
    TempDir dir;
    std::vector<Tri> tris = read_fixture("bunny_from_draco.bin.stl");
    std::shuffle(tris.begin(), tris.end(), std::mt19937_64(3));
    write_stl(dir / "shuffled.stl", tris);
    fs::create_directory(dir / "tmp");
    CliRun r =
        run("sort --axis z --memory 1M --tmpdir " + dir / "tmp" + " " + dir / "shuffled.stl" + " " + dir / "sorted.stl",
            dir);
    ASSERT_EQ(r.code, 0) << r.err;
    Mesh m = read_mesh(dir / "sorted.stl");
    expect_sorted_permutation(m.tris, tris, 2);
    EXPECT_EQ(m.sorted_axis, 2);
    EXPECT_EQ(file_count(dir / "tmp"), 0u);
}

// glTF keeps the sorted order (without Draco) but has no place for the axis: said, with the
// option that stands in for it. It used to be dropped silently, and `info --order` then
// advised flagging the file with `meshstream sort`.
TEST(SortCommand, AGltfOutputSaysItCannotRecordTheAxis) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(2000, 14));
    CliRun g = run("sort --axis y --no-draco " + dir / "in.stl" + " " + dir / "out.gltf", dir);
    ASSERT_EQ(g.code, 0) << g.err;
    EXPECT_NE(g.err.find("out.gltf: glTF has no place for the sorted axis: decimate it with --sorted-axis y, or sort "
                         "to STL, PLY or OBJ, which record it"),
              std::string::npos)
        << g.err;
    CliRun p = run("sort --axis y " + dir / "in.stl" + " " + dir / "out.ply", dir);
    EXPECT_EQ(p.err, "");
}

TEST(SortCommand, SaysWhatTheWriterLeftOut) {
    // A NaN corner travels through the sort; a glTF cannot store it, and its writer leaves the
    // triangle out with a note, which sort prints as convert does (never silently dropped).
    TempDir dir;
    std::vector<Tri> tris = random_triangles(200, 3);
    tris[17][4] = std::numeric_limits<float>::quiet_NaN();
    write_stl(dir / "in.stl", tris);
    CliRun g = run("sort --axis x --compress meshopt " + dir / "in.stl" + " " + dir / "out.glb", dir);
    ASSERT_EQ(g.code, 0) << g.err;
    EXPECT_NE(g.err.find("out.glb: 1 of the 200 triangles have a NaN or infinite coordinate, which glTF cannot store: "
                         "left out"),
              std::string::npos)
        << g.err;
    CliRun strict = run("sort --axis x --strict --compress meshopt " + dir / "in.stl" + " " + dir / "strict.glb", dir);
    EXPECT_EQ(strict.code, 1) << strict.err;
}

TEST(SortCommand, AutoAxisIsTheLongestExtent) {
    TempDir dir;
    std::vector<Tri> tris = random_triangles(20000, 1);
    write_stl(dir / "in.stl", tris);
    CliRun r = run("sort " + dir / "in.stl" + " " + dir / "out.stl", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    Mesh m = read_mesh(dir / "out.stl");
    EXPECT_EQ(m.sorted_axis, 1);
    expect_sorted_permutation(m.tris, tris, 1);
    // Default temporary directory: next to the output, and emptied.
    EXPECT_EQ(file_count(dir.path().string()), 2u);
}

TEST(SortCommand, StdinToStdout) {
    TempDir dir;
    std::vector<Tri> tris = random_triangles(30000, 2);
    write_stl(dir / "in.stl", tris);
    CliRun r = run("sort --axis x --memory 1M --to stl - - < " + dir / "in.stl", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    std::ofstream(dir / "out.stl", std::ios::binary) << r.out;
    Mesh m = read_mesh(dir / "out.stl");
    expect_sorted_permutation(m.tris, tris, 0);
    EXPECT_EQ(m.sorted_axis, 0);
    // Through a pipe as well (not a seekable file).
    r = run("sort --axis x --to stl - - < /dev/null", dir);
    EXPECT_EQ(r.code, 1);  // empty input is not a mesh
    r = run("sort --axis y --to stl - " + dir / "piped.stl" + " < " + dir / "in.stl", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    expect_sorted_permutation(read_mesh(dir / "piped.stl").tris, tris, 1);
}

TEST(SortCommand, AutoAxisNeedsAFile) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(10, 3));
    CliRun r = run("sort --to stl - - < " + dir / "in.stl", dir);
    EXPECT_EQ(r.code, 2);  // a command line that cannot work
    EXPECT_NE(r.err.find("give --axis x, y or z"), std::string::npos) << r.err;
    r = run("sort --axis w " + dir / "in.stl" + " " + dir / "out.stl", dir);
    EXPECT_EQ(r.code, 2);  // bad command line
    EXPECT_FALSE(fs::exists(dir / "out.stl"));
}

TEST(SortCommand, MultiPassMergeUnderOneMebibyte) {
    TempDir dir;
    std::vector<Tri> tris = random_triangles(500000, 4);
    write_stl(dir / "in.stl", tris);
    CliRun r = run("sort --stats --axis z --memory 1M " + dir / "in.stl" + " " + dir / "out.stl", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("2 merge passes"), std::string::npos) << r.err;
    expect_sorted_permutation(read_mesh(dir / "out.stl").tris, tris, 2);
    EXPECT_EQ(file_count(dir.path().string()), 2u);  // in.stl and out.stl only
    // Within the budget nothing is written to disk: said so (it used to say "0 runs of up to N").
    r = run("sort --stats --axis z " + dir / "in.stl" + " " + dir / "out.stl", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("): in memory (room for "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(" triangles), no runs, 0 merge passes, 0 B temporary written"), std::string::npos) << r.err;
}

// /dev/stdout, /dev/fd/1 and devices are written in place, like '-', and the runs go to
// $TMPDIR: the command used to create a temporary file beside "pipe:[N]" (failing), rename
// over a `>>` log (losing what it held) or spill its runs into /dev (memory).
TEST(SortCommand, DeviceOutputsAreWrittenInPlaceWithRunsInTheTemporaryDirectory) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(30000, 12));  // two runs at --memory 1M
    fs::create_directory(dir / "tmp");
    ASSERT_EQ(run("sort --axis z --memory 1M " + dir / "in.stl" + " " + dir / "ref.stl", dir).code, 0);
    const std::string ref = slurp(dir / "ref.stl");
    const std::string sort =
        "TMPDIR=" + dir / "tmp" + " " + MESHSTREAM_BINARY + " -q sort --axis z --memory 1M --to stl " + dir / "in.stl";
    for (const char* name : {"/dev/stdout", "/dev/fd/1"}) {
        EXPECT_EQ(std::system((sort + " " + name + " 2> " + dir / "err.txt" + " | cat > " + dir / "piped.stl").c_str()),
                  0);
        EXPECT_EQ(slurp(dir / "err.txt"), "") << name;
        EXPECT_TRUE(slurp(dir / "piped.stl") == ref) << name;
        std::ofstream(dir / "log.stl") << "kept";
        EXPECT_EQ(std::system((sort + " " + name + " >> " + dir / "log.stl").c_str()), 0);
        EXPECT_TRUE(slurp(dir / "log.stl") == "kept" + ref) << name;
    }
    EXPECT_EQ(file_count(dir / "tmp"), 0u);
    // Runs in $TMPDIR, not in /dev: a $TMPDIR that does not exist is named in the error.
    const int status =
        std::system(("TMPDIR=" + dir / "none" + " " + MESHSTREAM_BINARY + " -q sort --axis z --memory 1M --to stl " +
                     dir / "in.stl" + " /dev/null 2> " + dir / "err.txt")
                        .c_str());
    EXPECT_EQ(WEXITSTATUS(status), 1);
    EXPECT_NE(slurp(dir / "err.txt").find(dir / "none"), std::string::npos) << slurp(dir / "err.txt");
}

TEST(SortCommand, TruncatedInputLeavesNoOutputAndNoTemporaryFiles) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(100000, 5));
    fs::resize_file(dir / "in.stl", 84 + 50 * 60000 + 17);  // runs are already on disk when it fails
    fs::create_directory(dir / "tmp");
    CliRun r =
        run("sort --axis z --memory 1M --tmpdir " + dir / "tmp" + " " + dir / "in.stl" + " " + dir / "out.stl", dir);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("in.stl"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.stl"));
    EXPECT_EQ(file_count(dir / "tmp"), 0u);
    EXPECT_EQ(file_count(dir.path().string()), 2u);  // in.stl and tmp/
}

TEST(SortCommand, MissingOutputDirectoryFailsBeforeSorting) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(10, 6));
    CliRun r = run("sort --axis z " + dir / "in.stl" + " " + dir / "no/such/out.stl", dir);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("does not exist or is not writable"), std::string::npos) << r.err;
}

TEST(SortCommand, SigintRemovesTemporaryFiles) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(500000, 7));
    fs::create_directory(dir / "tmp");
    fs::create_directory(dir / "out");
    const std::string tmp = dir / "tmp", in = dir / "in.stl", out = dir / "out/out.stl";
    pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        int null_fd = ::open("/dev/null", O_WRONLY);
        ::dup2(null_fd, 2);
        ::execl(MESHSTREAM_BINARY, "meshstream", "-q", "sort", "--axis", "z", "--memory", "1M", "--tmpdir", tmp.c_str(),
                in.c_str(), out.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    int status = 0;
    bool finished = false;
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (file_count(tmp) == 0 && std::chrono::steady_clock::now() < deadline) {
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            finished = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (!finished) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));  // past mkstemp → registration
        ::kill(pid, SIGINT);
        ::waitpid(pid, &status, 0);
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        GTEST_SKIP() << "the sort finished before it could be interrupted";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << status;
    EXPECT_EQ(file_count(tmp), 0u);
    EXPECT_EQ(file_count(dir / "out"), 0u);
}

TEST(InfoOrder, DistinguishesShuffledFromSorted) {
    TempDir dir;
    std::vector<Tri> tris = read_fixture("bunny_from_draco.bin.stl");
    std::shuffle(tris.begin(), tris.end(), std::mt19937_64(9));
    write_stl(dir / "shuffled.stl", tris);
    ASSERT_EQ(run("sort --axis y " + dir / "shuffled.stl" + " " + dir / "sorted.stl", dir).code, 0);
    CliRun shuffled = run("info --order --buffer 20000 " + dir / "shuffled.stl", dir);
    CliRun sorted = run("info --order --buffer 20000 " + dir / "sorted.stl", dir);
    ASSERT_EQ(shuffled.code, 0) << shuffled.err;
    ASSERT_EQ(sorted.code, 0) << sorted.err;
    uint64_t w_shuffled = width_of(shuffled.out), w_sorted = width_of(sorted.out);
    EXPECT_GT(w_shuffled, 69451u / 2) << shuffled.out;
    EXPECT_LT(w_sorted, 69451u / 10) << sorted.out;
    EXPECT_NE(shuffled.out.find("--buffer 20000 is too small"), std::string::npos) << shuffled.out;
    // A larger buffer is not the remedy for a shuffled file: sorting is.
    EXPECT_NE(shuffled.out.find(": the file is in no streaming order (its width is a tenth of it or more), so "
                                "`meshstream sort` it first\n"),
              std::string::npos)
        << shuffled.out;
    {
        // The shuffled triangles under the sorted file's header, which says "sorted along y".
        std::string bytes = slurp(dir / "shuffled.stl");
        bytes.replace(0, 80, slurp(dir / "sorted.stl").substr(0, 80));
        std::ofstream(dir / "false_flag.stl", std::ios::binary) << bytes;
        CliRun f = run("info --order " + dir / "false_flag.stl", dir);
        ASSERT_EQ(f.code, 0) << f.err;
        EXPECT_NE(f.out.find("(the file says it is sorted along y, but it is not: `meshstream sort` it again)"),
                  std::string::npos)
            << f.out;
        EXPECT_NE(f.out.find(", unless the surface has holes: the file is not sorted as it says"), std::string::npos)
            << f.out;
    }
    EXPECT_NE(sorted.out.find("--buffer 20000 suffices at --ratio 0.1 (needs about "), std::string::npos) << sorted.out;
    EXPECT_EQ(sorted.out.find("unless the surface has holes"), std::string::npos) << sorted.out;  // flagged sorted
    // Not flagged as sorted: holes would stay open to the end, which the width cannot tell.
    CliRun big = run("info --order --buffer 200000 " + dir / "shuffled.stl", dir);
    EXPECT_NE(big.out.find("--buffer 200000 suffices at --ratio 0.1 (needs about "), std::string::npos) << big.out;
    EXPECT_NE(big.out.find(", unless the surface has holes: the file is not flagged as sorted"), std::string::npos)
        << big.out;
    EXPECT_NE(sorted.out.find("(sorted along y by minimum coordinate)"), std::string::npos) << sorted.out;
    EXPECT_NE(sorted.out.find("(exact)"), std::string::npos) << sorted.out;
    // --json carries the same numbers.
    CliRun json = run("info --order --json " + dir / "sorted.stl", dir);
    ASSERT_EQ(json.code, 0) << json.err;
    EXPECT_NE(json.out.find("\"width\": " + std::to_string(w_sorted)), std::string::npos) << json.out;
    EXPECT_NE(json.out.find("\"buffer_suffices\": true"), std::string::npos) << json.out;

    // The verdict's promise: a buffer info calls sufficient for a ratio decimates at that ratio
    // without forced writes (the room needed grows with the ratio: this file, of width 933,
    // needed 1 371 at 1 % and 2 437 at 90 %).
    for (const char* ratio : {"0.01", "0.1", "0.5", "0.9"}) {
        CliRun info = run("info --order --json --ratio " + std::string(ratio) + " " + dir / "sorted.stl", dir);
        ASSERT_EQ(info.code, 0) << info.err;
        const size_t at = info.out.find("\"buffer_needed\": ");
        ASSERT_NE(at, std::string::npos) << info.out;
        const uint64_t needed = std::stoull(info.out.substr(at + 17));
        EXPECT_GT(needed, w_sorted) << ratio;
        CliRun d = run("decimate -r " + std::string(ratio) + " --buffer " + std::to_string(needed) + " " +
                           dir / "sorted.stl" + " " + dir / "dec.stl",
                       dir);
        ASSERT_EQ(d.code, 0) << d.err;
        EXPECT_EQ(d.err.find("force-written"), std::string::npos)
            << "ratio " << ratio << ", buffer " << needed << ": " << d.err;
    }
}

// A CAD model of many open parts, with one triangle 230 of its 743 units long along x: sorted
// along x, it decimates without forced writes through the buffer `info --order` calls
// sufficient (5 000 for "needs about 4 844"). The sweep's margin used to be the longest
// triangle read so far, so it kept hole rims open 460 units behind the front: 10 033 forced
// writes at 5 000 and 3 936 at 10 000. The file's flag says it is sorted by triangle minimum,
// so no margin is needed.
TEST(SortCommand, ALongTriangleDoesNotHoldOffTheSweepOfASortedCadModel) {
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/gltf/2CylinderEngine_draco/2CylinderEngine.gltf";
    ASSERT_EQ(run("sort --axis x " + in + " " + dir / "x.stl", dir).code, 0);
    CliRun d = run("decimate -r 0.1 --buffer 5000 " + dir / "x.stl" + " " + dir / "out.stl", dir);
    ASSERT_EQ(d.code, 0) << d.err;
    EXPECT_NE(d.err.find("forced writes 0\n"), std::string::npos) << d.err;
    EXPECT_NE(d.err.find("sorted along x (ascending): "), std::string::npos) << d.err;
    const uint64_t out = *io::open_input(dir / "out.stl").reader->triangle_count();
    EXPECT_GE(out, 11033u) << d.err;  // the target (one more when an odd one is left at the end)
    EXPECT_LE(out, 11034u) << d.err;
}

TEST(SortCommand, FullDiskIsAClearErrorAndLeavesNothing) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(200000, 8));  // 7.2 MB of run records
    fs::create_directory(dir / "small");
    // A small tmpfs as the temporary directory (needs root; skipped elsewhere): 1 MiB fills
    // early; 7000k holds all but the last few KiB of the runs, which used to wait in the temp
    // file's buffer and fail only when the merge read them, without the --tmpdir advice.
    for (const char* size : {"1M", "7000k"}) {
        if (std::system(
                ("mount -t tmpfs -o size=" + std::string(size) + " tmpfs " + dir / "small" + " 2>/dev/null").c_str()) !=
            0)
            GTEST_SKIP() << "cannot mount a small tmpfs here";
        CliRun r = run(
            "sort --axis z --memory 1M --tmpdir " + dir / "small" + " " + dir / "in.stl" + " " + dir / "out.stl", dir);
        size_t left = file_count(dir / "small");
        std::system(("umount " + dir / "small").c_str());
        EXPECT_EQ(r.code, 1) << size;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << size << ": " << r.err;
        EXPECT_NE(r.err.find("(temporary file of meshstream sort; --tmpdir picks another directory)"),
                  std::string::npos)
            << size << ": " << r.err;
        EXPECT_EQ(left, 0u) << size;
        EXPECT_FALSE(fs::exists(dir / "out.stl")) << size;
    }
}

// At the least budget the merge is two-way with 64 KiB reads: consumed run data is given back
// page by page, so the runs need about one copy on disk. With reads of 360 bytes (the budget
// split between the runs) no punched hole freed a page, and this disk filled up.
TEST(SortCommand, TheLeastBudgetMergesInAboutOneCopyOnDisk) {
    TempDir dir;
    const std::vector<Tri> tris = random_triangles(100000, 13);  // 3.6 MB of run records
    write_stl(dir / "in.stl", tris);
    fs::create_directory(dir / "small");
    if (std::system(("mount -t tmpfs -o size=4500k tmpfs " + dir / "small" + " 2>/dev/null").c_str()) != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs here";
    CliRun r = run(
        "sort --stats --axis z --memory 97K --tmpdir " + dir / "small" + " " + dir / "in.stl" + " " + dir / "out.stl",
        dir);
    std::system(("umount " + dir / "small").c_str());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find(" merge passes"), std::string::npos) << r.err;
    expect_sorted_permutation(read_mesh(dir / "out.stl").tris, tris, 2);
}

// The output is written on its own thread: a write error there (here the output's disk is
// full, runs on a disk with room) must stop the sort with the error and leave no output.
TEST(SortCommand, FullOutputDiskIsAClearErrorAndLeavesNothing) {
    TempDir dir;
    write_stl(dir / "in.stl", random_triangles(100000, 9));  // 5 MB of binary STL out
    fs::create_directory(dir / "small");
    fs::create_directory(dir / "tmp");
    if (std::system(("mount -t tmpfs -o size=1M tmpfs " + dir / "small" + " 2>/dev/null").c_str()) != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs here";
    // --memory 1M: runs on disk and a multi-pass merge before the output fails; 64M: in memory.
    for (const char* memory : {"1M", "64M"}) {
        CliRun r = run(std::string("sort --axis z --memory ") + memory + " --tmpdir " + dir / "tmp" + " " +
                           dir / "in.stl" + " " + dir / "small/out.stl",
                       dir);
        EXPECT_EQ(r.code, 1) << memory;
        EXPECT_NE(r.err.find("out.stl"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
        EXPECT_EQ(file_count(dir / "small"), 0u) << memory;
        EXPECT_EQ(file_count(dir / "tmp"), 0u) << memory;
    }
    std::system(("umount " + dir / "small").c_str());
}
