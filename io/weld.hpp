// Welding for the indexed writers (PLY, OBJ): turns a stream of triangle-soup chunks into a
// vertex list and an index list, in bounded memory. Corners are the same vertex when their
// positions are bit-identical (with -0.0 == +0.0; the welded vertex is written as +0.0) and
// their per-corner attributes (io::CornerLayout's record) are equal, or, when the chunks carry
// the vertex_id channel, when their ids, positions and attributes are equal: a UV or normal
// seam stays two vertices.
//
// Output order does not depend on the path taken: vertices sorted by key (position bits, or
// vertex id then position), so a PLY/OBJ input keeps its vertex order; triangles in input
// order. The two paths therefore give byte-identical files.
//  - In-memory path: an open-addressing hash table (linear probing, load <= 0.8; 20 bytes a
//    slot for positions, 32 with vertex ids) plus a spool of the corners in a TempFile
//    (16 or 24 bytes a corner), re-read at finish() to look each corner up. Cost: one hash
//    insert and one lookup per corner, the spool written and read once.
//  - Out-of-core path, taken when the table would outgrow the budget: (key, corner number)
//    records are sorted in runs and merged (io::RecordSorter), which assigns vertex ids in
//    key order and writes the vertices; (corner number, id) records are then sorted back into
//    corner order. Cost: two external sorts, i.e. about 2 × (24..32) + 2 × 16 bytes of temp
//    I/O per corner, O(n log n) CPU; memory stays within the budget.
#pragma once

#include "io/chunk.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace meshstream::io {

class Welder {
public:
    // The largest corner record welded (CornerLayout::bytes()).
    static constexpr size_t kMaxAttributeBytes = 256;

    // `budget_bytes` bounds the hash table or the sort buffers; temp files go to `tmpdir`
    // (empty: $TMPDIR or /tmp). `name` names the output in error messages. `channels`: those of
    // the chunks to come, whose per-corner attributes are kept (vertex ids are decided by the
    // first chunk). Throws io::Error when the corner record passes kMaxAttributeBytes.
    Welder(uint64_t budget_bytes, std::string tmpdir, std::string name, const Channels& channels);
    ~Welder();
    Welder(const Welder&) = delete;
    Welder& operator=(const Welder&) = delete;

    // Adds a chunk's triangles (with the channels given to the constructor). The first
    // non-empty chunk decides whether vertex ids are used. Throws io::Error (temp-file I/O, or
    // more than 2^32 - 1 vertices).
    void add(const TriangleChunk& chunk);
    // Ends input and assigns vertex ids. Throws io::Error.
    void finish();

    // After finish():
    uint64_t vertex_count() const;
    uint64_t triangle_count() const;
    bool out_of_core() const;  // true when the sort-based path was taken
    // The corner records' layout (attribute bytes per vertex).
    const CornerLayout& layout() const { return layout_; }
    // Fills `xyz` (3 per vertex) and `attributes` (layout().bytes() per vertex) with the next
    // vertices, in output order, as many as both hold; 0 at the end.
    size_t next_vertices(std::span<float> xyz, std::span<std::byte> attributes);
    // Fill `out` with the next triangles' indices (3 each; out.size() >= 3); 0 at the end.
    size_t next_indices(std::span<uint32_t> out);

    struct Core;

private:
    std::unique_ptr<Core> core_;
    uint64_t budget_bytes_;
    std::string tmpdir_;
    std::string name_;
    CornerLayout layout_;
};

}  // namespace meshstream::io
