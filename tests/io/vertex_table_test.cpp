// The vertex table returns what was appended whether it sits in memory, in a spilled temp
// file (with reads while still appending), or in an input file read in place; read from a
// file, it stays within its budget.
#include "io/vertex_table.hpp"

#include "indexed_test_util.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

using namespace meshstream;

namespace {

// Vertex i: (i/2, -i, 3), and when the table has 3-byte records, (1, i mod 256, 2).
void expect_vertex(io::VertexTable& t, uint64_t i) {
    float xyz[3];
    std::byte attributes[3] = {};
    t.get(i, xyz, attributes);
    ASSERT_EQ(xyz[0], static_cast<float>(i) * 0.5f) << i;
    ASSERT_EQ(xyz[1], -static_cast<float>(i)) << i;
    ASSERT_EQ(xyz[2], 3.0f) << i;
    if (t.attribute_bytes() > 0) {
        ASSERT_EQ(attributes[0], std::byte{1}) << i;
        ASSERT_EQ(attributes[1], static_cast<std::byte>(i)) << i;
        ASSERT_EQ(attributes[2], std::byte{2}) << i;
    }
}

// Appends vertices 0 .. n-1 as expect_vertex reads them.
void append_vertices(io::VertexTable& t, uint64_t n) {
    for (uint64_t i = 0; i < n; ++i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        const std::byte attributes[3] = {std::byte{1}, static_cast<std::byte>(i), std::byte{2}};
        t.append(xyz, attributes);
    }
}

// A table of n vertices (expect_vertex's) read in place from `dir`/v.bin: 5 junk bytes, then
// records of 20 bytes, pad(2) x y z pad(8); a cache of 16 KiB.
std::unique_ptr<io::VertexTable> input_file_table(const test::TempDir& dir, uint64_t n) {
    std::string bytes(5, 'j');
    for (uint64_t i = 0; i < n; ++i) {
        char rec[20] = {};
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        std::memcpy(rec + 2, xyz, 12);
        bytes.append(rec, 20);
    }
    test::spit(dir / "v.bin", bytes);
    const size_t xyz_offsets[3] = {2, 6, 10};
    return io::VertexTable::of_input_file(dir / "v.bin", 5, n, 20, xyz_offsets, 16 << 10);
}

}  // namespace

