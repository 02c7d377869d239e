// The vertex table of the indexed readers (PLY, OBJ): faces refer to vertices at random, so
// the reader keeps every vertex, in bounded memory. Up to the budget the records live in
// memory (64 Ki-record blocks, no reallocation copies); past it they go to an io::TempFile. A
// seekable binary PLY whose x, y, z are float32 in host byte order is not copied at all: its
// own vertex block is read in place (of_input_file). emit_polygon, at the end, turns a face
// into triangles for both readers.
//
// Memory: records in a file are read through a direct-mapped cache of its 512-byte pages,
// filled by pread, its pages and their tags within the budget, so resident memory is the budget
// plus one 1 MiB append buffer, whatever the input size; the OS page cache, which RSS does not
// count, keeps the file's pages between misses. The file is not mmap'ed: Linux maps far more
// than the page a read faults in (the page's whole page-cache folio, up to 2 MiB, and 64 KiB of
// neighbours), so resident pages would have to be counted and dropped by hand, either too
// finely (the budget leaks) or per folio (2 MiB mapped on every miss).
#pragma once

#include "io/byte_stream.hpp"
#include "io/chunk.hpp"
#include "io/triangulate.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace meshstream::io {

class VertexTable {
public:
    enum class Storage { kMemory, kTempFile, kInputFile };

    // An owned, growable table whose records are x, y, z and `attribute_bytes` more (a
    // CornerLayout's record, or 0). Throws io::Error when a temp file cannot be created or written.
    VertexTable(uint64_t budget_bytes, std::string tmpdir, size_t attribute_bytes);
    // A read-only view of `count` records of `stride` bytes starting at byte `offset` of the
    // regular file `path`: float32 x, y, z (host byte order) at xyz_offsets, no attributes.
    // Throws io::Error when the file cannot be opened.
    static std::unique_ptr<VertexTable> of_input_file(const std::string& path, uint64_t offset, uint64_t count,
                                                      size_t stride, const size_t (&xyz_offsets)[3],
                                                      uint64_t budget_bytes);
    ~VertexTable();
    VertexTable(const VertexTable&) = delete;
    VertexTable& operator=(const VertexTable&) = delete;

    // Changes the budget of an owned table, for a reader that shares its budget among several
    // (OBJ: positions, texture coordinates, normals). A table in memory past the new budget
    // spills now; a spilled one's page cache is made anew at the new size.
    void set_budget(uint64_t budget_bytes);
    // Appends a vertex (owned tables only): xyz[3] and attribute_bytes() of `attributes`.
    void append(const float* xyz, const std::byte* attributes);
    uint64_t size() const { return size_; }
    // The bytes its records take (in memory, in its temporary file or in the input file): a
    // budget of this and two pages more holds them all, read once.
    uint64_t bytes() const { return size_ * stride_; }
    size_t attribute_bytes() const { return attribute_bytes_; }
    Storage storage() const { return storage_; }
    // Copies vertex i (< size()) into xyz[3] and, when `attributes` is non-null, its
    // attribute_bytes() there. Not const: it accounts the pages it touches.
    void get(uint64_t i, float* xyz, std::byte* attributes);
    // The positions of records [first, first + count) (<= size()) into xyz (3 floats each), read
    // in bulk: from a file, in reads of up to 1 MiB beside the page cache, which is left as it
    // is. The cheapest way through every record in order.
    void positions(uint64_t first, uint64_t count, float* xyz);
    // A second reader of this table's records, for another thread: get(), positions() and
    // prefetch() as this table's, safe beside this table's own reads on one other thread (records
    // in memory are read in place; from a file, through a page cache of its own). A table read
    // from a file gives it half of its budget (both caches are made anew). It must not outlive
    // this table, nor this table be appended to while it lives.
    std::unique_ptr<VertexTable> split();
    // A hint that record i (< size()) is read soon: its bytes are asked of the memory ahead (a
    // record from a file, where its page would be cached), so that get() does not wait for
    // them. The faces index vertices at random: without it a read waits for memory at most corners.
    void prefetch(uint64_t i) const {
        const std::byte* rec = nullptr;
        if (storage_ == Storage::kMemory) {
            rec = records_->blocks_[i >> kBlockRecordsLog2].get() +
                  (i & ((uint64_t{1} << kBlockRecordsLog2) - 1)) * stride_;
        } else if (i < file_records_) {
            const uint64_t at = file_offset_ % kPageBytes + i * stride_;
            const size_t slot = static_cast<size_t>(at / kPageBytes % page_tags_.size());
            prefetch_line(&page_tags_[slot]);
            rec = pages_.get() + slot * kPageBytes + at % kPageBytes;
        } else {
            return;
        }
        prefetch_line(rec);
        prefetch_line(rec + stride_ - 1);
    }

private:
    // The cache line holding `p`, asked of the memory ahead. Not __builtin_prefetch: GCC takes a
    // function that only prefetches for one without effects (pure) and drops the calls to it.
    static void prefetch_line(const void* p) {
#if defined(__x86_64__) || defined(__i386__)
        asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(p)));
