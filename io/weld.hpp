// Welding for the indexed writers (PLY, OBJ): turns a stream of triangle-soup chunks into a
// vertex list and an index list, in bounded memory. Corners are the same vertex when their
// positions are bit-identical (with -0.0 == +0.0; the welded vertex is written as +0.0), or,
// when the chunks carry the vertex_id channel, when their ids (and positions) are equal.
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

struct WeldedVertex {
    float xyz[3];
    uint8_t rgb[3];
};

class Welder {
public:
    // `budget_bytes` bounds the hash table or the sort buffers; temp files go to `tmpdir`
    // (empty: $TMPDIR or /tmp). `name` names the output in error messages.
    Welder(uint64_t budget_bytes, std::string tmpdir, std::string name);
    ~Welder();
    Welder(const Welder&) = delete;
    Welder& operator=(const Welder&) = delete;

    // Adds a chunk's triangles. The first non-empty chunk decides whether vertex ids are used
    // and whether colour is kept. Throws io::Error (temp-file I/O, or more than 2^32 - 1
    // vertices).
    void add(const TriangleChunk& chunk);
    // Ends input and assigns vertex ids. Throws io::Error.
    void finish();

    // After finish():
    uint64_t vertex_count() const;
    uint64_t triangle_count() const;
    bool color() const;
    bool out_of_core() const;  // true when the sort-based path was taken
    // Fill `out` with the next vertices, in output order; 0 at the end.
    size_t next_vertices(std::span<WeldedVertex> out);
    // Fill `out` with the next triangles' indices (3 each; out.size() >= 3); 0 at the end.
    size_t next_indices(std::span<uint32_t> out);

    struct Core;

private:
    std::unique_ptr<Core> core_;
    uint64_t budget_bytes_;
    std::string tmpdir_;
    std::string name_;
};

}  // namespace meshstream::io
