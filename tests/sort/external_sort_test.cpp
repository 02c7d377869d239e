// Tests of the external merge sort (sort/external_sort.hpp), chunks in and chunks out: order,
// bit-exact multiset, stability, multi-pass merging under a tiny budget, channels, and
// temporary-file cleanup.
#include "sort/external_sort.hpp"

#include "io/error.hpp"
#include "sort/radix.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

namespace fs = std::filesystem;
using namespace meshstream;
using Tri = std::array<float, 9>;

using meshstream::test::TempDir;

namespace {

// A fresh directory under the system temp dir, removed with its contents afterwards.
// Binary STL read by hand (84-byte header, 50-byte facets) so this test needs no format code.
std::vector<Tri> read_binary_stl(const std::string& name) {
    std::ifstream in(std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    uint32_t n;
    std::memcpy(&n, bytes.data() + 80, 4);
    EXPECT_EQ(bytes.size(), 84 + 50 * size_t{n});
    std::vector<Tri> tris(n);
    for (uint32_t i = 0; i < n; ++i) std::memcpy(tris[i].data(), bytes.data() + 84 + 50 * size_t{i} + 12, 36);
    return tris;
}

struct Result {
    std::vector<Tri> tris;
    sort::SortStats stats;
};

Result sort_triangles(const std::vector<Tri>& input, sort::SorterOptions options, size_t chunk_capacity = 1000) {
    sort::ExternalSorter sorter(options);
    io::TriangleChunk chunk(chunk_capacity);
    for (const Tri& t : input) {
        chunk.push(reinterpret_cast<const float(&)[9]>(*t.data()));
        if (chunk.full()) {
            sorter.add(chunk);
            chunk.clear();
        }
    }
    if (!chunk.empty()) sorter.add(chunk);
    sorter.finish_input();
    Result r;
    while (sorter.next(chunk)) {
        auto xyz = chunk.xyz();
        for (size_t i = 0; i < chunk.size(); ++i) std::memcpy(r.tris.emplace_back().data(), &xyz[9 * i], 36);
    }
    r.stats = sorter.stats();
    return r;
}

// The reference: std::stable_sort by the same key.
std::vector<Tri> stable_sorted(std::vector<Tri> tris, int axis) {
    std::stable_sort(tris.begin(), tris.end(), [axis](const Tri& a, const Tri& b) {
        return sort::triangle_key(a.data(), axis) < sort::triangle_key(b.data(), axis);
    });
    return tris;
}

bool bytes_less(const Tri& a, const Tri& b) { return std::memcmp(a.data(), b.data(), sizeof(Tri)) < 0; }

// Triangles whose z keys take `distinct` values; x of corner 0 holds the input position.
std::vector<Tri> generated(size_t n, uint32_t distinct, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<Tri> tris(n);
    for (size_t i = 0; i < n; ++i) {
        float z = static_cast<float>(rng() % distinct) * 0.25f;
        tris[i] = {float(i), 1, z + 1, 2, 3, z, 4, 5, z + 0.5f};
    }
    return tris;
}

}  // namespace

TEST(ExternalSorter, ShuffledFixtureComesOutSortedBitExact) {
    std::vector<Tri> bunny = read_binary_stl("bunny_from_draco.bin.stl");
    ASSERT_EQ(bunny.size(), 69451u);
    std::vector<Tri> shuffled = bunny;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(7));
    TempDir dir;
    for (int axis = 0; axis < 3; ++axis) {
        for (uint64_t budget : {uint64_t{512} << 10, uint64_t{64} << 20}) {
            sort::SorterOptions o;
            o.axis = axis;
            o.memory_budget_bytes = budget;
            o.tmpdir = dir.path().string();
            Result r = sort_triangles(shuffled, o, 777);
            ASSERT_EQ(r.tris.size(), bunny.size());
            for (size_t i = 1; i < r.tris.size(); ++i)
                ASSERT_LE(sort::triangle_key(r.tris[i - 1].data(), axis), sort::triangle_key(r.tris[i].data(), axis))
                    << "axis " << axis << " at " << i;
            // Same multiset of triangles, bit for bit.
            std::vector<Tri> a = r.tris, b = bunny;
            std::sort(a.begin(), a.end(), bytes_less);
            std::sort(b.begin(), b.end(), bytes_less);
            ASSERT_TRUE(std::memcmp(a.data(), b.data(), a.size() * sizeof(Tri)) == 0);
            if (budget < (uint64_t{1} << 20)) {
                EXPECT_EQ(r.stats.runs, 7u);  // 69451 / (512 KiB / 52 B)
                EXPECT_EQ(r.stats.merge_passes, 1);
            } else {
                EXPECT_EQ(r.stats.runs, 0u);  // fits in memory: no temporary file
                EXPECT_EQ(r.stats.temp_bytes_written, 0u);
            }
            EXPECT_EQ(dir.file_count(), 0u);
        }
    }
}

