// Welding: the hash path and the external-sort path give the same vertices and indices;
// -0.0 welds with +0.0; vertex ids keep coincident vertices apart; the record sorter sorts
// across spilled runs.
#include "io/weld.hpp"

#include "io/record_sort.hpp"
#include "indexed_test_util.hpp"

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
        io::Welder w(budget, dir.path(), "test");
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
            if (channels.color)
                for (int k = 0; k < 9; ++k) chunk.rgb_at(i)[k] = static_cast<uint8_t>(t + k);
        }
        w.add(chunk);
        w.finish();
        out.out_of_core = w.out_of_core();
        std::vector<io::WeldedVertex> vs(100);
        while (size_t n = w.next_vertices(vs))
            for (size_t i = 0; i < n; ++i) {
                out.xyz.insert(out.xyz.end(), vs[i].xyz, vs[i].xyz + 3);
                out.rgb.insert(out.rgb.end(), vs[i].rgb, vs[i].rgb + 3);
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
        ch.color = color;
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
