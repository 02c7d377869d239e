// Welding: the hash path and the external-sort path give the same vertices and indices;
// -0.0 welds with +0.0; vertex ids keep coincident vertices apart; the record sorter sorts
// across spilled runs.
#include "io/weld.hpp"

#include "indexed_test_util.hpp"
#include "io/record_sort.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <random>

using namespace meshstream;

namespace {

struct Welded {
    std::vector<float> xyz;
    std::vector<uint8_t> rgb;
    std::vector<uint32_t> indices;
    bool out_of_core = false;
};

Welded weld(const std::vector<float>& soup, uint64_t budget, io::Channels channels = {},
            const std::vector<uint64_t>& ids = {}) {
    test::TempDir dir;
    Welded out;
    {
        io::Welder w(budget, dir.path(), "test", channels);
        io::TriangleChunk chunk(333, channels);
        for (size_t t = 0; t < soup.size() / 9; ++t) {
            if (chunk.full()) {
                w.add(chunk);
                chunk.clear();
            }
            size_t i = chunk.size();
            float* p = chunk.push_slot();
            std::copy(soup.begin() + 9 * t, soup.begin() + 9 * t + 9, p);
            if (channels.vertex_id)
                for (int k = 0; k < 3; ++k) chunk.id_at(i)[k] = ids[3 * t + k];
            if (channels.color)  // 8-bit RGB of the corner's position, alpha 1
                for (int k = 0; k < 12; ++k)
                    chunk.color_at(i)[k] =
                        k % 4 == 3
                            ? 1.0f
                            : float(static_cast<uint8_t>(7 * p[3 * (k / 4)] + 3 * p[3 * (k / 4) + 1] + k % 4)) / 255.0f;
        }
        w.add(chunk);
        w.finish();
        out.out_of_core = w.out_of_core();
        std::vector<float> xyz(3 * 100);
        std::vector<std::byte> records(100 * w.layout().bytes());
        while (size_t n = w.next_vertices(xyz, records))
            for (size_t i = 0; i < n; ++i) {
                out.xyz.insert(out.xyz.end(), &xyz[3 * i], &xyz[3 * i] + 3);
                for (size_t b = 0; b < w.layout().bytes(); ++b)
                    out.rgb.push_back(uint8_t(records[w.layout().bytes() * i + b]));
            }
        std::vector<uint32_t> idx(300);
        while (size_t n = w.next_indices(idx)) out.indices.insert(out.indices.end(), idx.begin(), idx.begin() + n);
        EXPECT_EQ(out.xyz.size() / 3, w.vertex_count());
        EXPECT_EQ(out.indices.size() / 3, w.triangle_count());
    }
    EXPECT_TRUE(dir.entries().empty());  // spools live in the welder's lifetime only
    return out;
}

}  // namespace

TEST(Welder, HashAndExternalSortPathsAgree) {
    std::vector<float> grid = test::grid_soup(80);  // 12482 triangles, 6400 vertices
    for (bool color : {false, true}) {
        io::Channels ch;
        if (color) ch.color = io::ColorFormat{};
        Welded memory = weld(grid, uint64_t{64} << 20, ch);
        Welded tiny = weld(grid, 32 << 10, ch);
        EXPECT_FALSE(memory.out_of_core);
        EXPECT_TRUE(tiny.out_of_core);
        EXPECT_EQ(memory.xyz.size(), 3u * 6400);
        EXPECT_EQ(memory.xyz, tiny.xyz);
        EXPECT_EQ(memory.rgb, tiny.rgb);
        EXPECT_EQ(memory.indices, tiny.indices);
        for (size_t c = 0; c < memory.indices.size(); ++c)
            for (int a = 0; a < 3; ++a) ASSERT_EQ(memory.xyz[3 * memory.indices[c] + a], grid[3 * c + a]);
    }
}

TEST(Welder, MinusZeroWeldsWithPlusZeroAndIdsKeepVerticesApart) {
    const std::vector<float> soup = {0, 0, 0, 1, 0, 0, 0, 1, 0, -0.0f, -0.0f, 0, 0, 1, 0, 1, 0, -0.0f};
    Welded w = weld(soup, 1 << 20);
    EXPECT_EQ(w.xyz.size(), 9u);
    EXPECT_EQ(w.indices, (std::vector<uint32_t>{0, 2, 1, 0, 1, 2}));
    io::Channels ch;
    ch.vertex_id = true;
    Welded ids = weld(soup, 1 << 20, ch, {10, 11, 12, 13, 12, 11});  // corner 3 is another vertex at 0
    EXPECT_EQ(ids.xyz.size(), 12u);
    EXPECT_EQ(ids.indices, (std::vector<uint32_t>{0, 1, 2, 3, 2, 1}));
    Welded ids_tiny = weld(soup, 0, ch, {10, 11, 12, 13, 12, 11});
    EXPECT_EQ(ids_tiny.indices, ids.indices);
}