TEST(ExternalSorter, EqualKeysKeepInputOrderAcrossRuns) {
    std::vector<Tri> input = generated(60000, 5, 1);
    TempDir dir;
    sort::SorterOptions o;
    o.memory_budget_bytes = 256 << 10;  // runs of 5041 triangles
    o.tmpdir = dir.path().string();
    Result r = sort_triangles(input, o);
    EXPECT_GT(r.stats.runs, 10u);
    ASSERT_EQ(r.tris.size(), input.size());
    for (size_t i = 1; i < r.tris.size(); ++i)
        if (r.tris[i - 1][5] == r.tris[i][5]) {
            ASSERT_LT(r.tris[i - 1][0], r.tris[i][0]) << "at " << i;
        }
    EXPECT_TRUE(r.tris == stable_sorted(input, 2));
}

TEST(ExternalSorter, KeysGivenByTheCallerSortAsTheKeyFunctionDoes) {
    // A caller's key function over x, its keys computed by the caller: the same output as the
    // sorter computing them, across spilled runs (equal keys in input order).
    std::vector<Tri> input = generated(30000, 7, 3);
    for (size_t i = 0; i < input.size(); ++i) input[i][0] = float((i * 7919) % 1000);
    TempDir dir;
    sort::SorterOptions o;
    o.memory_budget_bytes = 256 << 10;
    o.tmpdir = dir.path().string();
    o.key = [](const float* xyz) { return uint32_t(xyz[0]) / 3; };
    const Result expected = sort_triangles(input, o);
    sort::ExternalSorter sorter(o);
    io::TriangleChunk chunk(1000);
    std::vector<uint32_t> keys;
    for (size_t i = 0; i < input.size(); ++i) {
        chunk.push(reinterpret_cast<const float(&)[9]>(*input[i].data()));
        keys.push_back(uint32_t(input[i][0]) / 3);
        if (chunk.full() || i + 1 == input.size()) {
            sorter.add(chunk, keys);
            chunk.clear();
            keys.clear();
        }
    }
    sorter.finish_input();
    EXPECT_GT(sorter.stats().runs, 2u);
    std::vector<Tri> out;
    while (sorter.next(chunk))
        for (size_t i = 0; i < chunk.size(); ++i) std::memcpy(out.emplace_back().data(), &chunk.xyz()[9 * i], 36);
    ASSERT_EQ(out.size(), input.size());
    EXPECT_TRUE(out == expected.tris);
    for (size_t i = 1; i < out.size(); ++i) ASSERT_LE(uint32_t(out[i - 1][0]) / 3, uint32_t(out[i][0]) / 3) << i;
}

TEST(ExternalSorter, MultiPassMergeUnderTinyBudget) {
    // 500 000 triangles in 768 KiB (what `sort --memory 1M` gives the sorter): 34 runs, at most
    // 12 read buffers of 64 KiB, so one intermediate pass precedes the final merge.
    std::vector<Tri> input = generated(500000, 100000, 2);
    TempDir dir;
    sort::SorterOptions o;
    o.memory_budget_bytes = 768 << 10;
    o.tmpdir = dir.path().string();
    int passes_seen = 0;
    o.on_merge_progress = [&](int pass, int pass_count, uint64_t) {
        passes_seen = std::max(passes_seen, pass);
        EXPECT_EQ(pass_count, 2);
    };
    sort::ExternalSorter sorter(o);
    io::TriangleChunk chunk(4096);
    for (const Tri& t : input) {
        chunk.push(reinterpret_cast<const float(&)[9]>(*t.data()));
        if (chunk.full()) {
            sorter.add(chunk);
            chunk.clear();
        }
    }
    sorter.add(chunk);
    EXPECT_EQ(dir.file_count(), 1u);  // all runs share one file
    sorter.finish_input();
    EXPECT_EQ(passes_seen, 1);
    EXPECT_EQ(sorter.stats().merge_passes, 2);
    EXPECT_EQ(sorter.stats().runs, 34u);
    EXPECT_EQ(dir.file_count(), 1u);  // the first generation is gone
    std::vector<Tri> out;
    while (sorter.next(chunk)) {
        auto xyz = chunk.xyz();
        for (size_t i = 0; i < chunk.size(); ++i) std::memcpy(out.emplace_back().data(), &xyz[9 * i], 36);
    }
    EXPECT_EQ(dir.file_count(), 0u);  // removed as soon as the output is complete
    EXPECT_TRUE(out == stable_sorted(input, 2));
    const size_t data_bytes = input.size() * 36;
    EXPECT_EQ(sorter.stats().temp_bytes_written, 2 * data_bytes);
    // Hole punching (tmpfs, ext4, xfs) keeps the disk use near one copy; without it, two.
    EXPECT_LE(sorter.stats().peak_temp_bytes, 2 * data_bytes);
}