TEST(VertexTable, SpillsPastTheBudgetAndReadsWhileAppending) {
    for (size_t attribute_bytes : {0, 3}) {
        test::TempDir dir;
        io::VertexTable t(1 << 20, dir.path(), attribute_bytes);
        const uint64_t n = 150000;  // 1.8-2.4 MB: past the budget and the 1 MiB tail
        for (uint64_t i = 0; i < n; ++i) {
            const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
            const std::byte attributes[3] = {std::byte{1}, static_cast<std::byte>(i), std::byte{2}};
            t.append(xyz, attributes);
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

// The page holding the end of the spilled file is cached short when a record there is read;
// records appended later fill the rest of it, and must be read from the file again.
TEST(VertexTable, APageCachedAtTheFilesEndIsReadAgainOnceItGrows) {
    test::TempDir dir;
    io::VertexTable t(1 << 20, dir.path(), 0);
    auto add = [&](uint64_t i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        t.append(xyz, nullptr);
    };
    uint64_t n = 0;
    while (t.storage() == io::VertexTable::Storage::kMemory) add(n++);
    // Spilled: the file holds 87 381 records (1 048 572 bytes, a page's last 4 bytes short).
    expect_vertex(t, 87380);
    while (n < 3 * 87381) add(n++);  // past two tail flushes
    for (uint64_t i = 87370; i < 87400; ++i) expect_vertex(t, i);
}

TEST(VertexTable, StaysInMemoryWithinTheBudget) {
    io::VertexTable t(1 << 20, {}, 0);
    for (uint64_t i = 0; i < 1000; ++i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        t.append(xyz, nullptr);
    }
    EXPECT_EQ(t.storage(), io::VertexTable::Storage::kMemory);
    for (uint64_t i = 0; i < 1000; ++i) expect_vertex(t, i);
}

// A reader that shares its budget among tables lowers it: a table in memory past the new
// budget spills at once, a spilled one keeps its records under a smaller page cache.
TEST(VertexTable, ALowerBudgetSpillsOrShrinksTheCacheAndKeepsEveryRecord) {
    test::TempDir dir;
    io::VertexTable t(uint64_t{8} << 20, dir.path(), 3);
    auto add = [&](uint64_t i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        const std::byte attributes[3] = {std::byte{1}, static_cast<std::byte>(i), std::byte{2}};
        t.append(xyz, attributes);
    };
    uint64_t n = 0;
    for (; n < 20000; ++n) add(n);  // 300 KB
    t.set_budget(uint64_t{1} << 20);
    EXPECT_EQ(t.storage(), io::VertexTable::Storage::kMemory);
    t.set_budget(100 << 10);
    EXPECT_EQ(t.storage(), io::VertexTable::Storage::kTempFile);
    EXPECT_EQ(dir.entries().size(), 1u);
    for (uint64_t i = 0; i < n; i += 3) expect_vertex(t, i);
    for (; n < 150000; ++n) add(n);
    t.set_budget(64 << 10);
    for (uint64_t i = n; i-- > 0;) expect_vertex(t, (i * 7919) % n);
}
TEST(VertexTable, ReadsRecordsOfAnInputFileInPlace) {
    test::TempDir dir;
    const uint64_t n = 5000;
    auto t = input_file_table(dir, n);
    EXPECT_EQ(t->storage(), io::VertexTable::Storage::kInputFile);
    for (uint64_t i = n; i-- > 0;) expect_vertex(*t, (i * 31) % n);
}

// Positions read in bulk are the records' whatever the storage: from memory, from a spilled
// temp file and its unflushed tail, and from an input file (past 1 MiB, in several reads),
// from any first record. Prefetched records read the same.
TEST(VertexTable, PositionsReadInBulkAndPrefetchedRecordsAreTheRecords) {
    test::TempDir dir;
    auto expect_positions = [](io::VertexTable& t) {
        const uint64_t n = t.size();
        for (uint64_t first : {uint64_t{0}, uint64_t{1}, n / 3}) {
            std::vector<float> xyz(3 * (n - first) + 3, -7.0f);
            t.positions(first, n - first, xyz.data());
            for (uint64_t i = first; i < n; ++i) {
                ASSERT_EQ(xyz[3 * (i - first)], static_cast<float>(i) * 0.5f) << i;
                ASSERT_EQ(xyz[3 * (i - first) + 1], -static_cast<float>(i)) << i;
                ASSERT_EQ(xyz[3 * (i - first) + 2], 3.0f) << i;
            }
            EXPECT_EQ(xyz.back(), -7.0f);  // nothing past the count
        }
        expect_vertex(t, n / 2);  // the cache still reads
        for (uint64_t i = 0; i < n; i += 97) t.prefetch(i);  // a hint: it changes nothing read
        for (uint64_t i = 0; i < n; i += 89) expect_vertex(t, i);
    };
    for (uint64_t budget : {uint64_t{64} << 20, uint64_t{1} << 20}) {
        io::VertexTable t(budget, dir.path(), 3);
        append_vertices(t, 150000);  // 2.25 MB
        EXPECT_EQ(t.storage(), budget > (4u << 20) ? io::VertexTable::Storage::kMemory : io::VertexTable::Storage::kTempFile);
        expect_positions(t);
    }
    expect_positions(*input_file_table(dir, 100000));  // 2 MB
}

// A split table and its second reader read every record right at once on two threads, in
// memory and from a spilled file (each through half the budget's cache).
TEST(VertexTable, ASplitTablesTwoReadersReadTheirRecordsOnTwoThreads) {
    test::TempDir dir;
    for (uint64_t budget : {uint64_t{64} << 20, uint64_t{64} << 10}) {
        io::VertexTable t(budget, dir.path(), 3);
        const uint64_t n = 150000;
        append_vertices(t, n);
        std::unique_ptr<io::VertexTable> second = t.split();
        EXPECT_EQ(second->size(), n);
        EXPECT_EQ(second->storage(), t.storage());
        std::thread other([&] {
            for (uint64_t i = n; i-- > 0;) expect_vertex(*second, (i * 7919) % n);
        });
        for (uint64_t i = 0; i < n; ++i) expect_vertex(t, (i * 104729) % n);
        other.join();
    }
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

// Reads one record per `step_bytes` of a 48 MiB table in a file, with the given
// budget; returns the peak growth of the resident set.
uint64_t resident_growth_of_sparse_reads(const std::string& path, uint64_t budget, uint64_t step_bytes) {
    const uint64_t n = uint64_t{4} << 20;  // 12-byte records: 48 MiB
    const size_t xyz_offsets[3] = {0, 4, 8};
    auto t = io::VertexTable::of_input_file(path, 0, n, 12, xyz_offsets, budget);
    const uint64_t before = resident_bytes();
    EXPECT_GT(before, 0u);
    uint64_t peak = before;
    for (uint64_t i = 0, reads = 0; i < n; i += step_bytes / 12 + 1, ++reads) {
        expect_vertex(*t, i);
        if (reads % 4 == 0) peak = std::max(peak, resident_bytes());
    }
    return peak - before;
}

std::string table_bytes() {
    const uint64_t n = uint64_t{4} << 20;
    std::string bytes(n * 12, '\0');
    for (uint64_t i = 0; i < n; ++i) {
        const float xyz[3] = {static_cast<float>(i) * 0.5f, -static_cast<float>(i), 3.0f};
        std::memcpy(&bytes[i * 12], xyz, 12);
    }
    return bytes;
}
}  // namespace

// Reading one record per 64 KiB of a cached 48 MB table: when the table was read through mmap,
// Linux mapped the cached neighbours of every faulted page too, and counting only the pages
// touched let the whole table become resident. The table must stay near its 1 MiB budget.
TEST(VertexTable, FileTableStaysWithinItsBudgetWhenReadSparsely) {
    test::TempDir dir;
    test::spit(dir / "v.bin", table_bytes());  // now in the page cache, where fault-around finds it
    const uint64_t growth = resident_growth_of_sparse_reads(dir / "v.bin", uint64_t{1} << 20, uint64_t{64} << 10);
    EXPECT_LT(growth, uint64_t{2} << 20) << "resident growth " << growth << " bytes";
}

// The same for a file the page cache read ahead, as a PLY read before its faces: readahead
// fills large folios, and through mmap Linux mapped a faulted page's whole folio (2 MiB,
// measured on 6.18): accounting 64 KiB blocks, one record read per 256 KiB made 22 MiB
// resident against a budget of 8 MiB.
TEST(VertexTable, FileTableStaysWithinItsBudgetWhenTheFileWasReadAhead) {
    test::TempDir dir;
    const std::string path = dir / "v.bin";
    test::spit(path, table_bytes());
    {
        // Out of the page cache (written back first), then read back in sequentially.
        const int fd = ::open(path.c_str(), O_RDONLY);
        ASSERT_GE(fd, 0);
        ASSERT_EQ(::fdatasync(fd), 0);
        ASSERT_EQ(::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED), 0);
        std::vector<char> buffer(size_t{1} << 20);
        while (::read(fd, buffer.data(), buffer.size()) > 0) {}
        ::close(fd);
    }
    const uint64_t budget = uint64_t{8} << 20;
    const uint64_t growth = resident_growth_of_sparse_reads(path, budget, uint64_t{256} << 10);
    EXPECT_LT(growth, budget + (uint64_t{1} << 20)) << "resident growth " << growth << " bytes";
}
