// Regression tests for decimator findings of the libFuzzer target tests/fuzz/fuzz_decimate.cpp
// (issue 7). Each input is the minimized finding, written out inline. The undefined behaviour
// they caught is reported by the sanitizer build (CMakePresets.json "asan"), where these tests
// fail without the fix; the plain build checks the decimated result.
#include "decimate/stream_decimator.hpp"

#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

namespace {

// A strip of 2·n triangles along x at height z, with corners scaled by `scale`.
std::vector<float> strip(int n, float scale, float z = 0) {
    std::vector<float> soup;
    for (int i = 0; i < n; ++i) {
        const float x0 = scale * float(i), x1 = scale * float(i + 1);
        soup.insert(soup.end(), {x0, 0, z, x1, 0, z, x1, scale, z});
        soup.insert(soup.end(), {x0, 0, z, x1, scale, z, x0, scale, z});
    }
    return soup;
}

}  // namespace

// Welding cells were keyed by an int64 cast of floor(x / weld_eps), undefined (UBSan:
// "-3.68935e+19 is outside the range of representable values of type 'long'") for huge
// coordinates or tiny cells.
TEST(FuzzRegression, Issue7_WeldHugeCoordinate) {
    // 4e37 · 8 stays below FLT_MAX (1e38 · 8 made the last corners infinite, which push() now refuses).
    for (float scale : {3.7e19f, 4e37f, -4e37f}) {
        Options options;
        options.buffer_triangles = 16;
        options.weld_eps = 1;
        options.ratio = 0.5;
        Decimated d = run_decimator(strip(8, scale), options);
        EXPECT_EQ(d.stats.triangles_in, 16u);
        EXPECT_EQ(d.triangle_count(), d.stats.triangles_out);
        EXPECT_GT(d.triangle_count(), 0u);
    }
    Options tiny;
    tiny.buffer_triangles = 16;
    tiny.weld_eps = 1e-30;
    Decimated d = run_decimator(strip(8, 1e30f), tiny);
    EXPECT_EQ(d.stats.triangles_in, 16u);
    EXPECT_EQ(d.triangle_count(), d.stats.triangles_out);
}

// A NaN or infinite corner can be neither welded (NaN != NaN) nor finalized, so finish() found
// no writable face (assert `allow_forced`). Minimized finding: one triangle, all three corners
// (nan, 9e-40, 1.8e-30), --weld 1, sorted along y. The commands drop such triangles first
// (io::TriangleInput; tested in tests/tools/cli_bad_input_test.cpp), and push() refuses them with
// std::invalid_argument (it was an assert, compiled out of release builds).
TEST(FuzzRegression, Issue7_NonFiniteCoordinatesAreRefused) {
    Options options;
    options.buffer_triangles = 72;
    options.weld_eps = 1;
    options.sorted_axis = 1;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> soup = {nan, 9.2e-40f, 1.8e-30f, nan, 9.2e-40f, 1.8e-30f, nan, 9.2e-40f, 1.8e-30f};
    EXPECT_THROW(run_decimator(soup, options), std::invalid_argument);
}

// pick_write() kept the candidate with the largest quadric error, starting from −1: when every
// candidate's error was NaN (inf·0 from a 1.2e20 coordinate next to denormals), it returned
// "no face", so finish() force-wrote (assert `allow_forced` in Debug) and the CLI warned of a
// buffer full of undecimatable triangles. Minimized by libFuzzer (exact float bits).
TEST(FuzzRegression, Issue7_NanQuadricErrorStillPicksAFaceToWrite) {
    Options options;
    options.buffer_triangles = 1020;
    options.ratio = 0.25;
    options.output_chunk_triangles = 1;
    const uint32_t p[4][3] = {{0x050c0a0b, 0x00000001, 0x0e0e0a0f},
                              {0x0d0e090e, 0x350e0b0a, 0x60d00000},  // y 5.3e-7, z 1.2e20
                              {0x00120000, 0x0b0a0d0e, 0x0e7f0000},
                              {0x0a0e0f00, 0x0a0d0e0e, 0x0a0d0e0b}};
    std::vector<float> soup;
    for (int v : {3, 1, 2, 1, 2, 3})
        for (int k = 0; k < 3; ++k) soup.push_back(std::bit_cast<float>(p[v][k]));
    Decimated d = run_decimator(soup, options);
    EXPECT_EQ(d.stats.triangles_in, 2u);
    EXPECT_EQ(d.triangle_count(), d.stats.triangles_out);
    EXPECT_EQ(d.stats.forced_writes, 0u);
}
