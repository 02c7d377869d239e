// The vertex table of the indexed readers (PLY, OBJ): faces refer to vertices at random, so
// the reader keeps every vertex, in bounded memory. Up to the budget the records live in
// memory (64 Ki-record blocks, no reallocation copies); past it they go to an io::TempFile that
// is read through a shared read-only mmap (the OS page cache does the caching). A seekable
// binary PLY whose x, y, z are float32 in host byte order is not copied at all: its own vertex
// block is mapped (map_input_file). emit_polygon, at the end, turns a face into triangles for
// both readers.
//
// Memory: mapped pages count towards RSS once touched, and Linux maps the faulted page's whole
// page-cache folio (up to 2 MiB) and its cached neighbours within 64 KiB (fault-around). So
// reads through a mapping larger than the budget note the 2 MiB blocks of the file they can
// have made resident, and past the budget drop the block noted first with
// madvise(MADV_DONTNEED). Resident memory is therefore at most max(budget, 6 MiB) + bitmap
// (1/2^24 of the table) + one 1 MiB append buffer, whatever the input size.
#pragma once

#include "io/byte_stream.hpp"
#include "io/chunk.hpp"
#include "io/triangulate.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace meshstream::io {

class VertexTable {
public:
    enum class Storage { kMemory, kTempFile, kInputFile };

    // An owned, growable table. `color`: records carry RGB8. Throws io::Error when a temp file
    // cannot be created or written.
    VertexTable(uint64_t budget_bytes, std::string tmpdir, bool color);
    // A read-only view of `count` records of `stride` bytes starting at byte `offset` of the
    // regular file `path`: float32 x, y, z (host byte order) at xyz_offsets, and when
    // `rgb_offsets` is non-null uint8 red, green, blue there. Throws io::Error when the file
    // cannot be opened or mapped.
    static std::unique_ptr<VertexTable> map_input_file(const std::string& path, uint64_t offset, uint64_t count,
                                                       size_t stride, const size_t (&xyz_offsets)[3],
                                                       const size_t* rgb_offsets, uint64_t budget_bytes);
    ~VertexTable();
    VertexTable(const VertexTable&) = delete;
    VertexTable& operator=(const VertexTable&) = delete;

    // Appends a vertex (owned tables only). `rgb` may be null (black).
    void append(const float* xyz, const uint8_t* rgb);
    uint64_t size() const { return size_; }
    bool color() const { return color_; }
    Storage storage() const { return storage_; }
    // Copies vertex i (< size()) into xyz[3] and, when rgb is non-null, rgb[3] (zeros when the
    // table has no colour). Not const: it accounts the pages it touches.
    void get(uint64_t i, float* xyz, uint8_t* rgb);

private:
    VertexTable() = default;
    void spill();
    void flush_tail();
    void map_temp(uint64_t min_bytes);
    const std::byte* record_in_map(uint64_t byte_offset);

    uint64_t budget_bytes_ = 0;
    std::string tmpdir_;
    bool color_ = false;
    Storage storage_ = Storage::kMemory;
    uint64_t size_ = 0;
    size_t stride_ = 12;
    size_t xyz_offsets_[3] = {0, 4, 8};
    size_t rgb_offsets_[3] = {12, 13, 14};

    // kMemory: fixed-size blocks of records.
    static constexpr size_t kBlockRecordsLog2 = 16;
    std::vector<std::unique_ptr<std::byte[]>> blocks_;

    // kTempFile / kInputFile: a mapping; records [0, mapped_records_) are readable through it,
    // later ones (temp file only) sit in tail_ until flushed.
    std::unique_ptr<TempFile> temp_;
    int input_fd_ = -1;
    void* map_ = nullptr;
    size_t map_bytes_ = 0;
    const std::byte* base_ = nullptr;  // first record (map_ plus the page-alignment delta)
    uint64_t map_file_offset_ = 0;     // where map_ starts in the mapped file
    uint64_t mapped_records_ = 0;
    std::vector<std::byte> tail_;
    // Residency accounting for mappings larger than the budget, in 2 MiB blocks of the file.
    void start_accounting();
    size_t block_count() const;
    std::vector<uint64_t> touched_bits_;  // blocks that may be resident
    std::deque<uint64_t> touched_order_;  // the same, in the order they were first touched
    uint64_t block_limit_ = 0;
};

// What emit_polygon keeps between calls: the current polygon's corners and its triangles. One
// per reader, reused, so a polygon allocates nothing once a larger one has been read; it holds
// about 80 bytes a corner of the largest polygon.
struct PolygonScratch {
    std::vector<float> xyz;           // 3 per corner
    std::vector<uint8_t> rgb;         // 3 per corner
    std::vector<uint32_t> triangles;  // 3 corner numbers per triangle
    TriangulateScratch triangulate;
};

// Emits the triangulation of `polygon` (triangulate_polygon: the fan (p0, pk, pk+1) when it is
// convex, ear clipping otherwise; always size - 2 triangles) into `chunk`, from triangle
// `*next` on, until the chunk is full or the polygon is done. The first call for a polygon
// passes *next == 0 and reads its corners and triangulates it into `scratch`; later calls
// for it must pass the same scratch. Sets the chunk's vertex ids (the polygon's indices) and
// colours when the chunk has those channels. Returns true when the polygon is finished
// (at once for fewer than 3 corners). Indices must be < table.size(); fewer than 2^32 corners.
bool emit_polygon(VertexTable& table, const std::vector<uint64_t>& polygon, PolygonScratch& scratch, size_t* next,
                  TriangleChunk& chunk);

}  // namespace meshstream::io