TEST(ExternalSorter, CarriesChannelsWithTheirTriangle) {
    io::Channels ch;
    ch.normal = true;
    ch.color = io::ColorFormat{};
    ch.vertex_id = true;
    sort::SorterOptions o;
    o.channels = ch;
    o.memory_budget_bytes = 64 << 10;  // 1024-triangle runs
    TempDir dir;
    o.tmpdir = dir.path().string();
    EXPECT_EQ(sort::ExternalSorter::record_bytes_for(ch), 36u + 9 + 36 + 24);  // colour as RGB8
    sort::ExternalSorter sorter(o);
    io::TriangleChunk chunk(300, ch);
    const int n = 5000;
    std::mt19937 rng(3);
    for (int i = 0; i < n; ++i) {
        if (chunk.full()) {
            sorter.add(chunk);
            chunk.clear();
        }
        float z = float(rng() % 1000);
        float* p = chunk.push_slot();
        const float tri[9] = {float(i), 0, z, 1, 0, z, 0, 1, z};
        std::memcpy(p, tri, sizeof tri);
        size_t k = chunk.size() - 1;
        for (int c = 0; c < 12; ++c) chunk.color_at(k)[c] = c % 4 == 3 ? 1.0f : float(uint8_t(i + c)) / 255.0f;
        for (int c = 0; c < 9; ++c) chunk.normal_at(k)[c] = float(i) + 0.5f * c;
        for (int c = 0; c < 3; ++c) chunk.id_at(k)[c] = uint64_t(i) * 3 + c;
    }
    sorter.add(chunk);
    sorter.finish_input();
    EXPECT_GT(sorter.stats().runs, 1u);
    int seen = 0;
    float prev_z = -1;
    while (sorter.next(chunk)) {
        for (size_t k = 0; k < chunk.size(); ++k, ++seen) {
            const float* p = &chunk.xyz()[9 * k];
            int i = int(p[0]);
            ASSERT_GE(p[2], prev_z);
            prev_z = p[2];
            for (int c = 0; c < 12; ++c)
                ASSERT_EQ(chunk.colors()[12 * k + c], c % 4 == 3 ? 1.0f : float(uint8_t(i + c)) / 255.0f);
            for (int c = 0; c < 9; ++c) ASSERT_EQ(chunk.normals()[9 * k + c], float(i) + 0.5f * c);
            for (int c = 0; c < 3; ++c) ASSERT_EQ(chunk.vertex_ids()[3 * k + c], uint64_t(i) * 3 + c);
        }
    }
    EXPECT_EQ(seen, n);
}

TEST(ExternalSorter, AbandonedSortLeavesNoTemporaryFiles) {
    std::vector<Tri> input = generated(50000, 1000, 4);
    TempDir dir;
    sort::SorterOptions o;
    o.memory_budget_bytes = 128 << 10;
    o.tmpdir = dir.path().string();
    {
        // Input fails half-way (the caller's reader throws): the sorter unwinds.
        sort::ExternalSorter sorter(o);
        io::TriangleChunk chunk(1000);
        for (size_t i = 0; i < input.size() / 2; ++i) {
            chunk.push(reinterpret_cast<const float(&)[9]>(*input[i].data()));
            if (chunk.full()) {
                sorter.add(chunk);
                chunk.clear();
            }
        }
        EXPECT_EQ(dir.file_count(), 1u);
    }
    EXPECT_EQ(dir.file_count(), 0u);
    {
        // Output fails half-way through the final merge.
        sort::ExternalSorter sorter(o);
        io::TriangleChunk chunk(1000);
        for (const Tri& t : input) {
            chunk.push(reinterpret_cast<const float(&)[9]>(*t.data()));
            if (chunk.full()) {
                sorter.add(chunk);
                chunk.clear();
            }
        }
        sorter.finish_input();
        ASSERT_TRUE(sorter.next(chunk));
        EXPECT_EQ(dir.file_count(), 1u);
    }
    EXPECT_EQ(dir.file_count(), 0u);
}

TEST(ExternalSorter, MissingTmpdirIsAnErrorNamingIt) {
    sort::SorterOptions o;
    o.memory_budget_bytes = 64 << 10;
    o.tmpdir = "/nonexistent-meshstream-dir";
    sort::ExternalSorter sorter(o);
    io::TriangleChunk chunk(2000);
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    while (!chunk.full()) chunk.push(tri);
    try {
        sorter.add(chunk);  // 2000 > one 1024-triangle run: the first spill creates the file
        FAIL() << "expected io::Error";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-meshstream-dir"), std::string::npos) << e.what();
    }
}

TEST(ExternalSorter, EmptyInput) {
    sort::ExternalSorter sorter(sort::SorterOptions{});
    sorter.finish_input();
    io::TriangleChunk chunk(10);
    EXPECT_FALSE(sorter.next(chunk));
    EXPECT_EQ(sorter.triangle_count(), 0u);
}