#elif defined(__aarch64__)
        asm volatile("prfm pldl1keep, %0" : : "Q"(*static_cast<const char*>(p)));
#else
        __builtin_prefetch(p);
#endif
    }

    VertexTable() = default;
    void spill();
    void flush_tail();

    // The table whose records these are: this one, or the one split() was called on (its
    // blocks, tail and file are read; the page cache is this one's own).
    const VertexTable* records_ = this;
    uint64_t budget_bytes_ = 0;
    std::string tmpdir_;
    size_t attribute_bytes_ = 0;
    Storage storage_ = Storage::kMemory;
    uint64_t size_ = 0;
    size_t stride_ = 12;
    size_t xyz_offsets_[3] = {0, 4, 8};
    std::vector<std::byte> record_;  // append's assembly buffer

    // kMemory: fixed-size blocks of records.
    static constexpr size_t kBlockRecordsLog2 = 16;
    std::vector<std::unique_ptr<std::byte[]>> blocks_;

    // kTempFile / kInputFile: records [0, file_records_) are read from a file through the page
    // cache below; later ones (temp file only) sit in tail_ until flushed.
    // The cache's page: small, because faces refer to vertices scattered through a window of the
    // table, so a large page holds mostly vertices nobody asks for (fewer of the wanted ones fit
    // the budget, and each miss copies more); smaller pages than this miss about as often, and a
    // miss costs mostly the pread call (docs/results.md#formats).
    static constexpr size_t kPageBytes = 512;
    std::unique_ptr<TempFile> temp_;
    int input_fd_ = -1;
    std::string input_path_;
    uint64_t file_offset_ = 0;  // where record 0 is in the file
    uint64_t file_records_ = 0;
    std::vector<std::byte> tail_;
    // A direct-mapped cache of the file's 512-byte pages (numbered from the one holding record 0).
    // Anonymous memory of its own, so that it goes back to the system with the reader (sort
    // frees the reader before merging; from malloc's heap its pages stayed resident).
    struct Unmap {
        size_t bytes;
        void operator()(std::byte* p) const;
    };
    std::unique_ptr<std::byte, Unmap> pages_;
    std::vector<uint64_t> page_tags_;  // the page each slot holds; ~0: none
    void start_cache(uint64_t table_bytes);
    const std::byte* cached_page(uint64_t page);
    void read_file(uint64_t offset, void* dst, size_t n);  // n bytes of the file at `offset`
};

// What emit_polygon keeps between calls: the current polygon's corners and its triangles. One
// per reader, reused, so a polygon allocates nothing once a larger one has been read; it holds
// about 80 bytes a corner of the largest polygon.
struct PolygonScratch {
    std::vector<float> xyz;           // 3 per corner
    std::vector<std::byte> records;   // one corner record per corner
    std::vector<std::byte> record;    // one corner record, for triangles
    std::vector<uint32_t> triangles;  // 3 corner numbers per triangle
    TriangulateScratch triangulate;
};

// Emits the triangulation of `polygon` (triangulate_polygon: the fan (p0, pk, pk+1) when it is
// convex, ear clipping otherwise; always size - 2 triangles) into `chunk`, from triangle
// `*next` on, until the chunk is full or the polygon is done. The first call for a polygon
// passes *next == 0 and reads its corners and triangulates it into `scratch`; later calls
// for it must pass the same scratch. Sets the chunk's vertex ids (the polygon's indices) when
// the chunk has them, and when `layout` is non-null (the table's records are its corner
// records, and the chunk has its channels) the corners' attributes. Per-triangle channels are
// the caller's: the triangles added are those from the chunk's size before the call on.
// Returns true when the polygon is finished (at once for fewer than 3 corners). Indices must
// be < table.size(); fewer than 2^32 corners.
bool emit_polygon(VertexTable& table, const CornerLayout* layout, const std::vector<uint64_t>& polygon,
                  PolygonScratch& scratch, size_t* next, TriangleChunk& chunk);

}  // namespace meshstream::io
