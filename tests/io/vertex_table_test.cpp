// The vertex table returns what was appended whether it sits in memory, in a spilled and
// mapped temp file (with reads while still appending), or in a mapped input file.
#include "io/vertex_table.hpp"

#include "indexed_test_util.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

using namespace meshstream;

namespace {

void expect_vertex(io::VertexTable& t, uint64_t i) {
    float xyz[3];
    uint8_t rgb[3];
    t.get(i, xyz, rgb);
    ASSERT_EQ(xyz[0], static_cast<float>(i) * 0.5f) << i;
    ASSERT_EQ(xyz[1], -static_cast<float>(i)) << i;
    ASSERT_EQ(xyz[2], 3.0f) << i;
    if (t.color()) {
        ASSERT_EQ(rgb[1], static_cast<uint8_t>(i)) << i;
    }
}

}  // namespace

TEST(VertexTable, SpillsPastTheBudgetAndReadsWhileAppending) {
    for (bool color : {false, true}) {
        test::TempDir dir;
        io::VertexTable t(1 << 20, dir.path(), color);
        const uint64_t n = 150000;  // 1.8-2.4 MB: past the budget and the 1 MiB tail
        for (uint64_t i = 0; i < n; ++i) {
            const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
            const uint8_t rgb[3] = {1, static_cast<uint8_t>(i), 2};
            t.append(xyz, rgb);
            if (i % 9973 == 0) {  // OBJ reads earlier vertices between appends
                expect_vertex(t, i);
                expect_vertex(t, i / 2);
            }
        }
        EXPECT_EQ(t.storage(), io::VertexTable::Storage::kTempFile);
        EXPECT_EQ(dir.entries().size(), 1u);
        for (uint64_t i = 0; i < n; i += 7) expect_vertex(t, i);
        for (uint64_t i = n / 4; i-- > 0;) expect_vertex(t, (i * 7919) % n);  // scattered: drops pages
    }
}

TEST(VertexTable, StaysInMemoryWithinTheBudget) {
    io::VertexTable t(1 << 20, {}, false);
    for (uint64_t i = 0; i < 1000; ++i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        t.append(xyz, nullptr);
    }
    EXPECT_EQ(t.storage(), io::VertexTable::Storage::kMemory);
    for (uint64_t i = 0; i < 1000; ++i) expect_vertex(t, i);
}

TEST(VertexTable, MapsRecordsOfAnInputFile) {
    test::TempDir dir;
    // 5 junk bytes, then records of 20 bytes: pad(2) x y z pad(3) r g b ... (stride 20).
    std::string bytes(5, 'j');
    const uint64_t n = 5000;
    for (uint64_t i = 0; i < n; ++i) {
        char rec[20] = {};
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        std::memcpy(rec + 2, xyz, 12);
        rec[17] = static_cast<char>(i);
        bytes.append(rec, 20);
    }
    test::spit(dir / "v.bin", bytes);
    const size_t xyz_offsets[3] = {2, 6, 10};
    const size_t rgb_offsets[3] = {16, 17, 18};
    auto t = io::VertexTable::map_input_file(dir / "v.bin", 5, n, 20, xyz_offsets, rgb_offsets, 16 << 10);
    EXPECT_EQ(t->storage(), io::VertexTable::Storage::kInputFile);
    for (uint64_t i = n; i-- > 0;) expect_vertex(*t, (i * 31) % n);
}

namespace {
// The process's resident set now (not its peak), from /proc/self/statm.
uint64_t resident_bytes() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (f == nullptr) return 0;
    unsigned long long size = 0, resident = 0;
    const int got = std::fscanf(f, "%llu %llu", &size, &resident);
    std::fclose(f);
    return got == 2 ? resident * static_cast<uint64_t>(sysconf(_SC_PAGESIZE)) : 0;
}
}  // namespace

// Reading one record per 64 KiB of a cached 48 MB table: Linux maps the cached neighbours of
// every faulted page too, so counting only the pages touched let the whole table become
// resident. The table must stay near its 1 MiB budget.
TEST(VertexTable, MappedTableStaysWithinItsBudgetWhenReadSparsely) {
    test::TempDir dir;
    const uint64_t n = uint64_t{4} << 20;  // 12-byte records: 48 MiB
    std::string bytes(n * 12, '\0');
    for (uint64_t i = 0; i < n; ++i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        std::memcpy(&bytes[i * 12], xyz, 12);
    }
    test::spit(dir / "v.bin", bytes);  // now in the page cache, where fault-around finds it
    bytes = {};
    const size_t xyz_offsets[3] = {0, 4, 8};
    const uint64_t budget = uint64_t{1} << 20;
    auto t = io::VertexTable::map_input_file(dir / "v.bin", 0, n, 12, xyz_offsets, nullptr, budget);
    const uint64_t before = resident_bytes();
    ASSERT_GT(before, 0u);
    uint64_t peak = before;
    const uint64_t step = (uint64_t{64} << 10) / 12 + 1;  // one record per 64 KiB block
    for (uint64_t i = 0, reads = 0; i < n; i += step, ++reads) {
        expect_vertex(*t, i);
        if (reads % 8 == 0) peak = std::max(peak, resident_bytes());
    }
    EXPECT_LT(peak - before, budget + (uint64_t{4} << 20)) << "resident growth " << (peak - before) << " bytes";
}