TEST(Welder, EmptyInput) {
    Welded w = weld({}, 1 << 20);
    EXPECT_TRUE(w.xyz.empty());
    EXPECT_TRUE(w.indices.empty());
}

TEST(RecordSorter, SortsAcrossSpilledRuns) {
    std::mt19937_64 rng(42);
    std::vector<uint64_t> values(30000);
    for (auto& v : values) v = rng() % 5000;
    for (uint64_t budget : {uint64_t{1} << 30, uint64_t{16} << 10}) {
        io::RecordSorter<uint64_t, std::less<uint64_t>> sorter(budget, {});
        for (uint64_t v : values) sorter.push(v);
        sorter.finish_input(budget);
        EXPECT_EQ(sorter.spilled(), budget < (1u << 20));
        std::vector<uint64_t> out;
        uint64_t v;
        while (sorter.next(v)) out.push_back(v);
        std::vector<uint64_t> expect = values;
        std::sort(expect.begin(), expect.end());
        EXPECT_EQ(out, expect);
    }
}

TEST(RecordSorter, MergesInLevelsWhenRunsOutnumberTheMergeBudget) {
    // 15 runs of 2 048 records, and a merge budget of 64 KiB, three blocks of the least size
    // (16 KiB): merged three at a time (15 → 5 → 2) before the last merge, instead of giving
    // all 15 runs a block of at least 16 KiB each (240 KiB).
    std::mt19937_64 rng(7);
    std::vector<uint64_t> values(30000);
    for (auto& v : values) v = rng() % 100000;
    test::TempDir dir;
    io::RecordSorter<uint64_t, std::less<uint64_t>> sorter(16 << 10, dir.path());
    for (uint64_t v : values) sorter.push(v);
    sorter.finish_input(64 << 10);
    EXPECT_TRUE(sorter.spilled());
    EXPECT_LE(sorter.merge_block_bytes(), uint64_t{64} << 10);
    EXPECT_EQ(dir.entries().size(), 1u);  // the earlier levels' files are gone
    std::vector<uint64_t> out;
    uint64_t v;
    while (sorter.next(v)) out.push_back(v);
    std::sort(values.begin(), values.end());
    EXPECT_EQ(out, values);
}

TEST(Welder, CornersOfOnePositionWithOtherAttributesStayApart) {
    // Two triangles sharing an edge whose corners differ in colour on one side: a colour seam.
    const std::vector<float> soup = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    io::Channels ch;
    ch.color = io::ColorFormat{};
    for (uint64_t budget : {uint64_t{1} << 20, uint64_t{0}}) {
        test::TempDir dir;
        io::Welder w(budget, dir.path(), "test", ch);
        io::TriangleChunk chunk(2, ch);
        for (int t = 0; t < 2; ++t) {
            float* p = chunk.push_slot();
            std::copy(soup.begin() + 9 * t, soup.begin() + 9 * t + 9, p);
            for (int k = 0; k < 3; ++k) chunk.color_at(size_t(t))[4 * k] = t == 0 ? 1.0f : 0.0f;  // red, then black
        }
        w.add(chunk);
        w.finish();
        EXPECT_EQ(w.vertex_count(), 6u) << budget;  // the shared edge's two positions twice
        EXPECT_EQ(w.layout().bytes(), 3u);
    }
}

TEST(Welder, RefusesCornerRecordsPastItsLimit) {
    io::Channels ch;
    for (int c = 0; c < 40; ++c) {
        std::string name = "s";
        name += std::to_string(c);
        ch.vertex_scalars.push_back({name, io::ScalarType::kFloat64});
    }
    test::TempDir dir;
    try {
        io::Welder w(1 << 20, dir.path(), "out.ply", ch);
        FAIL() << "no error";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("out.ply: 320 bytes of vertex attributes per corner"), std::string::npos)
            << e.what();
    }
}
