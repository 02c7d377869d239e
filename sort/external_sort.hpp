// Out-of-core sorting of a triangle stream by its sort key (sort/radix.hpp): chunks in, chunks
// out, no format I/O. Classic external merge sort (Knuth TAOCP vol. 3, §5.4.1, replacement by
// fixed-size runs): triangles are gathered into runs that fill the memory budget, each run is
// radix-sorted in memory and appended as compact binary records to one temporary file; then
// the runs are merged k ways with large buffered reads. When more runs exist than read buffers
// fit in the budget, consecutive groups of runs are first merged into a second temporary file
// (a multi-pass merge), so memory stays bounded for any input size. Input that fits in one run
// never touches the disk.
//
// Stable and deterministic: equal keys keep their input order (the radix sort is stable, and
// merges break key ties by run number, runs being numbered in input order).
//
// Memory: at most `memory_budget_bytes` for run records, sort arrays and merge read buffers,
// plus a constant ~3 MiB (one 1 MiB staging buffer, and the 1 MiB write buffer of each of the
// at most two live io::TempFile objects). Temporary disk: about the record size × triangles;
// consumed parts of run files are released with hole punching where the file system allows.
// Temporary files are io::TempFile objects: removed by their destructors on success or error,
// and by io::install_cleanup_handlers' handler on SIGINT/SIGTERM/SIGHUP.
#pragma once

#include "io/byte_stream.hpp"
#include "io/chunk.hpp"
#include "io/triangle_records.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace meshstream::sort {

struct SorterOptions {
    int axis = 2;                                        // 0 = x, 1 = y, 2 = z
    // A key of the caller's instead of the axis key: a triangle's 9 coordinates to its 32-bit
    // key (e.g. an octree cell's Morton code). Must be deterministic.
    std::function<uint32_t(const float* xyz)> key;
    uint64_t memory_budget_bytes = uint64_t{192} << 20;  // runs + merge buffers (see above)
    std::string tmpdir;                                  // empty: $TMPDIR or /tmp
    io::Channels channels;                               // channels carried through the sort
    // Called during intermediate merge passes (which run inside finish_input()) with the pass
    // number (1-based), the number of passes planned and triangles merged so far in this pass.
    // May be empty.
    std::function<void(int pass, int pass_count, uint64_t merged)> on_merge_progress;
};

struct SortStats {
    uint64_t triangles = 0;
    uint64_t runs = 0;                // runs written to disk (0: sorted in memory)
    uint64_t run_capacity = 0;        // triangles per run
    int merge_passes = 0;             // passes over the data after run generation, incl. the final one
    uint64_t temp_bytes_written = 0;  // all temporary-file writes
    uint64_t peak_temp_bytes = 0;     // largest temporary disk use at any time (after hole punching)
    size_t record_bytes = 0;          // bytes per triangle record on disk
};

class ExternalSorter {
public:
    // Throws io::Error only later, from add()/finish_input() (temporary files are created lazily).
    explicit ExternalSorter(SorterOptions options);
    ~ExternalSorter();
    ExternalSorter(const ExternalSorter&) = delete;
    ExternalSorter& operator=(const ExternalSorter&) = delete;

    // Adds a chunk's triangles. Precondition: finish_input() not called yet, and
    // chunk.channels() == options.channels. Throws io::Error when a temporary file cannot be
    // created or written (e.g. the disk is full); the sorter is then unusable.
    void add(const io::TriangleChunk& chunk);
    // The same for a caller that has computed the triangles' keys already: keys[i] is chunk
    // triangle i's, as options.key gives it (the merge computes the keys of the runs' heads
    // again from their triangles).
    void add(const io::TriangleChunk& chunk, std::span<const uint32_t> keys);
    // Ends the input: sorts the last run and, when needed, runs the intermediate merge passes
    // (the long part for big inputs; reported through on_merge_progress). Throws io::Error.
    void finish_input();
    // Fills `chunk` (cleared first) with the next triangles in key order; false once all were
    // returned. Precondition: finish_input() was called; chunk has the sorter's channels.
    // Throws io::Error on temporary-file read failures.
    bool next(io::TriangleChunk& chunk);

    uint64_t triangle_count() const { return stats_.triangles; }
    const SortStats& stats() const { return stats_; }

    // Triangles per in-memory run for a budget and record size (at least 1024).
    static uint64_t run_capacity_for(uint64_t memory_budget_bytes, size_t record_bytes);
    // Bytes per record for the given channels (io::TriangleRecords: 36 for positions only).
    static size_t record_bytes_for(const io::Channels& channels);

private:
    struct Segment {
        uint64_t offset;  // byte offset in the run file
        uint64_t count;   // triangles
    };
    struct Cursor;
    class Merger;

    uint32_t key_of(const float* xyz) const;  // options_.key, else the axis key
    void spill_run();
    void sort_run();
    void merge_pass(int pass, int pass_count, size_t fan_in);
    void start_final_merge();
    void write_temp(io::TempFile& file, const void* data, size_t n);
    // Punches [begin, end) out of the file; `consumed` bytes of run data are then gone.
    void release_temp_range(io::TempFile& file, uint64_t begin, uint64_t end, uint64_t consumed);

    SorterOptions options_;
    SortStats stats_;
    size_t record_bytes_;
    io::TriangleRecords codec_;  // a triangle's record in the runs
    bool input_done_ = false;

    // Run generation.
    std::unique_ptr<std::byte[]> records_;
    std::unique_ptr<uint64_t[]> items_, scratch_;
    std::span<uint64_t> sorted_;  // after sort_run(): (key << 32 | position) in key order
    size_t run_size_ = 0;
    size_t emit_pos_ = 0;  // in-memory output position when nothing was spilled
    std::vector<std::byte> staging_;
    std::vector<uint32_t> keys_;  // add(chunk)'s keys of a chunk

    // Runs on disk.
    std::unique_ptr<io::TempFile> runs_file_;
    std::vector<Segment> segments_;
    uint64_t live_temp_bytes_ = 0;
    std::unique_ptr<Merger> final_;
};

}  // namespace meshstream::sort
